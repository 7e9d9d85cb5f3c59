// The limits of one call (lua_host.hpp says what bounds a call's time): the counting allocator, which holds the
// memory cap, and the count and call hooks, which hold the instruction budget and the wall-time bound.
#include "script/lua_host_impl.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>

namespace arwb::script {
namespace {

using Clock = std::chrono::steady_clock;

// The count hook fires every kStep instructions at most; the last step before the budget is cut to land exactly
// on it. Some single instructions cost time in proportion to a string's length (==, <, .. and indexing by a new
// long string), so the step is small: 100 such instructions on the longest strings the memory cap allows take
// under half a second, and a hook every 100 instructions costs under a tenth of Lua's speed. The call hook
// catches library functions at their call.
constexpr long long kStep = 100;
constexpr int kHookMask = LUA_MASKCOUNT | LUA_MASKCALL;
// Blocks at least this large are refused once the call is kAllocationGrace past its time: a loop of string
// operators (concatenation, indexing by a new long string) allocates but may call nothing. The grace lets the hooks,
// which know the line, stop the usual cases first.
constexpr std::size_t kTimedAllocation = 64u << 10;
constexpr auto kAllocationGrace = std::chrono::milliseconds(100);

// Pushes "file:line: " of the innermost Lua function on the stack (in a call hook, level 0 may be a C function).
void push_position(lua_State* L) {
  lua_Debug d;
  for (int level = 0; level < 8 && lua_getstack(L, level, &d); ++level) {
    if (lua_getinfo(L, "Sl", &d) && d.currentline > 0) {
      lua_pushfstring(L, "%s:%d: ", d.short_src, d.currentline);
      return;
    }
  }
  lua_pushliteral(L, "");
}

void limits_hook(lua_State* L, lua_Debug* ar) {
  Host& h = host_of(L);
  if (ar->event == LUA_HOOKCOUNT) h.spent += lua_gethookcount(L);
  const long long budget = h.limits.instructions_per_call;
  if (!h.exceeded && !h.timed_out) {
    if (h.spent >= budget) h.exceeded = true;
    else if (Clock::now() >= h.deadline) h.timed_out = true;
    else {
      if (ar->event == LUA_HOOKCOUNT)
        lua_sethook(L, limits_hook, kHookMask, static_cast<int>(std::min(kStep, budget - h.spent)));
      return;
    }
  }
  // Past a limit: every further instruction and call fails too, so a pcall inside the script cannot swallow it
  // and carry on looping.
  lua_sethook(L, limits_hook, kHookMask, 1);
  push_position(L);
  if (h.exceeded)
    lua_pushfstring(L, "instruction budget of %I exceeded", static_cast<lua_Integer>(budget));
  else
    lua_pushfstring(L, "ran longer than %d ms", static_cast<int>(h.limits.call_ms));
  lua_concat(L, 2);
  if (h.stop_message.empty()) {
    try {
      h.stop_message = lua_tostring(L, -1);
    } catch (...) {
    }
  }
  lua_error(L);
}

}  // namespace

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
    if (grow >= kTimedAllocation && (h->timed_out || Clock::now() >= h->deadline + kAllocationGrace)) {
      h->timed_out = true;
      return nullptr;
    }
  }
  void* p = std::realloc(ptr, nsize);
  if (!p) return nullptr;
  if (!h->script_mode && nsize > old) h->host_bytes += nsize - old;
  h->used = h->used - old + nsize;
  h->peak = std::max(h->peak, h->used);
  return p;
}

void LuaState::arm_budget() {
  host_->spent = 0;
  host_->exceeded = false;
  host_->timed_out = false;
  host_->stop_message.clear();
  host_->deadline = Clock::now() + std::chrono::microseconds(static_cast<long long>(host_->limits.call_ms * 1000));
  lua_sethook(L_, limits_hook, kHookMask, static_cast<int>(std::min(kStep, host_->limits.instructions_per_call)));
}

}  // namespace arwb::script
