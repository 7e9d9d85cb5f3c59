// The Lua state behind a scene (lua_host.hpp): made with the counting allocator and the sandboxed libraries,
// called in script mode under fresh limits (load_chunk, pcall), and closed with its finalizers under a budget.
// The limits themselves are in lua_limits.cpp, the libraries in lua_libraries.cpp.
#include "script/lua_host_impl.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace arwb::script {
namespace {

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
  open_sandboxed_libraries(L_, host_.get());

  arm_budget();
}

LuaState::~LuaState() {
  if (!L_) return;
  // Finalizers run while closing: under a budget and the cap, and nobody to report to.
  host_->reporter = nullptr;
  arm_budget();
  enter_script_mode();
  lua_close(L_);
}

void LuaState::begin_frame() {
  host_->out_lines = 0;
  host_->out_bytes = 0;
  host_->suppressed = 0;
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
  arm_budget();   // the allocator's clock check uses this call's deadline
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
  if (rc == LUA_OK && !host_->exceeded && !host_->timed_out) {
    lua_remove(L_, base);
    return out;
  }
  // A call that passed a limit fails even when the script swallowed the error (a coroutine stopped inside
  // coroutine.resume, a pcall) and returned before the next hook.
  if (rc == LUA_OK) lua_pushnil(L_);
  out.ok = false;
  size_t len = 0;
  const char* msg = lua_tolstring(L_, -1, &len);
  // A message of many megabytes (error(string.rep("x", 1e7))) is cut before it is copied.
  if (!msg) out.message = "(error object is not a string)";
  else if (len > kMaxMessageBytes) out.message = std::string(msg, kMaxMessageBytes) + "...";
  else out.message.assign(msg, len);
  out.message = strip_traceback(std::move(out.message));
  lua_settop(L_, base - 1);
  out.budget = host_->exceeded;
  out.time = !out.budget && host_->timed_out;
  if (out.budget || out.time) {
    // The hook's own words, unless the allocator stopped it first (then the caller names the place).
    out.message = !host_->stop_message.empty() ? host_->stop_message
                                               : "ran longer than " + std::to_string(int(host_->limits.call_ms)) + " ms";
  }
  out.memory = !out.budget && !out.time &&
               (rc == LUA_ERRMEM || out.message == "not enough memory" || out.message.ends_with(": not enough memory"));
  out.overflow = !out.budget && !out.time && !out.memory &&
                 (rc == LUA_ERRERR || out.message.ends_with("stack overflow"));
  return out;
}

}  // namespace arwb::script
