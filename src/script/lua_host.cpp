#include "script/lua_host.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>
#include <cctype>

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

std::atomic<lua_CFunction> g_test_function{nullptr};
std::atomic<const char*> g_test_name{nullptr};

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

// ---- instruction budget and wall time ---------------------------------------------------------------------------

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

// ---- message handler, print, load, warn, panic -----------------------------------------------------------------

// Lua's pattern matcher works inside one C call, where neither hook can see it: ("a"):rep(1e6):find(".-b") takes
// about 10^12 steps. So each search is priced first, by an upper bound on the matcher's steps:
//   starts x (pattern length + 1) x product over quantified items (* + -) of (run + 1) x 2 per optional item (?)
//   x (scan + 1) per %bxy, where scan is the longest stretch from an x to the y that balances it (or to the end)
//   x (n + 1) per back-reference (%1 .. %9),
// where starts is 1 for a pattern anchored with ^ (find, match, gsub) and n + 1 otherwise, n is the string's
// length, and run is the longest stretch of the string that the item's class matches (a quantifier can stretch
// over no more; for "." it is n). %d+ on ordinary text is cheap; on a million digits it is not. A search priced
// above kMaxPatternSteps (10 million, 60 to 110 ms on this machine when loaded) is refused with the line.
// Patterns without special characters and plain finds go through memchr and memcmp, whose worst case is
// (n - m + 1) x m byte comparisons for a text of m bytes: refused above kMaxPlainSteps (about 0.1 s).
constexpr double kMaxPatternSteps = 1e7;
constexpr double kMaxPlainSteps = 2e9;
constexpr int kMaxRunScans = 4;   // quantified items whose runs are measured; later ones count as n

size_t skip_set(std::string_view p, size_t i) {   // p[i] == '['; returns the index after the closing ']'
  ++i;
  if (i < p.size() && p[i] == '^') ++i;
  do {   // a ']' right after '[' or '[^' is a member, as in Lua
    if (i >= p.size()) return p.size();
    i += p[i] == '%' ? 2 : 1;
  } while (i < p.size() && p[i] != ']');
  return std::min(i + 1, p.size());
}

// Does character c belong to class %k (the manual's 6.4.1; an upper-case letter is the complement)?
bool in_class(unsigned char c, unsigned char k) {
  bool r = false;
  switch (std::tolower(k)) {
    case 'a': r = std::isalpha(c); break;
    case 'c': r = std::iscntrl(c); break;
    case 'd': r = std::isdigit(c); break;
    case 'g': r = std::isgraph(c); break;
    case 'l': r = std::islower(c); break;
    case 'p': r = std::ispunct(c); break;
    case 's': r = std::isspace(c); break;
    case 'u': r = std::isupper(c); break;
    case 'w': r = std::isalnum(c); break;
    case 'x': r = std::isxdigit(c); break;
    default: return k == c;   // %. %% ...: the character itself
  }
  return std::isupper(k) ? !r : r;
}

// Does c match the single-character item ("x", ".", "%a", "[set]")?
bool item_matches(unsigned char c, std::string_view item) {
  if (item.empty()) return false;
  if (item[0] == '.') return true;
  if (item[0] == '%') return item.size() > 1 && in_class(c, static_cast<unsigned char>(item[1]));
  if (item[0] != '[') return static_cast<unsigned char>(item[0]) == c;
  const size_t end = item.back() == ']' && item.size() > 1 ? item.size() - 1 : item.size();
  size_t i = 1;
  bool negate = false;
  if (i < end && item[i] == '^') negate = true, ++i;
  while (i < end) {   // a ']' first is a member: it is before `end`
    if (item[i] == '%' && i + 1 < item.size()) {
      if (in_class(c, static_cast<unsigned char>(item[i + 1]))) return !negate;
      i += 2;
    } else if (i + 2 < end && item[i + 1] == '-') {
      if (static_cast<unsigned char>(item[i]) <= c && c <= static_cast<unsigned char>(item[i + 2])) return !negate;
      i += 3;
    } else {
      if (static_cast<unsigned char>(item[i]) == c) return !negate;
      ++i;
    }
  }
  return negate;
}

