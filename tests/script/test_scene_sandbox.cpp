// Tests for the scene sandbox (src/script): what a scene cannot reach, load() text only, the per-call
// instruction budget and the memory cap. Each absent global has its own test case.
#include "scene_test_util.hpp"
#include "script/lua_host.hpp"

#include <lua.hpp>

#include <cstdio>

namespace arwb::script::test {
namespace {

// ---- absent and present globals ----------------------------------------------------------------------------------

// The scene prints type() of the expression, read directly, through _G and through rawget.
std::vector<std::string> types_of(const std::string& expr, const std::string& raw_table, const std::string& raw_key) {
  SceneFixture s;
  const auto p = s.write("scene.lua", "print(type(" + expr + "))\nprint(type(rawget(" + raw_table + ", \"" + raw_key +
                                          "\")))\nprint(type(load(\"return " + expr + "\")()))\n");
  EXPECT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  return s.printed();
}

class AbsentGlobal : public testing::TestWithParam<const char*> {};

TEST_P(AbsentGlobal, IsNil) {
  const std::string name = GetParam();
  EXPECT_EQ(types_of(name, "_G", name), (std::vector<std::string>{"nil", "nil", "nil"}));
}

INSTANTIATE_TEST_SUITE_P(Sandbox, AbsentGlobal,
                         testing::Values("io", "package", "require", "dofile", "loadfile", "debug", "collectgarbage"));

class AbsentOsFunction : public testing::TestWithParam<const char*> {};

TEST_P(AbsentOsFunction, IsNil) {
  const std::string name = GetParam();
  EXPECT_EQ(types_of("os." + name, "os", name), (std::vector<std::string>{"nil", "nil", "nil"}));
}

INSTANTIATE_TEST_SUITE_P(Sandbox, AbsentOsFunction,
                         testing::Values("execute", "exit", "getenv", "remove", "rename", "tmpname", "setlocale"));

class PresentOsFunction : public testing::TestWithParam<const char*> {};

TEST_P(PresentOsFunction, IsAFunction) {
  const std::string name = GetParam();
  EXPECT_EQ(types_of("os." + name, "os", name), (std::vector<std::string>{"function", "function", "function"}));
}

INSTANTIATE_TEST_SUITE_P(Sandbox, PresentOsFunction, testing::Values("clock", "time", "date"));

TEST(Sandbox, OsClockTimeAndDateWork) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
print(os.clock() >= 0, os.time() > 1600000000, os.date("%Y", 0) == "1970" or os.date("%Y", 0) == "1969")
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_EQ(s.printed(), (std::vector<std::string>{"true\ttrue\ttrue"}));
}

TEST(Sandbox, StringDumpIsAbsentAlsoThroughStringMethods) {
  EXPECT_EQ(types_of("string.dump", "string", "dump"), (std::vector<std::string>{"nil", "nil", "nil"}));
  SceneFixture s;
  const auto p = s.write("scene.lua", "print(type((\"x\").dump), type(getmetatable(\"\").__index.dump))\n");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_EQ(s.printed(), (std::vector<std::string>{"nil\tnil"}));
}

TEST(Sandbox, TheUsualLibraryIsThere) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
print(math.floor(2.5), string.format("%03d", 7), table.concat({1, 2}, ","), utf8.char(72),
      select("#", 1, 2), coroutine.wrap(function() coroutine.yield(9) end)())
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_EQ(s.printed(), (std::vector<std::string>{"2\t007\t1,2\tH\t2\t9"}));
}

TEST(Sandbox, ValuesMetatablesAreLocked) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
local v = text "x"
print(getmetatable(v), pcall(setmetatable, v, {}))
print(tostring(beside { side = "left" }))
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto out = s.printed();
  ASSERT_EQ(out.size(), 2u) << s.console();
  EXPECT_EQ(out[0].rfind("locked\tfalse\t", 0), 0u) << out[0];
  EXPECT_EQ(out[1], "beside left gap 0.25 size 1");
}

// ---- load ----------------------------------------------------------------------------------------------------

