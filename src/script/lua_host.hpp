// The sandboxed Lua state behind a scene: a counting allocator with a cap, an instruction budget and a wall-time
// bound per call, the trimmed standard library, and the rules that keep Lua errors and C++ apart.
//
// What bounds a call's time. A count hook (every kStep instructions) and a call hook (every function call, so
// every library function) check the budget and the clock, and the allocator checks the clock before any large
// block: a loop of library calls over long strings is stopped at its next call, one of string operators at its
// next allocation. What happens inside one library call is bounded before it starts: pattern searches by their
// worst case (w_guarded_pattern), string.rep of nothing, table.move/insert/remove by their range, table.sort by
// its length, load by the text's size. Finalizers run with hooks off (Lua 5.4), so a scene cannot have any:
// setmetatable refuses a metatable with __gc, and scenes cannot make userdata.
//
// Two modes. In script mode (inside LuaState::pcall and load_chunk) the memory cap applies and the garbage
// collector runs. In host mode (everywhere else, and inside the C functions the scene calls, see guarded()) the
// allocator never refuses and the collector is stopped, so no finalizer runs and no Lua API call made by C++ code
// can raise an error: C++ code reads tables with raw access only, and raises Lua errors only after its own
// objects are gone. A Lua error therefore never unwinds (longjmp) through a C++ frame with live destructors.
#pragma once

#include "script/scene_runtime.hpp"

#include <lua.hpp>

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>

namespace arwb::script {

struct SceneDef;

// Where a scene's messages go (the runtime's console).
class Reporter {
 public:
  virtual ~Reporter() = default;
  virtual void report(int level, const std::string& text) = 0;   // 0 print, 1 warning, 2 error
};

// What the C functions of a state need; reachable from any thread of it through lua_getextraspace.
struct Host {
  ScriptLimits limits;
  Reporter* reporter = nullptr;
  std::string path;              // the scene file as given to load()
  std::string display;           // the file as Lua names it in messages (see chunk_display_name)
  std::filesystem::path dir;     // the scene's folder: media paths resolve inside it
  SceneDef* building = nullptr;  // the scene being declared while its main chunk runs; null afterwards
  // Allocator: bytes held by the state, exactly (every block's size as Lua reports it).
  std::size_t used = 0;
  std::size_t peak = 0;
  std::size_t host_bytes = 0;    // allocated in host mode since the last collect_garbage() (the GC was stopped)
  bool script_mode = false;
  // Instruction budget and wall time of the current call. Once either is passed, every instruction and every call
  // fails again, so a pcall inside the script cannot swallow it and go on.
  long long spent = 0;
  bool exceeded = false;
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  bool timed_out = false;
  std::string stop_message;      // "file:line: ..." as the hook raised it (an error handler may replace it)
  // print and warn output since begin_frame(), and the lines not shown.
  int out_lines = 0;
  std::size_t out_bytes = 0;
  long long suppressed = 0;
  // warn(): pieces of the message being built, and whether warnings are shown.
  std::string warning;
  bool warnings_on = true;
};

Host& host_of(lua_State* L);

// How Lua shows a file name in messages for chunkname "@path" (luaO_chunkid): the path itself, or "..." and
// its last 56 characters when longer than 59.
std::string chunk_display_name(const std::string& path);

// The position of the Lua code `level` calls up ("scene.lua:5: " and 5), or empty and 0 for C code.
struct Where {
  std::string prefix;
  int line = 0;
};
Where where(lua_State* L, int level = 1);

// Thrown inside guarded() to raise a Lua error with this message (positions included by the thrower).
struct LuaFail {
  std::string message;
};

// Runs the body of a C function called from Lua in host mode. C++ exceptions (LuaFail or any other) become a
// Lua error raised after the body's objects are destroyed. The body must not call Lua API functions that can
// raise errors (luaL_check*, metamethod-invoking accessors); in host mode allocation does not fail.
template <class F>
int guarded(lua_State* L, F&& body);

class LuaState {
 public:
  // A fresh sandboxed state (base, coroutine, table, string, math, utf8, and os.clock/time/date only) in host
  // mode. Throws std::runtime_error when Lua cannot create it.
  LuaState(const ScriptLimits& limits, Reporter* reporter, const std::string& path);
  ~LuaState();
  LuaState(const LuaState&) = delete;
  LuaState& operator=(const LuaState&) = delete;

  lua_State* L() const { return L_; }
  Host& host() { return *host_; }

  struct Outcome {
    bool ok = true;
    std::string message;   // the error, "file:line: message" when Lua knew the place; no traceback
    bool budget = false;   // stopped by the instruction budget
    bool time = false;     // stopped by the wall-time bound (ScriptLimits::call_ms)
    bool memory = false;   // refused by the memory cap
    bool overflow = false; // the Lua stack (or the C stack) overflowed: deep recursion, costly to repeat
  };
  // Compiles text (mode "t") as chunk "@path" in script mode; on success the function is on the stack.
  Outcome load_chunk(const std::string& text);
  // Calls the function below its nargs arguments in script mode, under a fresh instruction budget and wall-time
  // bound, with a message handler; leaves nresults on success, nothing on failure. Messages are cut to
  // kMaxMessageBytes.
  Outcome pcall(int nargs, int nresults);
  // Starts a frame's output count (print and warn lines; see ScriptLimits::output_lines_per_frame).
  void begin_frame();
  // Lines of output suppressed since begin_frame().
  long long suppressed_output() const { return host_->suppressed; }
  // Lets the collector catch up with what was allocated in host mode (where it is stopped), in script mode so
  // finalizers run under the budget and the cap. Call once per frame.
  void collect_garbage();
  // Milliseconds spent in script mode since the state was made.
  double script_ms() const { return script_ms_; }

 private:
  void enter_script_mode();
  void leave_script_mode();
  void arm_budget();

  std::unique_ptr<Host> host_;
  lua_State* L_ = nullptr;
  double script_ms_ = 0;
};

// The longest error message kept, and the longest text load() and a scene file may have: Lua compiles text
// with no hook running (about 0.1 s a megabyte here).
constexpr std::size_t kMaxMessageBytes = 4000;
constexpr std::size_t kMaxChunkBytes = 1u << 20;

// For tests only: a C function every new state gets as the global `name` (one at a time), to simulate a library
// call that never returns. Never set outside tests.
void set_test_global(const char* name, lua_CFunction f);

// Switches to host mode for the life of the object, back to the previous mode after.
void host_mode_enter(lua_State* L, bool* was_script);
void host_mode_leave(lua_State* L, bool was_script);

template <class F>
int guarded(lua_State* L, F&& body) {
  bool was_script = false;
  host_mode_enter(L, &was_script);
  int n = -1;
  try {
    n = body();
  } catch (const LuaFail& e) {
    lua_pushlstring(L, e.message.data(), e.message.size());
  } catch (const std::exception& e) {
    lua_pushstring(L, e.what());
  } catch (...) {
    lua_pushliteral(L, "unknown C++ exception");
  }
  host_mode_leave(L, was_script);
  if (n < 0) return lua_error(L);   // only the message is on the stack above the arguments; nothing to destroy
  return n;
}

}  // namespace arwb::script