// The longest stretch %bxy scans from an x: to the y that balances it, or to the end of s.
double longest_balance(std::string_view s, char x, char y) {
  size_t best = 0;
  if (x == y) {   // the next x closes it
    size_t last = std::string_view::npos;
    for (size_t i = 0; i < s.size(); ++i)
      if (s[i] == x) {
        if (last != std::string_view::npos) best = std::max(best, i - last);
        last = i;
      }
    if (last != std::string_view::npos) best = std::max(best, s.size() - last);
    return static_cast<double>(best);
  }
  std::vector<size_t> open;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == y && !open.empty()) {
      best = std::max(best, i - open.back());
      open.pop_back();
    } else if (s[i] == x) {
      if (open.size() >= (1u << 16)) return static_cast<double>(s.size());   // deeper: count the whole string
      open.push_back(i);
    }
  }
  for (const size_t i : open) best = std::max(best, s.size() - i);
  return static_cast<double>(best);
}

// The longest stretch of s whose characters all match the item.
double longest_run(std::string_view s, std::string_view item) {
  size_t best = 0, run = 0;
  for (const char ch : s) {
    run = item_matches(static_cast<unsigned char>(ch), item) ? run + 1 : 0;
    best = std::max(best, run);
  }
  return static_cast<double>(best);
}

bool has_specials(std::string_view p) { return p.find_first_of("^$*+?.([%-") != std::string_view::npos; }

// The upper bound above (stops measuring once it is past kMaxPatternSteps).
double pattern_steps(std::string_view s, std::string_view p, bool anchors) {
  const double n = static_cast<double>(s.size());
  const bool anchored = anchors && !p.empty() && p[0] == '^';
  double steps = (anchored ? 1 : n + 1) * (static_cast<double>(p.size()) + 1);
  std::vector<std::string_view> quantified;
  size_t i = anchored ? 1 : 0;
  while (i < p.size()) {
    const char c = p[i];
    if (c == '(' || c == ')') {
      ++i;
      continue;
    }
    if (c == '%' && i + 1 < p.size() && p[i + 1] == 'b') {
      if (i + 3 < p.size() && steps <= kMaxPatternSteps) steps *= longest_balance(s, p[i + 2], p[i + 3]) + 1;
      i += 4;
      continue;
    }
    if (c == '%' && i + 1 < p.size() && p[i + 1] == 'f') {
      i = i + 2 < p.size() && p[i + 2] == '[' ? skip_set(p, i + 2) : i + 2;
      continue;
    }
    if (c == '%' && i + 1 < p.size() && p[i + 1] >= '0' && p[i + 1] <= '9') {
      steps *= n + 1;
      i += 2;
      continue;
    }
    const size_t end = std::min(p.size(), c == '%' ? i + 2 : c == '[' ? skip_set(p, i) : i + 1);
    if (end < p.size() && (p[end] == '*' || p[end] == '+' || p[end] == '-')) {
      quantified.push_back(p.substr(i, end - i));
      i = end + 1;
    } else if (end < p.size() && p[end] == '?') {
      steps *= 2;
      i = end + 1;
    } else {
      i = end;
    }
  }
  for (size_t k = 0; k < quantified.size(); ++k) {   // once past the limit, the rest count as n (for the message)
    const bool measure = k < kMaxRunScans && steps <= kMaxPatternSteps && steps * (n + 1) > kMaxPatternSteps;
    steps *= (measure ? longest_run(s, quantified[k]) : n) + 1;
  }
  return steps;
}

