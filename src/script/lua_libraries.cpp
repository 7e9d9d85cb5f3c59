// The standard library as a scene gets it (lua_host.hpp): trimmed to what stays inside the sandbox, and guarded
// where one library call could run unbounded, since the hooks see a call only when it starts.
// [SECTION] Index
//   Patterns   string.find, match, gmatch and gsub, each search priced before it runs
//   Guards     string.rep, table.move, insert, remove and sort by their range; setmetatable without __gc
//   Output     print and warn, counted against the frame's allowance; load, text only and bounded
//   Opening    the libraries opened, trimmed and wrapped in a new state
#include "script/lua_host_impl.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

namespace arwb::script {
namespace {

std::atomic<lua_CFunction> g_test_function{nullptr};
std::atomic<const char*> g_test_name{nullptr};

// [SECTION] Patterns

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

// [SECTION] Guards

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

// [SECTION] Output

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

}  // namespace

void set_test_global(const char* name, lua_CFunction f) {
  g_test_name = name;
  g_test_function = f;
}

// [SECTION] Opening

void open_sandboxed_libraries(lua_State* L, Host* host) {
  lua_setwarnf(L, warn_function, host);

  // The library, minus what reaches outside the sandbox.
  const luaL_Reg libraries[] = {{LUA_GNAME, luaopen_base},          {LUA_COLIBNAME, luaopen_coroutine},
                                 {LUA_TABLIBNAME, luaopen_table},    {LUA_STRLIBNAME, luaopen_string},
                                 {LUA_MATHLIBNAME, luaopen_math},    {LUA_UTF8LIBNAME, luaopen_utf8}};
  for (const luaL_Reg& lib : libraries) {
    luaL_requiref(L, lib.name, lib.func, 1);
    lua_pop(L, 1);
  }
  // os: only clock, time and date.
  luaL_requiref(L, LUA_OSLIBNAME, luaopen_os, 0);
  lua_createtable(L, 0, 3);
  for (const char* name : {"clock", "time", "date"}) {
    lua_getfield(L, -2, name);
    lua_setfield(L, -2, name);
  }
  lua_setglobal(L, "os");
  lua_pop(L, 1);
  for (const char* name : {"dofile", "loadfile", "collectgarbage", "require", "package", "io", "debug"}) {
    lua_pushnil(L);
    lua_setglobal(L, name);
  }
  lua_getglobal(L, "string");
  lua_pushnil(L);
  lua_setfield(L, -2, "dump");
  for (const char* name : {"gmatch", "match", "gsub", "find"}) {
    lua_getfield(L, -1, name);
    lua_pushinteger(L, std::strcmp(name, "gmatch") == 0 ? 0 : std::strcmp(name, "find") == 0 ? 2 : 1);
    lua_pushcclosure(L, w_guarded_pattern, 2);
    lua_setfield(L, -2, name);
  }
  lua_getfield(L, -1, "rep");
  lua_pushcclosure(L, w_rep, 1);
  lua_setfield(L, -2, "rep");
  lua_pop(L, 1);
  lua_getglobal(L, "table");
  const luaL_Reg table_guards[] = {
      {"move", w_table_move}, {"insert", w_table_insert}, {"remove", w_table_remove}, {"sort", w_table_sort}};
  for (const luaL_Reg& g : table_guards) {
    lua_getfield(L, -1, g.name);
    lua_pushcclosure(L, g.func, 1);
    lua_setfield(L, -2, g.name);
  }
  lua_pop(L, 1);
  lua_pushcfunction(L, w_setmetatable);
  lua_setglobal(L, "setmetatable");
  if (const lua_CFunction f = g_test_function.load()) {
    lua_pushcfunction(L, f);
    lua_setglobal(L, g_test_name.load());
  }
  lua_getglobal(L, "load");
  lua_pushcclosure(L, w_load, 1);
  lua_setglobal(L, "load");
  lua_pushcfunction(L, w_print);
  lua_setglobal(L, "print");
}

}  // namespace arwb::script