// "return 1+1" compiled by a plain Lua state and dumped: a binary chunk, as a Lua string literal.
std::string binary_chunk_literal() {
  lua_State* L = luaL_newstate();
  EXPECT_EQ(luaL_loadstring(L, "return 1+1"), LUA_OK);
  std::string bytes;
  lua_dump(
      L,
      [](lua_State*, const void* p, size_t n, void* ud) {
        static_cast<std::string*>(ud)->append(static_cast<const char*>(p), n);
        return 0;
      },
      &bytes, 0);
  lua_close(L);
  EXPECT_EQ(bytes.substr(0, 4), "\x1bLua");
  std::string lit = "\"";
  for (unsigned char c : bytes) {
    char b[8];
    std::snprintf(b, sizeof b, "\\%03u", c);
    lit += b;
  }
  return lit + "\"";
}

TEST(Sandbox, LoadRefusesBinaryChunks) {
  SceneFixture s;
  const std::string bin = binary_chunk_literal();
  const auto p = s.write("scene.lua", "local bin = " + bin + R"(
print(load(bin))
print(load(bin, "chunk", "b"))
print(load(bin, "chunk", "bt", {}))
local parts = { bin }
print(load(function() return table.remove(parts, 1) end))
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto out = s.printed();
  ASSERT_EQ(out.size(), 4u) << s.console();
  for (int i = 0; i < 3; ++i) EXPECT_EQ(out[i], "nil\tload: binary chunks are not allowed in scenes (text only)");
  EXPECT_EQ(out[3].rfind("nil\t", 0), 0u);
  EXPECT_NE(out[3].find("binary chunk"), std::string::npos) << out[3];
}

TEST(Sandbox, LoadRunsTextInTheSandboxedEnvironment) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
print(load("return 1+1")())
print(load("return io")(), type(load("return marker")()), load("return x", "c", "t", { x = 5 })())
print(load("syntax error here"))
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto out = s.printed();
  ASSERT_EQ(out.size(), 3u) << s.console();
  EXPECT_EQ(out[0], "2");
  EXPECT_EQ(out[1], "nil\tfunction\t5");
  EXPECT_EQ(out[2].rfind("nil\t[string \"syntax error here\"]:1:", 0), 0u) << out[2];
}

TEST(Sandbox, ABinarySceneFileIsRefused) {
  SceneFixture s;
  lua_State* L = luaL_newstate();
  ASSERT_EQ(luaL_loadstring(L, "marker(7, { media = text \"x\" })"), LUA_OK);
  std::string bytes;
  lua_dump(
      L,
      [](lua_State*, const void* p, size_t n, void* ud) {
        static_cast<std::string*>(ud)->append(static_cast<const char*>(p), n);
        return 0;
      },
      &bytes, 0);
  lua_close(L);
  const auto p = s.write("scene.lua", bytes);
  EXPECT_FALSE(s.runtime.load(p));
  // Refused as text before Lua sees it (a compiled chunk holds NUL bytes); Lua's "t" mode is the second fence.
  EXPECT_NE(s.runtime.status().error.find("a NUL byte; not a text file"), std::string::npos)
      << s.runtime.status().error;
}

// ---- instruction budget --------------------------------------------------------------------------------------

ScriptLimits small_budget() {
  ScriptLimits l;
  l.instructions_per_call = 200'000;
  return l;
}