// string.find, match, gmatch and gsub, priced first (upvalue 1: the original; upvalue 2: 0 gmatch, whose ^ is no
// anchor, 1 match and gsub, 2 find, whose fourth argument asks for a plain search).
int w_guarded_pattern(lua_State* L) {
  const lua_Integer kind = lua_tointeger(L, lua_upvalueindex(2));
  if (lua_type(L, 1) == LUA_TSTRING && lua_type(L, 2) == LUA_TSTRING) {
    size_t len = 0, plen = 0;
    const char* subject = lua_tolstring(L, 1, &len);
    const char* pat = lua_tolstring(L, 2, &plen);
    const std::string_view sv(subject, len), pv(pat, plen);
    const bool plain = (kind == 2 && lua_toboolean(L, 4)) || (kind != 0 && !has_specials(pv));
    const double steps = plain ? (len >= plen ? double(len - plen + 1) * double(plen) : 0.0)
                               : pattern_steps(sv, pv, kind != 0);
    if (steps > (plain ? kMaxPlainSteps : kMaxPatternSteps)) {
      // No C++ objects here (a char array has no destructor): luaL_error does not return.
      char about[32];
      std::snprintf(about, sizeof about, "%.0e", steps);
      lua_pushlstring(L, pat, plen > 40 ? 40 : plen);
      return luaL_error(L,
                        "pattern '%s' is too costly for a scene: on a %I-character string it could take about %s "
                        "steps in one call (at most %s); shorten the string, anchor the pattern with ^, or search "
                        "in pieces",
                        lua_tostring(L, -1), static_cast<lua_Integer>(len), about, plain ? "2e+09" : "1e+07");
    }
  }
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
  return lua_gettop(L);
}

// ---- library functions whose one call could run unbounded -------------------------------------------------------

// The original function (upvalue 1) with the same arguments, after a wrapper's check.
int call_original(lua_State* L) {
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_insert(L, 1);
  lua_call(L, lua_gettop(L) - 1, LUA_MULTRET);
  return lua_gettop(L);
}

// Elements table.move, insert and remove may shift in one call (about 0.15 s), and the longest table.sort may
// order without a comparison function (with one, the hooks see every comparison). Neither range is bounded by
// memory: table.move({}, 1, 1e15, 2) or a __len of 1e15 loops over nils.
constexpr lua_Integer kMaxTableShift = 1 << 22;
constexpr lua_Integer kMaxSortLength = 1 << 18;

// string.rep of an empty string and separator does nothing n times: rep("", 1e15) would never return.
int w_rep(lua_State* L) {
  size_t len = 1, seplen = 0;
  if (lua_type(L, 1) == LUA_TSTRING) lua_tolstring(L, 1, &len);
  if (lua_type(L, 3) == LUA_TSTRING) lua_tolstring(L, 3, &seplen);
  const bool no_sep = lua_isnoneornil(L, 3) || (lua_type(L, 3) == LUA_TSTRING && seplen == 0);
  int isnum = 0;
  lua_tointegerx(L, 2, &isnum);
  if (lua_type(L, 1) == LUA_TSTRING && len == 0 && no_sep && isnum) {
    lua_pushliteral(L, "");
    return 1;
  }
  return call_original(L);
}

int shift_error(lua_State* L, const char* what, lua_Integer n) {
  return luaL_error(L, "%s would move %I elements in one call; a scene may move at most %I", what, n,
                    kMaxTableShift);
}

int w_table_move(lua_State* L) {   // table.move(a1, f, e, t [,a2])
  int okf = 0, oke = 0;
  const lua_Integer f = lua_tointegerx(L, 2, &okf), e = lua_tointegerx(L, 3, &oke);
  if (okf && oke && e >= f && (f <= 0 ? e >= kMaxTableShift + f : e - f >= kMaxTableShift))
    return shift_error(L, "table.move", e >= f && f > 0 ? e - f + 1 : kMaxTableShift + 1);
  return call_original(L);
}

// The length table.insert and remove shift over (may run __len, as they do).
lua_Integer length_for_shift(lua_State* L) {
  if (lua_type(L, 1) != LUA_TTABLE) return 0;
  return luaL_len(L, 1);
}

