// Issue 10's attacks on the scene sandbox, each as its reproduction: a finalizer that loops, library calls over
// long strings in a loop, costly patterns, unbounded single library calls, stack overflow, floods of fields and
// output, errors on every frame. Each is stopped or refused with its file:line, generously within time, and the
// next frames still run. Time bounds are generous (seconds) against limits of a quarter second.
#include "scene_test_util.hpp"

#include "script/lua_host.hpp"

#include <chrono>

namespace arwb::script::test {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// ---- finalizers ------------------------------------------------------------------------------------------------

// Lua runs __gc with hooks off: this scene hung `arwb render` and the workbench for ever.
TEST(Limits, AFinalizerIsRefusedWithItsLine) {
  SceneFixture s;
  const auto good = s.write("good.lua", "marker(1, { media = text \"good\" })\n");
  ASSERT_TRUE(s.runtime.load(good));
  const auto p = s.write("scene.lua", "setmetatable({}, { __gc = function() while true do end end })\n"
                                      "marker(1, { media = text \"x\" })\n");
  const auto t0 = Clock::now();
  EXPECT_FALSE(s.runtime.load(p));
  EXPECT_TRUE(s.runtime.status().error.ends_with(
      "/scene.lua:1: setmetatable: a metatable with __gc is not allowed in a scene (finalizers run where no time "
      "limit can stop them; use on_leave, or drop the table)"))
      << s.runtime.status().error;
  EXPECT_EQ(s.runtime.status().error_line, 1);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(s.update({track(1, 100, 100)}).at(0).media.text, "good");
  s.runtime.unload();
  EXPECT_LT(seconds_since(t0), 5.0);
}

TEST(Limits, NoWayAroundTheFinalizerRule) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
print(pcall(setmetatable, {}, { __gc = false }))
-- Lua marks a table for finalization only when its metatable has __gc as it is set: added later, it never runs.
local mt = {}
local t = setmetatable({}, mt)
mt.__gc = function() while true do end end
t = nil
print(getmetatable(setmetatable({}, { __index = {} })) ~= nil)
marker(1, { on_update = function() local x = setmetatable({}, mt) end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_TRUE(s.has("false\t")) << s.console();
  EXPECT_TRUE(s.has("__gc is not allowed")) << s.console();
  EXPECT_EQ(s.printed().back(), "true");
  const auto t0 = Clock::now();
  for (int i = 0; i < 3; ++i) s.update({track(1, 100, 100)});
  EXPECT_TRUE(s.has("scene.lua:9: setmetatable: a metatable with __gc is not allowed")) << s.console();
  s.runtime.unload();   // closing the state runs no scene finalizer
  EXPECT_LT(seconds_since(t0), 5.0);
}

// ---- wall time -------------------------------------------------------------------------------------------------
// The long strings are built from 1 KiB pieces: string.rep copies its piece once per repeat, and 8 million one-byte
// copies took over the 250 ms of loading the scene under ASan in CI.

// Each s:upper() is one instruction to the budget and about 3 ms on 4 MB: 5 million of them would take hours.
TEST(Limits, LibraryCallsOverALongStringInALoopAreStoppedByTime) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(local s = string.rep(string.rep("x", 1024), 4 * 1024)
marker(1, { media = text "one", on_update = function(m)
  while true do local u = s:upper() end
end })
marker(2, { media = text "two", on_update = function(m) print("two runs") end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  auto t0 = Clock::now();
  auto ov = s.update({track(1, 100, 100), track(2, 300, 100)});
  EXPECT_LT(seconds_since(t0), 3.0);
  const auto l = s.lines("ran longer than 250 ms");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_TRUE(l[0].text.ends_with("/scene.lua:3: ran longer than 250 ms in on_update of marker 1; disabled until "
                                  "the scene reloads"))
      << l[0].text;
  EXPECT_TRUE(find_overlay(ov, 1));
  EXPECT_TRUE(find_overlay(ov, 2));
  // That call used the frame's time: marker 2's on_update waits for the next frame.
  EXPECT_TRUE(s.has("the scene's calls took over 150 ms on this frame")) << s.console();
  t0 = Clock::now();
  ov = s.update({track(1, 100, 100), track(2, 300, 100)});
  EXPECT_LT(seconds_since(t0), 1.0);   // not run again
  EXPECT_EQ(s.count_printed("two runs"), 1);
  EXPECT_EQ(s.lines("ran longer than").at(0).repeats, 1);
}

TEST(Limits, AMillionPlainFindsAreStoppedByTime) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(local s = string.rep(string.rep("x", 1024), 1024)
marker(1, { on_update = function(m)
  local n = 0
  for i = 1, 1e6 do if s:find("y", 1, true) then n = n + 1 end end
end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto t0 = Clock::now();
  s.update({track(1, 100, 100)});
  EXPECT_LT(seconds_since(t0), 3.0);
  EXPECT_TRUE(s.has("/scene.lua:4: ran longer than 250 ms in on_update of marker 1; disabled")) << s.console();
}

// Hooks are per coroutine in Lua: one made in an earlier call and resumed later, and one made inside the call, are
// both stopped, even when the script swallows the error and returns.
TEST(Limits, CoroutinesOldAndNewAreStoppedByTime) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(local s = string.rep(string.rep("x", 1024), 8 * 1024)
local old = coroutine.create(function() while true do local u = s:lower() end end)
marker(1, { on_update = function(m) print(coroutine.resume(old)) end })
marker(2, { on_update = function(m)
  local new = coroutine.wrap(function() while true do local u = s:upper() end end)
  print(pcall(new))
end })
marker(3, { media = text "three" })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  // One frame each: the first call uses the frame's time, so the second waits for the next frame.
  const auto t0 = Clock::now();
  auto ov = s.update({track(1, 100, 100), track(2, 300, 100), track(3, 500, 100)});
  ov = s.update({track(1, 100, 100), track(2, 300, 100), track(3, 500, 100)});
  EXPECT_LT(seconds_since(t0), 4.0);
  EXPECT_TRUE(s.has("scene.lua:2: ran longer than 250 ms in on_update of marker 1; disabled")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:5: ran longer than 250 ms in on_update of marker 2; disabled")) << s.console();
  EXPECT_TRUE(find_overlay(ov, 3));
}

TEST(Limits, MetamethodsAndComputedTextAreStoppedByTime) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(local s = string.rep(string.rep("x", 1024), 8 * 1024)
local slow = setmetatable({}, { __tostring = function() while true do local u = s:upper() end end,
                               __index = function(t, k) while true do local u = s:lower() end end })
marker(1, { media = text(function(m) return tostring(slow) end) })
marker(2, { on_update = function(m) return slow.anything end })
marker(3, { media = text "three" })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto t0 = Clock::now();
  auto ov = s.update({track(1, 100, 100), track(2, 300, 100), track(3, 500, 100)});
  ov = s.update({track(1, 100, 100), track(2, 300, 100), track(3, 500, 100)});
  EXPECT_LT(seconds_since(t0), 4.0);
  EXPECT_TRUE(s.has("scene.lua:2: ran longer than 250 ms in text of marker 1; disabled")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:3: ran longer than 250 ms in on_update of marker 2; disabled")) << s.console();
  EXPECT_TRUE(find_overlay(ov, 3));
}

// Comparisons, concatenation and indexing by a new long string are single instructions costing milliseconds.
TEST(Limits, StringOperatorsInALoopAreStoppedByTime) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(local s = string.rep(string.rep("x", 1024), 8 * 1024)
local t = {}
marker(1, { on_update = function(m) while true do local x = t[s .. "y"] end end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto t0 = Clock::now();
  s.update({track(1, 100, 100)});
  EXPECT_LT(seconds_since(t0), 3.0);
  EXPECT_TRUE(s.has("ran longer than 250 ms in on_update of marker 1; disabled")) << s.console();
}

TEST(Limits, TheMainChunkIsStoppedByTimeAndTheLastGoodSceneStays) {
  SceneFixture s;
  const auto good = s.write("good.lua", "marker(1, { media = text \"good\" })\n");
  ASSERT_TRUE(s.runtime.load(good));
  const auto bad = s.write("bad.lua", "local s = string.rep(string.rep(\"x\", 1024), 4 * 1024)\n"
                                      "while true do local u = s:upper() end\n");
  const auto t0 = Clock::now();
  EXPECT_FALSE(s.runtime.load(bad));
  EXPECT_LT(seconds_since(t0), 3.0);
  // Line 2 normally; on a loaded machine the 4 MiB string.rep of line 1 could itself use up the 250 ms of wall time.
  const std::string& e = s.runtime.status().error;
  EXPECT_TRUE(e.ends_with("/bad.lua:2: ran longer than 250 ms while loading the scene") ||
              e.ends_with("/bad.lua:1: ran longer than 250 ms while loading the scene"))
      << e;
  EXPECT_EQ(s.update({track(1, 100, 100)}).at(0).media.text, "good");
}

// Many calls that each stay within their own bound: once the frame's 150 ms are used, the rest wait for the next
// frame (not disabled), so the frame ends at about a fifth of a second instead of more than one.
TEST(Limits, AFramesCallsTogetherAreBounded) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker({from = 0, to = 39}, { on_update = function(m)
  local t = os.clock() while os.clock() - t < 0.03 do end
  print("ran", m.id)
end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  std::vector<TrackedMarker> all;
  for (int id = 0; id < 40; ++id) all.push_back(track(id, 10 + 15 * id, 100, 10));
  const auto t0 = Clock::now();
  s.update(all);
  EXPECT_LT(seconds_since(t0), 0.9);   // 40 x 30 ms = 1.2 s without the frame bound
  EXPECT_LT(s.printed().size(), 20u);
  EXPECT_TRUE(s.has("scene.lua: the scene's calls took over 150 ms on this frame; its other on_update and text calls "
                    "wait for the next frame"))
      << s.console();
  EXPECT_FALSE(s.has("disabled")) << s.console();
  // The next frames start where this one stopped, so each marker gets its turn.
  auto all_ran = [&] {
    for (int id = 0; id < 40; ++id)
      if (!s.has("ran\t" + std::to_string(id))) return false;
    return true;
  };
  for (int frame = 0; frame < 60 && !all_ran(); ++frame) s.update(all);
  EXPECT_TRUE(all_ran()) << s.console();
}

// ---- what one library call does ---------------------------------------------------------------------------------

TEST(Limits, PatternsWithOneQuantifierOrABalanceOnLongStringsAreRefused) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"lua(local a = ("a"):rep(1e6)
local digits = ("1"):rep(1e6)
local open = ("("):rep(1e5)
marker(1, { on_update = function(m) return a:find(".-b") end })
marker(2, { on_update = function(m) return a:find("a*b") end })
marker(3, { on_update = function(m) return digits:match("%d+y") end })
marker(4, { on_update = function(m) return open:find("%b()") end })
marker(5, { on_update = function(m) for w in a:gmatch("a-b") do end end })
marker(6, { on_update = function(m)
  -- the same quantifiers on ordinary text: short runs of what they match, so cheap, and allowed
  local text = ("word 12 (x) "):rep(20000)
  local n = select(2, text:gsub("%d+", "N"))
  print(n, text:find("%b()"), text:find("^w%a*"), #text:match("^.-$"))
end })
)lua");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto t0 = Clock::now();
  s.update({track(1, 100, 100), track(2, 200, 100), track(3, 300, 100), track(4, 400, 100), track(5, 500, 100),
            track(6, 600, 100)});
  EXPECT_LT(seconds_since(t0), 3.0);
  const auto l = s.lines("too costly");
  ASSERT_EQ(l.size(), 5u) << s.console();
  EXPECT_NE(l[0].text.find("scene.lua:4: pattern '.-b' is too costly for a scene: on a 1000000-character string it "
                           "could take about 4e+12 steps in one call (at most 1e+07); shorten the string, anchor the "
                           "pattern with ^, or search in pieces (in on_update of marker 1)"),
            std::string::npos)
      << l[0].text;
  EXPECT_NE(l[1].text.find("scene.lua:5: pattern 'a*b'"), std::string::npos) << l[1].text;
  EXPECT_NE(l[2].text.find("scene.lua:6: pattern '%d+y'"), std::string::npos) << l[2].text;
  EXPECT_NE(l[3].text.find("scene.lua:7: pattern '%b()' is too costly for a scene: on a 100000-character string"),
            std::string::npos)
      << l[3].text;
  EXPECT_NE(l[4].text.find("scene.lua:8: pattern 'a-b'"), std::string::npos) << l[4].text;
  // Marker 6's ordinary searches run: on this frame, or on the next ones when the refusals above took the frame's
  // 150 ms (the sanitizer build on a loaded machine: CI run of 2026-11-27).
  for (int frame = 0; frame < 3 && !s.has("20000\t9\t1\t240000"); ++frame)
    s.update({track(6, 600, 100)});
  EXPECT_TRUE(s.has("20000\t9\t1\t240000")) << s.console();
}

TEST(Limits, LongPlainSearchesForLongTextsAreRefused) {
  SceneFixture s;
  // 4e5 x 1e4 steps, over the 2e9 allowed; the searches of line 4 stay short (under ASan on a loaded machine too).
  const auto p = s.write("scene.lua", R"(local a = ("a"):rep(4e5)
local needle = ("a"):rep(1e4) .. "b"
print(pcall(string.find, a, needle, 1, true))
print(a:find("aab", 1, true), a:find("b"))
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_TRUE(s.has("false\t")) << s.console();
  EXPECT_TRUE(s.has("too costly")) << s.console();
  EXPECT_TRUE(s.has("nil\tnil")) << s.console();
}

// Library calls whose one call is not bounded by the memory cap.
TEST(Limits, UnboundedLibraryCallsAreRefusedOrCut) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
print("rep", #string.rep("", 1e15), #(""):rep(1e15, ""), #string.rep("ab", 3, ""))
print(pcall(table.move, {}, 1, 1e15, 2))
local long = setmetatable({}, { __len = function() return 1e15 end })
print(pcall(table.insert, long, 1, "x"))
print(pcall(table.remove, long, 1))
local big = {} for i = 1, 300000 do big[i] = 300000 - i end
print(pcall(table.sort, big))
local few = {} for i = 1, 1000 do few[i] = 1000 - i end
table.sort(few, function(a, b) return a < b end)
print("sorted", few[1], few[1000])
print(load(string.rep(string.rep(" ", 1024), 2 * 1024)))
local pieces = 0
print(load(function() pieces = pieces + 1 if pieces <= 3 then return string.rep(string.rep(" ", 1024), 512) end end))
print(load(function() pieces = pieces + 1 if pieces <= 6 then return "local x = 1 " end end)())
local t = {1, 2, 3} table.insert(t, 1, 0) table.remove(t, 2) print(table.concat(table.move(t, 1, 3, 2), ","))
)");
  const auto t0 = Clock::now();
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_LT(seconds_since(t0), 5.0);
  const std::string c = s.console();
  EXPECT_TRUE(s.has("rep\t0\t0\t6")) << c;
  EXPECT_TRUE(s.has("false\ttable.move would move 1000000000000000 elements in one call; a scene may "
                    "move at most 4194304")) << c;
  EXPECT_TRUE(s.has("false\ttable.insert would move 1000000000000000 elements")) << c;
  EXPECT_TRUE(s.has("false\ttable.remove would move 999999999999999 elements")) << c;
  EXPECT_TRUE(s.has("false\ttable.sort of 300000 elements without a comparison function is too long"))
      << c;
  EXPECT_TRUE(s.has("sorted\t0\t999")) << c;
  EXPECT_TRUE(s.has("nil\tload: a chunk of 2097152 bytes is too long for a scene (at most 1048576)")) << c;
  EXPECT_TRUE(s.has("nil\tload: a chunk of more than 1048576 bytes is too long for a scene")) << c;
  EXPECT_TRUE(s.has("0,0,2,3")) << c;
}

// ---- failures that repeat ---------------------------------------------------------------------------------------

// Deep recursion cost 570 ms on every frame: disabled at once, whether the stack overflows first or the call's time
// runs out first (on a loaded machine). Through metamethods the C stack overflows after 200 levels, at once.
TEST(Limits, AStackOverflowIsDisabledAtOnce) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(local function down(n) return 1 + down(n + 1) end
local loop = setmetatable({}, { __index = function(t, k) return t[k] end })
marker(1, { media = text "one", on_update = function(m) return down(1) end })
marker(2, { on_update = function(m) return loop.x end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  for (int i = 0; i < 2; ++i) s.update({track(1, 100, 100), track(2, 300, 100)});
  auto l = s.lines("on_update of marker 1; disabled until the scene reloads");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_TRUE(l[0].text.find("/scene.lua:1: stack overflow") != std::string::npos ||
              l[0].text.find("/scene.lua:1: ran longer than 250 ms") != std::string::npos)
      << l[0].text;
  l = s.lines("on_update of marker 2; disabled until the scene reloads");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_NE(l[0].text.find("stack overflow"), std::string::npos) << l[0].text;
  const auto t0 = Clock::now();
  const auto ov = s.update({track(1, 100, 100), track(2, 300, 100)});
  EXPECT_LT(seconds_since(t0), 0.5);
  EXPECT_TRUE(find_overlay(ov, 1));
  EXPECT_EQ(s.lines("disabled until").size(), 2u) << s.console();
  EXPECT_EQ(s.lines("disabled until").at(0).repeats, 1);
}

TEST(Limits, ErrorsOnEveryFrameDisableTheCallback) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(marker(1, { media = text "one", on_update = function(m)
  print("tried") local t = nil return t.x
end })
marker(2, { on_update = function(m) print("two") end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(find_overlay(s.update({track(1, 100, 100), track(2, 300, 100)}), 1));
  EXPECT_EQ(s.count_printed("tried"), 3);
  EXPECT_EQ(s.count_printed("two"), 5);
  const auto l = s.lines("disabled after");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_TRUE(l[0].text.starts_with("on_update disabled after failing 3 frames in a row: ")) << l[0].text;
  EXPECT_TRUE(l[0].text.ends_with("/scene.lua:2: attempt to index a nil value (local 't') (in on_update of marker 1); "
                                  "it runs again when the scene reloads"))
      << l[0].text;
}

TEST(Limits, AnErrorThatStopsRepeatingIsNotDisabled) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(local n = 0
marker(1, { on_update = function(m) n = n + 1 if n % 3 ~= 0 then error("odd frame") end print("fine", n) end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  for (int i = 0; i < 9; ++i) s.update({track(1, 100, 100)});
  EXPECT_EQ(s.count_printed("fine\t9"), 1) << s.console();
  EXPECT_FALSE(s.has("disabled")) << s.console();
}

// A huge error message, or an error object whose __tostring loops, costs no more than a limit.
TEST(Limits, HugeAndEndlessErrorMessagesAreBounded) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker(1, { on_update = function(m) error(string.rep("x", 1e6)) end })   -- 1 MB: 10 MB took over the 250 ms watchdog under ASan
marker(2, { on_update = function(m)
  error(setmetatable({}, { __tostring = function() while true do end end }))
end })
marker(3, { media = text "three" })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto t0 = Clock::now();
  auto ov = s.update({track(1, 100, 100), track(2, 300, 100), track(3, 500, 100)});
  ov = s.update({track(1, 100, 100), track(2, 300, 100), track(3, 500, 100)});
  EXPECT_LT(seconds_since(t0), 4.0);
  const auto l = s.lines("xxxxxxxx");
  ASSERT_EQ(l.size(), 1u) << s.console().substr(0, 2000);
  EXPECT_LT(l[0].text.size(), 4200u);
  EXPECT_TRUE(s.has("scene.lua:4: instruction budget of 5000000 exceeded in on_update of marker 2; disabled") ||
              s.has("scene.lua:4: ran longer than 250 ms in on_update of marker 2; disabled"))
      << s.console().substr(s.console().size() - 1000);
  EXPECT_TRUE(find_overlay(ov, 3));
}

// ---- work the host does for a scene -------------------------------------------------------------------------------

// 200,000 unknown fields cost 386 ms a frame in warnings; only the first few are looked at.
TEST(Limits, ATableOfManyUnknownFieldsCostsAFewLines) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
local many = {}
for i = 1, 200000 do many[i] = i end
many.colour = "#ffffff"
local v = text("two", many)
marker(1, { media = text "one", on_update = function(m) return many end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_LE(s.lines("is ignored").size(), 32u) << s.console().substr(0, 3000);
  EXPECT_TRUE(s.has("scene.lua:5: text: a table of more than 32 fields; the others are not checked"))
      << s.console().substr(0, 3000);
  const auto before = s.runtime.status().console.size();
  const auto ov = s.update({track(1, 100, 100)});
  EXPECT_TRUE(find_overlay(ov, 1));
  EXPECT_LE(s.runtime.status().console.size() - before, 17u) << s.console().substr(0, 3000);
  EXPECT_TRUE(s.has("on_update of marker 1 returned a table of more than 16 fields; only media and place are read"))
      << s.console().substr(0, 3000);
}

TEST(Limits, PrintFloodsAreCutPerFrame) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker(1, { on_update = function(m)
  for i = 1, 1000 do print("line", i) end
  print(string.rep("more\n", 9999) .. "last")
  warn("a warning")
end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  s.update({track(1, 100, 100)});
  EXPECT_EQ(s.printed().size(), 100u);
  EXPECT_TRUE(s.has("scene.lua: 10901 more lines of print and warn output suppressed on this frame (a frame shows at "
                    "most 100 lines, 64 KiB)"))
      << s.console().substr(s.console().size() - 2000);
  s.update({track(1, 100, 100)});
  EXPECT_EQ(s.printed().back(), "line\t100");   // each frame starts afresh
  EXPECT_EQ(s.lines("10901 more lines of print and warn output").size(), 2u);
}

}  // namespace
}  // namespace arwb::script::test