TEST(Sandbox, BudgetStopsAnEndlessCallbackAndDisablesOnlyIt) {
  SceneFixture s(small_budget());
  const auto p = s.write("scene.lua", R"(marker(7, { media = text "seven", on_update = function() print("seven runs") end })
marker(30, {
  media = text "thirty",
  on_enter = function(m) print("enter", m.id) end,
  on_update = function(m, dt)
    print("tick")
    while true do end
  end,
})
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  auto ov = s.update({track(7, 100, 100), track(30, 300, 100)}, enters({7, 30}));
  const std::string want =
      "scene.lua:7: instruction budget of 200000 exceeded in on_update of marker 30; disabled until the scene reloads";
  const auto l = s.lines("instruction budget");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_TRUE(l[0].text.ends_with("/" + want)) << l[0].text;
  EXPECT_EQ(l[0].level, 2);
  EXPECT_TRUE(find_overlay(ov, 7));
  EXPECT_TRUE(find_overlay(ov, 30));   // its media keeps going
  EXPECT_EQ(s.runtime.status().mappings[1].state, "disabled: " + l[0].text);
  EXPECT_EQ(s.runtime.status().mappings[1].health, MappingHealth::disabled);

  ov = s.update({track(7, 100, 100), track(30, 300, 100)});
  EXPECT_TRUE(find_overlay(ov, 7));
  EXPECT_TRUE(find_overlay(ov, 30));
  EXPECT_EQ(s.lines("instruction budget").at(0).repeats, 1);   // not run again
  EXPECT_EQ(s.count_printed("tick"), 1);
  EXPECT_EQ(s.count_printed("seven runs"), 2);

  // Its other callbacks still run.
  s.update({track(7, 100, 100)}, {leave_event(30)});
  s.update({track(7, 100, 100), track(30, 300, 100)}, enters({30}));
  EXPECT_EQ(s.lines("enter\t30").size(), 2u) << s.console();

  // Until the scene reloads.
  ASSERT_TRUE(s.runtime.load(p));
  s.update({track(30, 300, 100)});
  EXPECT_EQ(s.printed().back(), "tick");
  EXPECT_EQ(s.lines("instruction budget").size(), 1u);
  EXPECT_EQ(s.lines("instruction budget").at(0).repeats, 2);
}

TEST(Sandbox, BudgetCannotBeSwallowedByPcallOrHiddenInACoroutine) {
  SceneFixture s(small_budget());
  const auto p = s.write("scene.lua", R"(
marker(1, { on_update = function() while true do pcall(function() while true do end end) end end })
marker(2, { on_update = function() coroutine.wrap(function() while true do end end)() end })
marker(3, { on_update = function() local co = coroutine.create(function() while true do end end)
                                    while true do coroutine.resume(co) end end })
marker(4, { media = text "four" })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto ov = s.update({track(1, 100, 100), track(2, 200, 100), track(3, 300, 100), track(4, 400, 100)});
  EXPECT_TRUE(s.has("in on_update of marker 1; disabled until the scene reloads")) << s.console();
  EXPECT_TRUE(s.has("in on_update of marker 2; disabled until the scene reloads")) << s.console();
  EXPECT_TRUE(s.has("in on_update of marker 3; disabled until the scene reloads")) << s.console();
  EXPECT_TRUE(find_overlay(ov, 4));
}

TEST(Sandbox, BudgetStopsAnEndlessTextFunction) {
  SceneFixture s(small_budget());
  const auto p = s.write("scene.lua", R"(
marker(5, { media = text(function(m) while true do end end) })
marker(6, { media = text(function(m) return "six" end) })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  for (int i = 0; i < 2; ++i) {
    const auto ov = s.update({track(5, 100, 100), track(6, 300, 100)});
    EXPECT_FALSE(find_overlay(ov, 5));
    ASSERT_TRUE(find_overlay(ov, 6));
    EXPECT_EQ(find_overlay(ov, 6)->media.text, "six");
  }
  const auto l = s.lines("instruction budget of 200000 exceeded in text of marker 5; disabled until the scene reloads");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_EQ(l[0].repeats, 1);
}

TEST(Sandbox, BudgetStopsAnEndlessMainChunkAndTheLastGoodSceneStays) {
  SceneFixture s(small_budget());
  const auto good = s.write("good.lua", "marker(7, { media = text \"good\" })\n");
  ASSERT_TRUE(s.runtime.load(good));
  const auto bad = s.write("bad.lua", "marker(8, { media = text \"bad\" })\nwhile true do end\n");
  EXPECT_FALSE(s.runtime.load(bad));
  EXPECT_TRUE(s.runtime.status().error.ends_with("/bad.lua:2: instruction budget of 200000 exceeded while loading the scene"))
      << s.runtime.status().error;
  EXPECT_EQ(s.runtime.status().error_line, 2);
  const auto ov = s.update({track(7, 100, 100), track(8, 300, 100)});
  ASSERT_EQ(ov.size(), 1u);
  EXPECT_EQ(ov[0].media.text, "good");
}

TEST(Sandbox, TheBudgetCountsTheWholeCall) {
  // 200000 instructions are enough for a loop of 10000 (a few instructions each) but not of 100000.
  SceneFixture s(small_budget());
  const auto p = s.write("scene.lua", R"(
marker(1, { on_update = function() local n = 0 for i = 1, 10000 do n = n + i end print("small", n) end })
marker(2, { on_update = function() local n = 0 for i = 1, 100000 do n = n + i end print("big", n) end })
)");
  ASSERT_TRUE(s.runtime.load(p));
  s.update({track(1, 100, 100), track(2, 300, 100)});
  EXPECT_TRUE(s.has("small\t50005000")) << s.console();
  EXPECT_FALSE(s.has("big\t"));
  EXPECT_TRUE(s.has("in on_update of marker 2; disabled")) << s.console();
}

// ---- memory cap ----------------------------------------------------------------------------------------------

ScriptLimits small_memory() {
  ScriptLimits l;
  l.memory_bytes = 16u << 20;
  return l;
}

TEST(Sandbox, MemoryBombInACallbackFailsAndTheRuntimeKeepsWorking) {
  SceneFixture s(small_memory());
  const auto p = s.write("scene.lua", R"(marker(7, { media = text "seven", on_update = function() print("alive") end })
marker(30, { on_update = function(m, dt)
  local s = string.rep("x", 1e9)
end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  auto ov = s.update({track(7, 100, 100), track(30, 300, 100)});
  const auto l = s.lines("not enough memory");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_TRUE(l[0].text.ends_with("/scene.lua:2: not enough memory (the cap is 16 MiB) in on_update of marker 30; "
                                  "disabled until the scene reloads"))
      << l[0].text;
  EXPECT_TRUE(find_overlay(ov, 7));
  ov = s.update({track(7, 100, 100), track(30, 300, 100)});
  EXPECT_TRUE(find_overlay(ov, 7));
  EXPECT_EQ(s.count_printed("alive"), 2);   // the next update still runs Lua
  EXPECT_EQ(s.lines("not enough memory").at(0).repeats, 1);

  // A later reload works.
  s.write("scene.lua", "marker(7, { media = text \"reloaded\" })\n");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_EQ(s.update({track(7, 100, 100)}).at(0).media.text, "reloaded");
}

TEST(Sandbox, MemoryBombWhileLoadingFailsTheLoadOnly) {
  SceneFixture s(small_memory());
  const auto good = s.write("good.lua", "marker(7, { media = text \"good\" })\n");
  ASSERT_TRUE(s.runtime.load(good));
  const auto bomb = s.write("bomb.lua", "local s = string.rep(\"x\", 1e9)\n");
  EXPECT_FALSE(s.runtime.load(bomb));
  EXPECT_NE(s.runtime.status().error.find("not enough memory"), std::string::npos) << s.runtime.status().error;
  EXPECT_EQ(s.update({track(7, 100, 100)}).at(0).media.text, "good");
  // A table that grows past the cap, too.
  // The instruction and wall-time limits out of the way: under the sanitizers on a loaded machine, filling 16 MB
  // took longer than the 250 ms a call may run.
  ScriptLimits l = small_memory();
  l.instructions_per_call = 1'000'000'000;
  l.call_ms = 60'000;
  SceneFixture s2(l);
  const auto grow2 = s2.write("grow.lua", "local t = {} local i = 0 while true do i = i + 1 t[i] = {i} end\n");
  EXPECT_FALSE(s2.runtime.load(grow2));
  EXPECT_NE(s2.runtime.status().error.find("not enough memory"), std::string::npos) << s2.runtime.status().error;
}

TEST(Sandbox, AScriptCanCatchTheMemoryErrorAndGoOn) {
  SceneFixture s(small_memory());
  const auto p = s.write("scene.lua", R"(
print(pcall(string.rep, "x", 1e9))
local t = {}
for i = 1, 1000 do t[i] = string.rep("y", 100) end
print("after", #t)
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_EQ(s.printed(), (std::vector<std::string>{"false\tnot enough memory", "after\t1000"}));
}

TEST(Sandbox, AllocatorAccountingIsExact) {
  // Lua's own count of its bytes (lua_gc COUNT/COUNTB) must equal what the allocator holds, after growing,
  // shrinking, a refused allocation and a full collection.
  ScriptLimits limits = small_memory();
  LuaState ls(limits, nullptr, "x.lua");
  lua_State* L = ls.L();
  auto lua_count = [&] {
    return static_cast<std::size_t>(lua_gc(L, LUA_GCCOUNT)) * 1024 + static_cast<std::size_t>(lua_gc(L, LUA_GCCOUNTB));
  };
  EXPECT_EQ(ls.host().used, lua_count());
  for (const char* code : {"t = {} for i = 1, 10000 do t[i] = tostring(i) end",
                           "t = nil", "u = string.rep('z', 1e6)", "local ok = pcall(string.rep, 'x', 1e9)",
                           "u = nil"}) {
    ASSERT_TRUE(ls.load_chunk(code).ok);
    const auto out = ls.pcall(0, 0);
    EXPECT_TRUE(out.ok) << out.message;
    EXPECT_EQ(ls.host().used, lua_count()) << code;
    EXPECT_LE(ls.host().used, limits.memory_bytes);
  }
  const std::size_t before = ls.host().used;
  lua_gc(L, LUA_GCRESTART);
  lua_gc(L, LUA_GCCOLLECT);
  lua_gc(L, LUA_GCSTOP);
  EXPECT_EQ(ls.host().used, lua_count());
  EXPECT_LT(ls.host().used, before);
  EXPECT_LT(ls.host().used, std::size_t(1) << 20);   // the 1 MB string and the table are gone
}

TEST(Sandbox, GarbageMadeByTheHostIsCollected) {
  // The runtime builds the marker tables in host mode, where the collector is stopped; collect_garbage() (once
  // a frame) must keep up even when the scene itself never allocates.
  LuaState ls(ScriptLimits{}, nullptr, "x.lua");
  lua_State* L = ls.L();
  const std::size_t start = ls.host().used;
  for (int frame = 0; frame < 500; ++frame) {
    for (int k = 0; k < 200; ++k) {
      lua_createtable(L, 0, 4);
      lua_pop(L, 1);
    }
    ls.collect_garbage();
  }
  EXPECT_LT(ls.host().used, start + (1u << 20));   // 100000 tables of 64+ bytes would be over 6 MB
}

// ---- pattern matching ----------------------------------------------------------------------------------------

// Backtracking happens inside one C call, out of the budget's sight: a pattern that would run for hours is refused
// up front with its line, and ordinary searches still work.
TEST(Sandbox, CostlyPatternsAreRefusedAndOrdinaryOnesWork) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"lua(marker(7, { media = text "seven" })
marker(30, { on_enter = function(m)
  local a = string.rep("a", 400)
  print(a:find(".-.-.-.-b"))
end })
marker(31, { on_enter = function(m)
  print(("ID 150 at 3.5"):match("(%a+) (%d+) at ([%d%.]+)"))
  print(("x=1, y=2"):gsub("(%w+)=(%w+)", "%2=%1"))
  print(string.rep("a", 100000):find("aab", 1, true), string.rep("ab", 5000):find("^(a)(b)"))
end })
)lua");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto ov = s.update({track(7, 100, 100), track(30, 300, 100), track(31, 500, 100)}, enters({7, 30, 31}));
  const auto l = s.lines("too costly");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_NE(l[0].text.find("scene.lua:4:"), std::string::npos) << l[0].text;
  EXPECT_NE(l[0].text.find("on a 400-character string it could take about 1e+14 steps"), std::string::npos) << l[0].text;
  EXPECT_TRUE(find_overlay(ov, 7));
  const std::string out = s.console();
  EXPECT_NE(out.find("ID\t150\t3.5"), std::string::npos) << out;
  EXPECT_NE(out.find("1=x, 2=y\t2"), std::string::npos) << out;
  EXPECT_NE(out.find("nil\t1\t2\ta\tb"), std::string::npos) << out;
}

}  // namespace
}  // namespace arwb::script::test