int w_table_insert(lua_State* L) {   // table.insert(t, [pos,] v): shifts #t - pos + 1
  if (lua_gettop(L) == 3) {
    int ok = 0;
    const lua_Integer pos = lua_tointegerx(L, 2, &ok);
    const lua_Integer n = length_for_shift(L);
    if (ok && pos >= 1 && pos <= n && n - pos >= kMaxTableShift) return shift_error(L, "table.insert", n - pos + 1);
  }
  return call_original(L);
}

int w_table_remove(lua_State* L) {   // table.remove(t [,pos]): shifts #t - pos
  if (lua_gettop(L) >= 2) {
    int ok = 0;
    const lua_Integer pos = lua_tointegerx(L, 2, &ok);
    const lua_Integer n = length_for_shift(L);
    if (ok && pos >= 1 && pos <= n && n - pos > kMaxTableShift) return shift_error(L, "table.remove", n - pos);
  }
  return call_original(L);
}

int w_table_sort(lua_State* L) {
  if (lua_isnoneornil(L, 2)) {
    const lua_Integer n = length_for_shift(L);
    if (n > kMaxSortLength)
      return luaL_error(L, "table.sort of %I elements without a comparison function is too long for one call in a "
                           "scene (at most %I; give a function, or sort in parts)", n, kMaxSortLength);
  }
  return call_original(L);
}

// setmetatable, refusing a metatable with __gc: Lua runs finalizers with hooks off, so a finalizer that loops
// could never be stopped, and Lua marks a table for finalization only if its metatable has __gc when it is set.
// Otherwise as the standard one.
int w_setmetatable(lua_State* L) {
  luaL_checktype(L, 1, LUA_TTABLE);
  const int t = lua_type(L, 2);
  luaL_argexpected(L, t == LUA_TNIL || t == LUA_TTABLE, 2, "nil or table");
  if (t == LUA_TTABLE) {
    lua_pushliteral(L, "__gc");
    const bool gc = lua_rawget(L, 2) != LUA_TNIL;
    lua_pop(L, 1);
    if (gc)
      return luaL_error(L, "setmetatable: a metatable with __gc is not allowed in a scene (finalizers run where no "
                           "time limit can stop them; use on_leave, or drop the table)");
  }
  if (luaL_getmetafield(L, 1, "__metatable") != LUA_TNIL) return luaL_error(L, "cannot change a protected metatable");
  lua_settop(L, 2);
  lua_setmetatable(L, 1);
  return 1;
}

// ---- message handler, output -------------------------------------------------------------------------------------

// Counts a line of output against the frame's allowance; false (and counted as suppressed) past it.
bool take_output(Host& h, std::size_t bytes) {
  if (h.out_lines >= h.limits.output_lines_per_frame || h.out_bytes + bytes > h.limits.output_bytes_per_frame) {
    ++h.suppressed;
    return false;
  }
  ++h.out_lines;
  h.out_bytes += bytes;
  return true;
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
    if (!h.reporter) return 0;
    // Past the frame's allowance lines are only counted; a line is cut where the console would cut it anyway.
    size_t start = 0;
    while (true) {
      const void* nl = std::memchr(s + start, '\n', len - start);
      const size_t end = nl ? static_cast<size_t>(static_cast<const char*>(nl) - s) : len;
      if (take_output(h, end - start))
        h.reporter->report(0, std::string(s + start, std::min(end - start, kMaxMessageBytes + 1)));
      if (!nl) break;
      start = end + 1;
    }
    return 0;
  });
}

// A scene's reader function for load, counting the text it gives (upvalue 1: the reader; 2: bytes so far), since
// Lua compiles each piece with no hook running.
int w_load_reader(lua_State* L) {
  lua_pushvalue(L, lua_upvalueindex(1));
  lua_call(L, 0, 1);
  if (lua_type(L, -1) == LUA_TSTRING) {
    size_t len = 0;
    lua_tolstring(L, -1, &len);
    const lua_Integer total = lua_tointeger(L, lua_upvalueindex(2)) + static_cast<lua_Integer>(len);
    if (total > static_cast<lua_Integer>(kMaxChunkBytes))
      return luaL_error(L, "load: a chunk of more than %I bytes is too long for a scene",
                        static_cast<lua_Integer>(kMaxChunkBytes));
    lua_pushinteger(L, total);
    lua_replace(L, lua_upvalueindex(2));
  }
  return 1;
}

