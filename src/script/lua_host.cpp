#include "script/lua_host.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

namespace arwb::script {
namespace {

// The hook fires every kStep instructions at most; the last step before the budget is cut to land exactly on it.
constexpr long long kStep = 100'000;

// ---- allocator -------------------------------------------------------------------------------------------------

// Exact accounting: Lua passes the block's real size as osize whenever ptr is not null (when ptr is null, osize
// is a type tag, not a size). Shrinking and freeing never fail; growing fails past the cap in script mode only.
void* counting_alloc(void* ud, void* ptr, std::size_t osize, std::size_t nsize) {
  Host* h = static_cast<Host*>(ud);
  const std::size_t old = ptr ? osize : 0;
  if (nsize == 0) {
    std::free(ptr);
    h->used -= old;
    return nullptr;
  }
  if (nsize > old && h->script_mode) {
    const std::size_t grow = nsize - old;
    const std::size_t cap = h->limits.memory_bytes;
    if (h->used > cap || grow > cap - h->used) return nullptr;
  }
  void* p = std::realloc(ptr, nsize);
  if (!p) return nullptr;
  if (!h->script_mode && nsize > old) h->host_bytes += nsize - old;
  h->used = h->used - old + nsize;
  h->peak = std::max(h->peak, h->used);
  return p;
}

// ---- instruction budget ----------------------------------------------------------------------------------------

void budget_hook(lua_State* L, lua_Debug* ar) {
  Host& h = host_of(L);
  h.spent += lua_gethookcount(L);
  const long long budget = h.limits.instructions_per_call;
  if (h.spent < budget) {
    lua_sethook(L, budget_hook, LUA_MASKCOUNT, static_cast<int>(std::min(kStep, budget - h.spent)));
    return;
  }
  // Past the budget: every further instruction fails too, so a pcall inside the script cannot swallow it and
  // carry on looping.
  h.exceeded = true;
  lua_sethook(L, budget_hook, LUA_MASKCOUNT, 1);
  lua_getinfo(L, "Sl", ar);
  if (ar->currentline > 0)
    lua_pushfstring(L, "%s:%d: instruction budget of %I exceeded", ar->short_src, ar->currentline,
                    static_cast<lua_Integer>(budget));
  else
    lua_pushfstring(L, "instruction budget of %I exceeded", static_cast<lua_Integer>(budget));
  lua_error(L);
}

// ---- message handler, print, load, warn, panic -----------------------------------------------------------------

// Lua's pattern matcher backtracks inside one C call, where the instruction budget cannot see it: 400 "a"s
// searched for ".-.-.-.-b" would take hours. Its worst case is about len^(q + 1) steps for q backtracking
// quantifiers (* + -), or len^q when anchored with ^, so patterns with two or more of them are refused on
// subjects long enough to pass kMaxPatternSteps. Scenes match short labels; a real search still passes.
constexpr double kMaxPatternSteps = 1e8;

size_t skip_set(std::string_view p, size_t i) {   // p[i] == '['; returns the index after the closing ']'
  ++i;
  if (i < p.size() && p[i] == '^') ++i;
  do {   // a ']' right after '[' or '[^' is a member, as in Lua
    if (i >= p.size()) return p.size();
    i += p[i] == '%' ? 2 : 1;
  } while (i < p.size() && p[i] != ']');
  return i + 1;
}

int backtracking_quantifiers(std::string_view p) {
  int q = 0;
  size_t i = !p.empty() && p[0] == '^' ? 1 : 0;
  while (i < p.size()) {
    size_t end;
    if (p[i] == '%' && i + 1 < p.size() && p[i + 1] == 'b') {
      i += 4;   // %bxy
      continue;
    }
    if (p[i] == '%' && i + 1 < p.size() && p[i + 1] == 'f') {
      i = skip_set(p, i + 2);   // %f[set]
      continue;
    }
    if (p[i] == '(' || p[i] == ')') {
      ++i;
      continue;
    }
    if (p[i] == '%') end = i + 2;
    else if (p[i] == '[') end = skip_set(p, i);
    else end = i + 1;
    if (end < p.size() && (p[end] == '*' || p[end] == '+' || p[end] == '-')) {
      ++q;
      ++end;
    } else if (end < p.size() && p[end] == '?') {
      ++end;
    }
    i = end;
  }
  return q;
}

// string.find, match, gmatch and gsub, checked first (upvalue 1: the original; upvalue 2: true for find, whose
// fourth argument asks for a plain search).
int w_guarded_pattern(lua_State* L) {
  const bool plain = lua_toboolean(L, lua_upvalueindex(2)) && lua_toboolean(L, 4);
  if (!plain && lua_type(L, 1) == LUA_TSTRING && lua_type(L, 2) == LUA_TSTRING) {
    size_t len = 0, plen = 0;
    lua_tolstring(L, 1, &len);
    const char* pat = lua_tolstring(L, 2, &plen);
    const std::string_view pv(pat, plen);
    const int q = backtracking_quantifiers(pv);
    const bool anchored = plen > 0 && pat[0] == '^';
    if (q >= 2 && std::pow(double(len) + 1, q + (anchored ? 0 : 1)) > kMaxPatternSteps) {
      // No C++ objects here: luaL_error does not return.
      lua_pushlstring(L, pat, plen > 40 ? 40 : plen);
      return luaL_error(L,
                        "pattern '%s' is too costly for a scene: %d backtracking quantifiers on a %d-character "
                        "string could take hours (shorten the string, anchor the pattern with ^, or split the search)",
                        lua_tostring(L, -1), q, static_cast<int>(len));
    }
  }
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
  return lua_gettop(L);
}

// The error as a string, with no traceback added.
int message_handler(lua_State* L) {
  if (lua_type(L, 1) == LUA_TSTRING) return 1;
  if (luaL_callmeta(L, 1, "__tostring") && lua_type(L, -1) == LUA_TSTRING) return 1;
  if (lua_type(L, 1) == LUA_TNUMBER) {
    lua_pushstring(L, lua_tostring(L, 1));
    return 1;
  }
  lua_pushfstring(L, "(error object is a %s value)", luaL_typename(L, 1));
  return 1;
}

// print(...): tostring of each argument, tab-separated, one console line per line of text.
int w_print(lua_State* L) {
  // Lua part first (tostring may run __tostring metamethods and fail): no C++ objects live here.
  const int n = lua_gettop(L);
  luaL_Buffer b;
  luaL_buffinit(L, &b);
  for (int i = 1; i <= n; ++i) {
    if (i > 1) luaL_addchar(&b, '\t');
    luaL_tolstring(L, i, nullptr);
    luaL_addvalue(&b);
  }
  luaL_pushresult(&b);
  return guarded(L, [&] {
    size_t len = 0;
    const char* s = lua_tolstring(L, -1, &len);
    Host& h = host_of(L);
    if (h.reporter) {
      std::string all(s, len);
      size_t start = 0;
      while (true) {
        const size_t nl = all.find('\n', start);
        h.reporter->report(0, all.substr(start, nl == std::string::npos ? std::string::npos : nl - start));
        if (nl == std::string::npos) break;
        start = nl + 1;
      }
    }
    return 0;
  });
}

// load(chunk [, chunkname [, mode [, env]]]): text only, whatever mode asks; the environment defaults to the
// scene's (sandboxed) globals.
int w_load(lua_State* L) {
  const int n = lua_gettop(L);
  if (lua_type(L, 1) == LUA_TSTRING) {
    size_t len = 0;
    const char* s = lua_tolstring(L, 1, &len);
    if (len > 0 && s[0] == LUA_SIGNATURE[0]) {
      luaL_pushfail(L);
      lua_pushliteral(L, "load: binary chunks are not allowed in scenes (text only)");
      return 2;
    }
  }
  lua_pushvalue(L, lua_upvalueindex(1));   // the standard load
  lua_pushvalue(L, 1);
  if (n >= 2) lua_pushvalue(L, 2);
  else lua_pushnil(L);
  lua_pushliteral(L, "t");
  int nargs = 3;
  if (n >= 4) {   // an explicit env, even nil, as the standard load distinguishes none from nil
    lua_pushvalue(L, 4);
    nargs = 4;
  }
  lua_call(L, nargs, LUA_MULTRET);
  return lua_gettop(L) - n;
}

void warn_function(void* ud, const char* msg, int tocont) {
  Host* h = static_cast<Host*>(ud);
  try {
    if (!tocont && h->warning.empty() && msg[0] == '@') {   // control message
      if (std::strcmp(msg, "@on") == 0) h->warnings_on = true;
      if (std::strcmp(msg, "@off") == 0) h->warnings_on = false;
      return;
    }
    h->warning += msg;
    if (tocont) return;
    std::string text = "warning: " + h->warning;
    h->warning.clear();
    if (h->reporter && h->warnings_on) h->reporter->report(1, text);
  } catch (...) {
    h->warning.clear();
  }
}

// A collector step worth argument 1 kilobytes of allocation.
int gc_step(lua_State* L) {
  lua_gc(L, LUA_GCSTEP, static_cast<int>(lua_tointeger(L, 1)));
  return 0;
}

int panic(lua_State* L) {
  const char* msg = lua_tostring(L, -1);
  std::fprintf(stderr, "arwb: unprotected Lua error: %s\n", msg ? msg : "(not a string)");
  return 0;   // Lua aborts
}

std::string strip_traceback(std::string s) {
  const size_t tb = s.find("\nstack traceback:");
  if (tb != std::string::npos) s.erase(tb);
  return s;
}

}  // namespace

Host& host_of(lua_State* L) { return **static_cast<Host**>(lua_getextraspace(L)); }

std::string chunk_display_name(const std::string& path) {
  // luaO_chunkid: "@" + path fits in LUA_IDSIZE (terminator included), else "..." and the tail.
  constexpr size_t kIdSize = LUA_IDSIZE;
  if (path.size() + 1 <= kIdSize) return path;
  const size_t tail = kIdSize - 3 - 1;
  return "..." + path.substr(path.size() - tail);
}

Where where(lua_State* L, int level) {
  Where w;
  lua_Debug ar;
  if (lua_getstack(L, level, &ar) && lua_getinfo(L, "Sl", &ar) && ar.currentline > 0) {
    w.line = ar.currentline;
    w.prefix = std::string(ar.short_src) + ":" + std::to_string(ar.currentline) + ": ";
  }
  return w;
}

void host_mode_enter(lua_State* L, bool* was_script) {
  Host& h = host_of(L);
  *was_script = h.script_mode;
  if (h.script_mode) {
    h.script_mode = false;
    lua_gc(L, LUA_GCSTOP);
  }
}

void host_mode_leave(lua_State* L, bool was_script) {
  Host& h = host_of(L);
  if (was_script && !h.script_mode) {
    h.script_mode = true;
    lua_gc(L, LUA_GCRESTART);
  }
}

LuaState::LuaState(const ScriptLimits& limits, Reporter* reporter, const std::string& path)
    : host_(std::make_unique<Host>()) {
  host_->limits = limits;
  host_->limits.instructions_per_call = std::max(1LL, limits.instructions_per_call);
  host_->reporter = reporter;
  host_->path = path;
  host_->display = chunk_display_name(path);
  std::filesystem::path dir = std::filesystem::path(path).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  const std::filesystem::path abs = std::filesystem::absolute(dir, ec);
  host_->dir = ec ? dir : abs;

  L_ = lua_newstate(counting_alloc, host_.get());
  if (!L_) throw std::runtime_error("cannot create a Lua state");
  *static_cast<Host**>(lua_getextraspace(L_)) = host_.get();
  lua_gc(L_, LUA_GCSTOP);   // host mode
  lua_atpanic(L_, panic);
  lua_setwarnf(L_, warn_function, host_.get());

  // The library, minus what reaches outside the sandbox.
  const luaL_Reg libraries[] = {{LUA_GNAME, luaopen_base},          {LUA_COLIBNAME, luaopen_coroutine},
                                 {LUA_TABLIBNAME, luaopen_table},    {LUA_STRLIBNAME, luaopen_string},
                                 {LUA_MATHLIBNAME, luaopen_math},    {LUA_UTF8LIBNAME, luaopen_utf8}};
  for (const luaL_Reg& lib : libraries) {
    luaL_requiref(L_, lib.name, lib.func, 1);
    lua_pop(L_, 1);
  }
  // os: only clock, time and date.
  luaL_requiref(L_, LUA_OSLIBNAME, luaopen_os, 0);
  lua_createtable(L_, 0, 3);
  for (const char* name : {"clock", "time", "date"}) {
    lua_getfield(L_, -2, name);
    lua_setfield(L_, -2, name);
  }
  lua_setglobal(L_, "os");
  lua_pop(L_, 1);
  for (const char* name : {"dofile", "loadfile", "collectgarbage", "require", "package", "io", "debug"}) {
    lua_pushnil(L_);
    lua_setglobal(L_, name);
  }
  lua_getglobal(L_, "string");
  lua_pushnil(L_);
  lua_setfield(L_, -2, "dump");
  for (const char* name : {"find", "match", "gmatch", "gsub"}) {
    lua_getfield(L_, -1, name);
    lua_pushboolean(L_, std::strcmp(name, "find") == 0);
    lua_pushcclosure(L_, w_guarded_pattern, 2);
    lua_setfield(L_, -2, name);
  }
  lua_pop(L_, 1);
  lua_getglobal(L_, "load");
  lua_pushcclosure(L_, w_load, 1);
  lua_setglobal(L_, "load");
  lua_pushcfunction(L_, w_print);
  lua_setglobal(L_, "print");

  lua_sethook(L_, budget_hook, LUA_MASKCOUNT, static_cast<int>(std::min(kStep, host_->limits.instructions_per_call)));
}

LuaState::~LuaState() {
  if (!L_) return;
  // Finalizers run while closing: under a budget and the cap, and nobody to report to.
  host_->reporter = nullptr;
  arm_budget();
  enter_script_mode();
  lua_close(L_);
}

void LuaState::arm_budget() {
  host_->spent = 0;
  host_->exceeded = false;
  lua_sethook(L_, budget_hook, LUA_MASKCOUNT, static_cast<int>(std::min(kStep, host_->limits.instructions_per_call)));
}

void LuaState::enter_script_mode() {
  if (host_->script_mode) return;
  host_->script_mode = true;
  lua_gc(L_, LUA_GCRESTART);
}

void LuaState::leave_script_mode() {
  if (!host_->script_mode) return;
  host_->script_mode = false;
  lua_gc(L_, LUA_GCSTOP);
}

void LuaState::collect_garbage() {
  const std::size_t kb = std::min<std::size_t>(host_->host_bytes / 1024 + 1, 1u << 20);
  host_->host_bytes = 0;
  lua_checkstack(L_, 4);
  lua_pushcfunction(L_, gc_step);
  lua_pushinteger(L_, static_cast<lua_Integer>(kb));
  pcall(1, 0);   // a finalizer's error is already a warning; nothing else can fail here
}

LuaState::Outcome LuaState::load_chunk(const std::string& text) {
  Outcome out;
  const std::string chunkname = "@" + host_->path;
  enter_script_mode();
  const int rc = luaL_loadbufferx(L_, text.data(), text.size(), chunkname.c_str(), "t");
  leave_script_mode();
  if (rc == LUA_OK) return out;
  out.ok = false;
  out.memory = rc == LUA_ERRMEM;
  const char* msg = lua_tostring(L_, -1);
  out.message = msg ? msg : "(error object is not a string)";
  lua_pop(L_, 1);
  if (out.message.find("binary chunk") != std::string::npos)
    out.message = host_->display + ": a scene is Lua source text; binary chunks are not allowed";
  return out;
}

LuaState::Outcome LuaState::pcall(int nargs, int nresults) {
  Outcome out;
  lua_checkstack(L_, 4);
  const int base = lua_gettop(L_) - nargs;   // the function's index
  lua_pushcfunction(L_, message_handler);
  lua_insert(L_, base);
  arm_budget();
  const auto t0 = std::chrono::steady_clock::now();
  enter_script_mode();
  const int rc = lua_pcall(L_, nargs, nresults, base);
  leave_script_mode();
  script_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (rc == LUA_OK) {
    lua_remove(L_, base);
    return out;
  }
  out.ok = false;
  const char* msg = lua_tostring(L_, -1);
  out.message = strip_traceback(msg ? msg : "(error object is not a string)");
  lua_settop(L_, base - 1);
  out.budget = host_->exceeded;
  out.memory = !out.budget && (rc == LUA_ERRMEM || out.message == "not enough memory" ||
                               out.message.ends_with(": not enough memory"));
  return out;
}

}  // namespace arwb::script
