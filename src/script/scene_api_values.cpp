// What the scene API's C functions share (scene_api_values.hpp): reporting, values in messages, options tables.
#include "script/scene_api_values.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace arwb::script::api {

void report(lua_State* L, int level, const std::string& text) {
  Host& h = host_of(L);
  if (h.reporter) h.reporter->report(level, text);
}

std::string shorten(std::string s, std::size_t n) {
  if (s.size() > n) s = s.substr(0, n - 3) + "...";
  return s;
}

std::string describe_value(lua_State* L, int idx) {
  idx = lua_absindex(L, idx);
  switch (lua_type(L, idx)) {
    case LUA_TSTRING: return "string '" + shorten(lua_tostring(L, idx)) + "'";
    case LUA_TNUMBER: {
      lua_pushvalue(L, idx);
      std::string s = "number " + std::string(lua_tostring(L, -1));
      lua_pop(L, 1);
      return s;
    }
    case LUA_TUSERDATA:
      if (luaL_testudata(L, idx, kMediaMeta)) return "a media value";
      if (luaL_testudata(L, idx, kPlaceMeta)) return "a placement";
      if (luaL_testudata(L, idx, kIdsMeta)) return "an ids(...) list";
      return "userdata";
    default: return luaL_typename(L, idx);
  }
}

bool get_integer(lua_State* L, int idx, long long* out) {
  if (lua_type(L, idx) != LUA_TNUMBER) return false;
  int isnum = 0;
  const lua_Integer v = lua_tointegerx(L, idx, &isnum);
  if (!isnum) return false;
  *out = v;
  return true;
}

void warn_unknown_fields(lua_State* L, int idx, const std::vector<std::string_view>& known, const Where& w,
                         const std::string& what) {
  idx = lua_absindex(L, idx);
  // Only the first fields: this runs inside one C call, where no limit can see it (200,000 unknown fields took
  // 0.4 s of messages).
  constexpr int kFieldsRead = 32;
  int fields = 0;
  lua_pushnil(L);
  while (lua_next(L, idx) != 0) {
    if (++fields > kFieldsRead) {
      lua_pop(L, 2);
      report(L, 1, w.prefix + what + "a table of more than " + std::to_string(kFieldsRead) +
                       " fields; the others are not checked");
      break;
    }
    if (lua_type(L, -2) == LUA_TSTRING) {
      const std::string key = lua_tostring(L, -2);
      if (std::find(known.begin(), known.end(), key) == known.end()) {
        std::string msg = w.prefix + what + "unknown field '" + shorten(key) + "'";
        const std::string dym = did_you_mean(key, known);
        if (!dym.empty()) msg += " (" + dym + ")";
        report(L, 1, msg);
      }
    } else {
      report(L, 1, w.prefix + what + "fields are named (name = value); a value at [" + describe_value(L, -2) +
                       "] is ignored");
    }
    lua_pop(L, 1);
  }
}

Options::Options(lua_State* L, int idx, std::string what, Where w)
    : L_(L), what_(std::move(what)), where_(std::move(w)) {
  idx_ = lua_absindex(L, idx);
  const int t = lua_type(L, idx_);
  present_ = t == LUA_TTABLE;
  if (t != LUA_TNONE && t != LUA_TNIL && t != LUA_TTABLE)
    fail("expected an options table {name = value, ...}, got " + describe_value(L, idx_));
}

bool Options::number(const char* key, double* out) {
  if (!get(key)) return false;
  if (lua_type(L_, -1) == LUA_TNUMBER) *out = lua_tonumber(L_, -1);
  else fail(std::string(key) + " must be a number, got " + describe_value(L_, -1));
  lua_pop(L_, 1);
  return true;
}

bool Options::boolean(const char* key, bool* out) {
  if (!get(key)) return false;
  if (lua_type(L_, -1) == LUA_TBOOLEAN) *out = lua_toboolean(L_, -1) != 0;
  else fail(std::string(key) + " must be true or false, got " + describe_value(L_, -1));
  lua_pop(L_, 1);
  return true;
}

bool Options::string(const char* key, std::string* out) {
  if (!get(key)) return false;
  bool ok = lua_type(L_, -1) == LUA_TSTRING;
  if (ok) *out = lua_tostring(L_, -1);
  else fail(std::string(key) + " must be a string, got " + describe_value(L_, -1));
  lua_pop(L_, 1);
  return ok;
}

bool Options::vec3(const char* key, cv::Vec3d* out) {
  if (!get(key)) return false;
  bool ok = lua_type(L_, -1) == LUA_TTABLE;
  cv::Vec3d v;
  for (int i = 0; ok && i < 3; ++i) {
    lua_rawgeti(L_, -1, i + 1);
    if (lua_isnil(L_, -1)) {
      lua_pop(L_, 1);
      lua_pushstring(L_, i == 0 ? "x" : i == 1 ? "y" : "z");
      lua_rawget(L_, -2);
    }
    ok = lua_type(L_, -1) == LUA_TNUMBER && std::isfinite(lua_tonumber(L_, -1));
    if (ok) v[i] = lua_tonumber(L_, -1);
    lua_pop(L_, 1);
  }
  if (ok) *out = v;
  else fail(std::string(key) + " must be three finite numbers {x, y, z}, got " + describe_value(L_, -1));
  lua_pop(L_, 1);
  return ok;
}

bool Options::table(const char* key) {
  if (!get(key)) return false;
  if (lua_type(L_, -1) == LUA_TTABLE) return true;
  fail(std::string(key) + " must be a table, got " + describe_value(L_, -1));
  lua_pop(L_, 1);
  return false;
}

void Options::finish(const std::vector<std::string_view>& known) {
  if (present_) warn_unknown_fields(L_, idx_, known, where_, what_ + ": ");
}

void Options::fail(const std::string& e) {
  if (error_.empty()) error_ = what_ + ": " + e;
}

bool Options::get(const char* key) {
  if (!present_) return false;
  lua_pushstring(L_, key);
  lua_rawget(L_, idx_);
  if (lua_isnil(L_, -1)) {
    lua_pop(L_, 1);
    return false;
  }
  return true;
}

bool parse_colour(const std::string& s, cv::Scalar* out) {
  if ((s.size() != 7 && s.size() != 9) || s[0] != '#') return false;
  int v[4] = {0, 0, 0, 255};
  for (size_t i = 1, k = 0; i < s.size(); i += 2, ++k) {
    int byte = 0;
    for (size_t j = i; j < i + 2; ++j) {
      const char c = s[j];
      int d = 0;
      if (c >= '0' && c <= '9') d = c - '0';
      else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
      else if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
      else return false;
      byte = byte * 16 + d;
    }
    v[k] = byte;
  }
  *out = cv::Scalar(v[2], v[1], v[0], v[3]);
  return true;
}

}  // namespace arwb::script::api