// load(chunk [, chunkname [, mode [, env]]]): text only, whatever mode asks, at most kMaxChunkBytes; the
// environment defaults to the scene's (sandboxed) globals.
int w_load(lua_State* L) {
  const int n = lua_gettop(L);
  if (lua_type(L, 1) == LUA_TFUNCTION) {
    lua_pushvalue(L, 1);
    lua_pushinteger(L, 0);
    lua_pushcclosure(L, w_load_reader, 2);
    lua_replace(L, 1);
  }
  if (lua_type(L, 1) == LUA_TSTRING) {
    size_t len = 0;
    const char* s = lua_tolstring(L, 1, &len);
    if (len > 0 && s[0] == LUA_SIGNATURE[0]) {
      luaL_pushfail(L);
      lua_pushliteral(L, "load: binary chunks are not allowed in scenes (text only)");
      return 2;
    }
    if (len > kMaxChunkBytes) {   // compiling runs no hook
      luaL_pushfail(L);
      lua_pushfstring(L, "load: a chunk of %I bytes is too long for a scene (at most %I)",
                      static_cast<lua_Integer>(len), static_cast<lua_Integer>(kMaxChunkBytes));
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
    if (h->warning.size() <= kMaxMessageBytes) h->warning.append(msg, strnlen(msg, kMaxMessageBytes + 1));
    if (tocont) return;
    std::string text = "warning: " + h->warning;
    h->warning.clear();
    if (h->reporter && h->warnings_on && take_output(*h, text.size())) h->reporter->report(1, text);
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

void set_test_global(const char* name, lua_CFunction f) {
  g_test_name = name;
  g_test_function = f;
}

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
  for (const char* name : {"gmatch", "match", "gsub", "find"}) {
    lua_getfield(L_, -1, name);
    lua_pushinteger(L_, std::strcmp(name, "gmatch") == 0 ? 0 : std::strcmp(name, "find") == 0 ? 2 : 1);
    lua_pushcclosure(L_, w_guarded_pattern, 2);
    lua_setfield(L_, -2, name);
  }
  lua_getfield(L_, -1, "rep");
  lua_pushcclosure(L_, w_rep, 1);
  lua_setfield(L_, -2, "rep");
  lua_pop(L_, 1);
  lua_getglobal(L_, "table");
  const luaL_Reg table_guards[] = {
      {"move", w_table_move}, {"insert", w_table_insert}, {"remove", w_table_remove}, {"sort", w_table_sort}};
  for (const luaL_Reg& g : table_guards) {
    lua_getfield(L_, -1, g.name);
    lua_pushcclosure(L_, g.func, 1);
    lua_setfield(L_, -2, g.name);
  }
  lua_pop(L_, 1);
  lua_pushcfunction(L_, w_setmetatable);
  lua_setglobal(L_, "setmetatable");
  if (const lua_CFunction f = g_test_function.load()) {
    lua_pushcfunction(L_, f);
    lua_setglobal(L_, g_test_name.load());
  }
  lua_getglobal(L_, "load");
  lua_pushcclosure(L_, w_load, 1);
  lua_setglobal(L_, "load");
  lua_pushcfunction(L_, w_print);
  lua_setglobal(L_, "print");

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

void LuaState::arm_budget() {
  host_->spent = 0;
  host_->exceeded = false;
  host_->timed_out = false;
  host_->stop_message.clear();
  host_->deadline = Clock::now() + std::chrono::microseconds(static_cast<long long>(host_->limits.call_ms * 1000));
  lua_sethook(L_, limits_hook, kHookMask, static_cast<int>(std::min(kStep, host_->limits.instructions_per_call)));
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
