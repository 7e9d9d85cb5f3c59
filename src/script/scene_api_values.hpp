// What the scene API's C functions share (internal to src/script): the values they make as full userdata, the
// words for a value in a message, and the options table every constructor reads.
//   scene_api.cpp         marker, dictionary, ids, the placements; the metatables and the globals
//   scene_api_media.cpp   the media constructors: image, video, web, text, stage, cube, axes, model
//   scene_api_values.cpp  what is declared here
#pragma once

#include "script/scene_model.hpp"

#include <opencv2/core.hpp>

#include <cstddef>
#include <new>
#include <string>
#include <string_view>
#include <vector>

namespace arwb::script::api {

inline constexpr const char* kMediaMeta = "arwb.media";
inline constexpr const char* kPlaceMeta = "arwb.place";
inline constexpr const char* kIdsMeta = "arwb.ids";

// A value as full userdata. `alive` guards against use after __gc (a finalizer may still reach a value finalized
// in the same cycle).
template <class T>
struct Box {
  bool alive = false;
  T value;
};

// Pushes a new value with the metatable `meta` and returns its payload.
template <class T>
T* new_value(lua_State* L, const char* meta) {
  void* p = lua_newuserdatauv(L, sizeof(Box<T>), 1);
  auto* b = new (p) Box<T>();
  b->alive = true;
  luaL_setmetatable(L, meta);
  return &b->value;
}

// The payload of the value at idx if it is a live value of `meta`, else null.
template <class T>
T* test_value(lua_State* L, int idx, const char* meta) {
  auto* b = static_cast<Box<T>*>(luaL_testudata(L, idx, meta));
  return b && b->alive ? &b->value : nullptr;
}

// A line for the scene's console (0 print, 1 warning, 2 error), when the state has a reporter.
void report(lua_State* L, int level, const std::string& text);

// `s` cut to n characters, "..." ending it when cut.
std::string shorten(std::string s, std::size_t n = 40);

// "string 'corner'", "number 5", "a placement", "nil" ... for messages.
std::string describe_value(lua_State* L, int idx);

// The integer at idx (a number with an exact integer value), else false.
bool get_integer(lua_State* L, int idx, long long* out);

// Warns about fields of the table at idx that are not in `known` ("unknown field 'plac' (did you mean
// 'place'?)"), with the call's position and `what` ("beside: ") before it.
void warn_unknown_fields(lua_State* L, int idx, const std::vector<std::string_view>& known, const Where& w,
                         const std::string& what);

// An optional options table (argument idx): typed getters with raw access; the first problem is kept. A getter
// returns whether the key is present (for string and vec3: present and of the right type).
class Options {
 public:
  Options(lua_State* L, int idx, std::string what, Where w);

  bool number(const char* key, double* out);
  bool boolean(const char* key, bool* out);
  bool string(const char* key, std::string* out);
  // {x, y, z} or {x = .., y = .., z = ..}: three finite numbers.
  bool vec3(const char* key, cv::Vec3d* out);
  // Pushes the table at `key` and returns true; false (nothing pushed) when absent or not a table (reported).
  bool table(const char* key);
  // Warns about the fields not in `known`.
  void finish(const std::vector<std::string_view>& known);
  void fail(const std::string& e);
  const std::string& error() const { return error_; }

 private:
  bool get(const char* key);

  lua_State* L_;
  int idx_ = 0;
  bool present_ = false;
  std::string what_;
  Where where_;
  std::string error_;
};

// "#rrggbb" or "#rrggbbaa" as BGRA.
bool parse_colour(const std::string& s, cv::Scalar* out);

// Registers the media constructors as globals (scene_api_media.cpp).
void open_media_constructors(lua_State* L);

}  // namespace arwb::script::api
