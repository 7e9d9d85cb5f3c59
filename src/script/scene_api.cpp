// The scene API's globals (docs/scene-api.md): dictionary, marker, ids, the media constructors (image, video,
// web, text, stage, and the 3D cube, axes and model) and the placements (on_marker, beside, billboard, screen).
//
// Every C function here is a small w_ function whose body runs in guarded() (lua_host.hpp): C++ exceptions
// become Lua errors, tables are read with raw access, and Lua errors are raised only once the body's C++
// objects are gone. Bad values never raise: a constructor returns a value carrying its error, and marker()
// reports it with the line and skips that call (its row stays, marked skipped), so the rest of the scene still
// works.
#include "base/text.hpp"
#include "detect/dictionary.hpp"
#include "detect/trace.hpp"
#include "media/media_path.hpp"
#include "script/scene_model.hpp"
#include "track/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <new>

namespace arwb::script {
namespace {

constexpr const char* kMediaMeta = "arwb.media";
constexpr const char* kPlaceMeta = "arwb.place";
constexpr const char* kIdsMeta = "arwb.ids";

// ---- values as full userdata -----------------------------------------------------------------------------------

// `alive` guards against use after __gc (a finalizer may still reach a value finalized in the same cycle).
template <class T>
struct Box {
  bool alive = false;
  T value;
};

template <class T>
T* new_value(lua_State* L, const char* meta) {
  void* p = lua_newuserdatauv(L, sizeof(Box<T>), 1);
  auto* b = new (p) Box<T>();
  b->alive = true;
  luaL_setmetatable(L, meta);
  return &b->value;
}

template <class T>
T* test_value(lua_State* L, int idx, const char* meta) {
  auto* b = static_cast<Box<T>*>(luaL_testudata(L, idx, meta));
  return b && b->alive ? &b->value : nullptr;
}

// Only our metatables carry __gc and they are locked (__metatable), so argument 1 is a Box<T>.
template <class T>
int w_gc(lua_State* L) {
  auto* b = static_cast<Box<T>*>(lua_touserdata(L, 1));
  if (b && b->alive) {
    b->alive = false;
    b->value.~T();
  }
  return 0;
}

void report(lua_State* L, int level, const std::string& text) {
  Host& h = host_of(L);
  if (h.reporter) h.reporter->report(level, text);
}

std::string shorten(std::string s, size_t n = 40) {
  if (s.size() > n) s = s.substr(0, n - 3) + "...";
  return s;
}

// "string 'corner'", "number 5", "a placement", "nil" ... for messages.
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

// Warns about fields of the table at idx that are not in `known` ("unknown field 'plac' (did you mean
// 'place'?)"), with the call's position and `what` ("beside: ") before it.
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

// An optional options table (argument idx): typed getters with raw access; the first problem is kept.
class Options {
 public:
  Options(lua_State* L, int idx, std::string what, Where w) : L_(L), what_(std::move(what)), where_(std::move(w)) {
    idx_ = lua_absindex(L, idx);
    const int t = lua_type(L, idx_);
    present_ = t == LUA_TTABLE;
    if (t != LUA_TNONE && t != LUA_TNIL && t != LUA_TTABLE)
      fail("expected an options table {name = value, ...}, got " + describe_value(L, idx_));
  }

  bool number(const char* key, double* out) {
    if (!get(key)) return false;
    if (lua_type(L_, -1) == LUA_TNUMBER) *out = lua_tonumber(L_, -1);
    else fail(std::string(key) + " must be a number, got " + describe_value(L_, -1));
    lua_pop(L_, 1);
    return true;
  }
  bool boolean(const char* key, bool* out) {
    if (!get(key)) return false;
    if (lua_type(L_, -1) == LUA_TBOOLEAN) *out = lua_toboolean(L_, -1) != 0;
    else fail(std::string(key) + " must be true or false, got " + describe_value(L_, -1));
    lua_pop(L_, 1);
    return true;
  }
  bool string(const char* key, std::string* out) {
    if (!get(key)) return false;
    bool ok = lua_type(L_, -1) == LUA_TSTRING;
    if (ok) *out = lua_tostring(L_, -1);
    else fail(std::string(key) + " must be a string, got " + describe_value(L_, -1));
    lua_pop(L_, 1);
    return ok;
  }
  // {x, y, z} or {x = .., y = .., z = ..}: three finite numbers.
  bool vec3(const char* key, cv::Vec3d* out) {
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
  // Pushes the table at `key` and returns true; false (nothing pushed) when absent or not a table (reported).
  bool table(const char* key) {
    if (!get(key)) return false;
    if (lua_type(L_, -1) == LUA_TTABLE) return true;
    fail(std::string(key) + " must be a table, got " + describe_value(L_, -1));
    lua_pop(L_, 1);
    return false;
  }
  void finish(const std::vector<std::string_view>& known) {
    if (present_) warn_unknown_fields(L_, idx_, known, where_, what_ + ": ");
  }
  void fail(const std::string& e) {
    if (error_.empty()) error_ = what_ + ": " + e;
  }
  const std::string& error() const { return error_; }

 private:
  bool get(const char* key) {
    if (!present_) return false;
    lua_pushstring(L_, key);
    lua_rawget(L_, idx_);
    if (lua_isnil(L_, -1)) {
      lua_pop(L_, 1);
      return false;
    }
    return true;
  }

  lua_State* L_;
  int idx_ = 0;
  bool present_ = false;
  std::string what_;
  Where where_;
  std::string error_;
};

// "#rrggbb" or "#rrggbbaa" as BGRA.
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

std::string stage_list() {
  std::string all;
  for (int i = 0; i < kStageCount; ++i) all += (i ? ", " : "") + std::string(stage_name(static_cast<Stage>(i)));
  return all;
}

// ---- media constructors ----------------------------------------------------------------------------------------

int make_file_media(lua_State* L, MediaKind kind) {
  const Where w = where(L);
  const std::string fname = kind == MediaKind::image ? "image" : "video";
  lua_settop(L, 2);
  MediaValue* v = new_value<MediaValue>(L, kMediaMeta);
  v->where = w.prefix;
  v->spec.kind = kind;
  Options opt(L, 2, fname, w);
  if (kind == MediaKind::video) opt.boolean("loop", &v->spec.loop);
  opt.finish(kind == MediaKind::video ? std::vector<std::string_view>{"loop"} : std::vector<std::string_view>{});
  if (lua_type(L, 1) != LUA_TSTRING) {
    v->error = fname + ": expected a path (string), got " + describe_value(L, 1);
    return 1;
  }
  v->spec.source = lua_tostring(L, 1);
  if (!opt.error().empty()) {
    v->error = opt.error();
    return 1;
  }
  const media::CheckedPath cp = media::check_media_path(host_of(L).dir, v->spec.source);
  if (!cp.ok()) {
    v->error = cp.error;
    return 1;
  }
  if (kind == MediaKind::image && cp.kind == media::MediaFileKind::video)
    v->error = v->spec.source + ": a video, not an image (use video(...))";
  else if (kind == MediaKind::video && cp.kind == media::MediaFileKind::image)
    v->error = v->spec.source + ": an image, not a video (use image(...))";
  v->spec.path = cp.path;
  return 1;
}

int w_image(lua_State* L) {
  return guarded(L, [&] { return make_file_media(L, MediaKind::image); });
}

int w_video(lua_State* L) {
  return guarded(L, [&] { return make_file_media(L, MediaKind::video); });
}

int w_web(lua_State* L) {
  return guarded(L, [&] {
    const Where w = where(L);
    lua_settop(L, 2);
    MediaValue* v = new_value<MediaValue>(L, kMediaMeta);
    v->where = w.prefix;
    v->spec.kind = MediaKind::web;
    Options opt(L, 2, "web", w);
    std::string title;
    const bool has_title = opt.string("title", &title);
    opt.finish({"title"});
    if (lua_type(L, 1) != LUA_TSTRING) {
      v->error = "web: expected a URL (string), got " + describe_value(L, 1);
      return 1;
    }
    v->spec.source = v->spec.url = lua_tostring(L, 1);
    v->spec.title = has_title ? title : media::url_host(v->spec.url);
    if (!opt.error().empty()) v->error = opt.error();
    else if (std::string e = media::check_url(v->spec.url); !e.empty()) v->error = e;
    return 1;
  });
}

int w_text(lua_State* L) {
  return guarded(L, [&] {
    const Where w = where(L);
    lua_settop(L, 2);
    MediaValue* v = new_value<MediaValue>(L, kMediaMeta);   // index 3
    v->where = w.prefix;
    v->spec.kind = MediaKind::text;
    Options opt(L, 2, "text", w);
    opt.number("size", &v->spec.font_px);
    std::string c;
    if (opt.string("colour", &c) || opt.string("color", &c)) {
      if (!parse_colour(c, &v->spec.colour)) opt.fail("colour must be \"#rrggbb\" or \"#rrggbbaa\", got '" + shorten(c) + "'");
    }
    if (opt.string("background", &c)) {
      if (!parse_colour(c, &v->spec.background))
        opt.fail("background must be \"#rrggbb\" or \"#rrggbbaa\", got '" + shorten(c) + "'");
    }
    opt.finish({"size", "colour", "color", "background"});
    if (!std::isfinite(v->spec.font_px) || v->spec.font_px <= 0 || v->spec.font_px > 1000) {
      char b[64];
      std::snprintf(b, sizeof b, "%g", std::isnan(v->spec.font_px) ? std::abs(v->spec.font_px) : v->spec.font_px);
      opt.fail(std::string("size must be a number of pixels in (0, 1000] (got ") + b + ")");
    }
    switch (lua_type(L, 1)) {
      case LUA_TFUNCTION:
        v->computed = true;
        v->spec.source = "function";
        lua_pushvalue(L, 1);
        lua_setiuservalue(L, 3, 1);
        break;
      case LUA_TSTRING:
      case LUA_TNUMBER:
        lua_pushvalue(L, 1);
        v->spec.source = v->spec.text = lua_tostring(L, -1);
        lua_pop(L, 1);
        break;
      default:
        v->error = "text: expected a string or a function(m) returning one, got " + describe_value(L, 1);
        return 1;
    }
    if (!opt.error().empty()) v->error = opt.error();
    return 1;
  });
}

int w_stage(lua_State* L) {
  return guarded(L, [&] {
    const Where w = where(L);
    lua_settop(L, 1);
    MediaValue* v = new_value<MediaValue>(L, kMediaMeta);
    v->where = w.prefix;
    v->spec.kind = MediaKind::stage;
    if (lua_type(L, 1) != LUA_TSTRING) {
      v->error = "stage: expected a stage name such as \"adaptive_threshold\", got " + describe_value(L, 1);
      return 1;
    }
    v->spec.source = v->spec.stage = lua_tostring(L, 1);
    Stage s{};
    if (!stage_from_name(v->spec.stage, &s) || static_cast<int>(s) >= kStageCount)
      v->error = "stage: unknown stage '" + shorten(v->spec.stage) + "' (" + stage_list() + ")";
    return 1;
  });
}

// ---- 3D media ----------------------------------------------------------------------------------------------

// What cube, axes and model share: size, offset, rotate, lit. Checks the size's range.
void read_solid_options(Options& opt, MediaSpec* spec, const char* size_key) {
  opt.number(size_key, &spec->size);
  opt.vec3("offset", &spec->offset);
  opt.vec3("rotate", &spec->rotate_deg);
  opt.boolean("lit", &spec->lit);
  if (!std::isfinite(spec->size) || spec->size <= 0 || spec->size > 100) {
    char b[64];
    std::snprintf(b, sizeof b, "%g", spec->size);
    opt.fail(std::string(size_key) + " must be a number of marker sides in (0, 100] (got " + b + ")");
  }
  for (int i = 0; i < 3; ++i)
    if (std::abs(spec->offset[i]) > 1000) opt.fail("offset must stay within 1000 marker sides of the marker");
}

// A face's look: "#rrggbb[aa]" is a colour, anything else an image path inside the scene's folder.
std::string read_face(lua_State* L, const std::string& value, int face, MediaSpec* spec) {
  const size_t f = static_cast<size_t>(face);
  if (!value.empty() && value[0] == '#') {
    if (!parse_colour(value, &spec->face_colour[f]))
      return "colour must be \"#rrggbb\" or \"#rrggbbaa\", got '" + shorten(value) + "'";
    return {};
  }
  const media::CheckedPath cp = media::check_media_path(host_of(L).dir, value);
  if (!cp.ok()) return cp.error;
  if (cp.kind != media::MediaFileKind::image) return value + ": a video, not an image (a cube's faces show images)";
  spec->face_image[f] = cp.path;
  spec->face_source[f] = value;
  spec->face_colour[f] = cv::Scalar(255, 255, 255, spec->face_colour[f][3]);
  return {};
}

int w_cube(lua_State* L) {
  return guarded(L, [&] {
    const Where w = where(L);
    lua_settop(L, 1);
    MediaValue* v = new_value<MediaValue>(L, kMediaMeta);   // index 2
    v->where = w.prefix;
    v->spec.kind = MediaKind::cube;
    v->spec.source = "cube";
    Options opt(L, 1, "cube", w);
    read_solid_options(opt, &v->spec, "size");
    std::string c;
    if (opt.string("colour", &c) || opt.string("color", &c)) {
      cv::Scalar col;
      if (!parse_colour(c, &col)) opt.fail("colour must be \"#rrggbb\" or \"#rrggbbaa\", got '" + shorten(c) + "'");
      else v->spec.face_colour.fill(col);
    }
    if (opt.table("faces")) {   // pushed at the top
      std::vector<std::string_view> names;
      for (int f = 0; f < kCubeFaces; ++f) {
        const char* name = cube_face_name(static_cast<CubeFace>(f));
        names.push_back(name);
        lua_pushstring(L, name);
        lua_rawget(L, -2);
        if (lua_type(L, -1) == LUA_TSTRING) {
          if (std::string e = read_face(L, lua_tostring(L, -1), f, &v->spec); !e.empty())
            opt.fail(std::string("faces.") + name + ": " + e);
        } else if (!lua_isnil(L, -1)) {
          opt.fail(std::string("faces.") + name + " must be a colour \"#rrggbb\" or an image path, got " +
                   describe_value(L, -1));
        }
        lua_pop(L, 1);
      }
      warn_unknown_fields(L, -1, names, w, "cube: faces: ");
      lua_pop(L, 1);
    }
    opt.finish({"size", "colour", "color", "faces", "offset", "rotate", "lit"});
    if (!opt.error().empty()) v->error = opt.error();
    return 1;
  });
}

int w_axes(lua_State* L) {
  return guarded(L, [&] {
    const Where w = where(L);
    lua_settop(L, 1);
    MediaValue* v = new_value<MediaValue>(L, kMediaMeta);
    v->where = w.prefix;
    v->spec.kind = MediaKind::axes;
    v->spec.source = "axes";
    v->spec.lit = false;
    Options opt(L, 1, "axes", w);
    read_solid_options(opt, &v->spec, "length");
    opt.number("thickness", &v->spec.thickness);
    if (!std::isfinite(v->spec.thickness) || v->spec.thickness <= 0 || v->spec.thickness > v->spec.size)
      opt.fail("thickness must be a number of marker sides in (0, length]");
    opt.finish({"length", "thickness", "offset", "rotate", "lit"});
    if (!opt.error().empty()) v->error = opt.error();
    return 1;
  });
}

int w_model(lua_State* L) {
  return guarded(L, [&] {
    const Where w = where(L);
    lua_settop(L, 2);
    MediaValue* v = new_value<MediaValue>(L, kMediaMeta);
    v->where = w.prefix;
    v->spec.kind = MediaKind::model;
    Options opt(L, 2, "model", w);
    read_solid_options(opt, &v->spec, "size");
    opt.finish({"size", "offset", "rotate", "lit"});
    if (lua_type(L, 1) != LUA_TSTRING) {
      v->error = "model: expected a path to an OBJ or glTF file (string), got " + describe_value(L, 1);
      return 1;
    }
    v->spec.source = lua_tostring(L, 1);
    if (!opt.error().empty()) {
      v->error = opt.error();
      return 1;
    }
    // The path's rules now (a missing file or one leading out skips the marker() call with its line); the
    // model itself is read when a marker first shows it (media_store.hpp), where a broken file is reported.
    const media::ResolvedFile f = media::resolve_scene_file(host_of(L).dir, v->spec.source);
    if (!f.ok()) v->error = "model: " + f.error;
    else v->spec.path = f.path;
    return 1;
  });
}

// ---- placements ------------------------------------------------------------------------------------------------

int make_place(lua_State* L, PlaceKind kind) {
  const Where w = where(L);
  lua_settop(L, 1);
  PlaceValue* v = new_value<PlaceValue>(L, kPlaceMeta);
  v->where = w.prefix;
  v->spec = PlaceSpec::defaults(kind);
  const std::string fname(place_kind_name(kind));
  Options opt(L, 1, fname, w);
  PlaceSpec& s = v->spec;
  opt.number("opacity", &s.opacity);
  std::string name;
  switch (kind) {
    case PlaceKind::on_marker:
      opt.number("scale", &s.scale);
      opt.number("rotate", &s.rotate_deg);
      if (opt.string("fit", &name) && !parse_fit(name, &s.fit))
        opt.fail("unknown fit '" + shorten(name) + "' (fit, fill, stretch)");
      opt.finish({"opacity", "scale", "rotate", "fit"});
      break;
    case PlaceKind::beside:
    case PlaceKind::billboard:
      if (opt.string("side", &name) && !parse_side(name, &s.side))
        opt.fail("unknown side '" + shorten(name) + "' (right, left, top, bottom)");
      opt.number("gap", &s.gap);
      opt.number("size", &s.size);
      opt.finish({"opacity", "side", "gap", "size"});
      break;
    case PlaceKind::screen:
      if (opt.string("corner", &name) && !parse_screen_corner(name, &s.corner))
        opt.fail("unknown corner '" + shorten(name) + "' (top_left, top_right, bottom_left, bottom_right)");
      opt.number("size", &s.size);
      opt.number("margin", &s.margin_px);
      opt.finish({"opacity", "corner", "size", "margin"});
      break;
  }
  if (!opt.error().empty()) v->error = opt.error();
  else if (std::string e = s.validate(); !e.empty()) v->error = fname + ": " + e;
  return 1;
}

int w_on_marker(lua_State* L) {
  return guarded(L, [&] { return make_place(L, PlaceKind::on_marker); });
}
int w_beside(lua_State* L) {
  return guarded(L, [&] { return make_place(L, PlaceKind::beside); });
}
int w_billboard(lua_State* L) {
  return guarded(L, [&] { return make_place(L, PlaceKind::billboard); });
}
int w_screen(lua_State* L) {
  return guarded(L, [&] { return make_place(L, PlaceKind::screen); });
}

// ---- ids, dictionary, marker -----------------------------------------------------------------------------------

int w_ids(lua_State* L) {
  return guarded(L, [&] {
    const Where w = where(L);
    const int n = lua_gettop(L);
    IdsValue* v = new_value<IdsValue>(L, kIdsMeta);
    v->where = w.prefix;
    for (int i = 1; i <= n; ++i) {
      long long id = 0;
      if (!get_integer(L, i, &id)) {
        v->error = "ids: argument " + std::to_string(i) + " must be an integer id, got " + describe_value(L, i);
        break;
      }
      if (id < -1'000'000'000LL || id > 1'000'000'000LL) id = id < 0 ? -1 : 1'000'000'000LL;
      v->ids.push_back(static_cast<int>(id));
    }
    if (v->error.empty() && v->ids.empty()) v->error = "ids: give at least one id, as in ids(1, 5, 9)";
    return 1;
  });
}

int w_dictionary(lua_State* L) {
  return guarded(L, [&] {
    Host& h = host_of(L);
    const Where w = where(L);
    if (!h.building) throw LuaFail{w.prefix + "dictionary() can only be used while the scene loads"};
    if (lua_type(L, 1) != LUA_TSTRING)
      throw LuaFail{w.prefix + "dictionary: expected a name such as \"ARUCO_ORIGINAL\", got " + describe_value(L, 1)};
    const std::string name = lua_tostring(L, 1);
    SceneDef& def = *h.building;
    std::string err;
    const std::optional<Dictionary> d = dictionary_by_name(name, &err);
    if (!d) throw LuaFail{w.prefix + "dictionary: " + err};
    if (!def.dictionary.empty() && d->name() != def.dict_name)
      throw LuaFail{w.prefix + "dictionary: the scene already uses " + def.dict_name};
    if (def.markers_declared && def.dictionary.empty())
      throw LuaFail{w.prefix + "dictionary must be declared before the first marker()"};
    def.dictionary = name;
    def.dict_name = d->name();
    def.dict_size = d->size();
    return 0;
  });
}

// The ids argument of marker(): an id, {first, last}, or ids(...). "" or the problem.
std::string read_ids(lua_State* L, int idx, const SceneDef& def, IdSet* out) {
  long long a = 0, b = 0;
  if (get_integer(L, idx, &a)) {
    if (std::string e = check_id(def, a); !e.empty()) return e;
    out->ranges.push_back({static_cast<int>(a), static_cast<int>(a)});
    return {};
  }
  if (lua_type(L, idx) == LUA_TTABLE) {
    const lua_Unsigned n = lua_rawlen(L, idx);
    lua_rawgeti(L, idx, 1);
    lua_rawgeti(L, idx, 2);
    const bool ok = n == 2 && get_integer(L, -2, &a) && get_integer(L, -1, &b);
    lua_pop(L, 2);
    if (!ok) return "an id range is {first, last} with two integers; for a list use ids(1, 5, 9)";
    if (a > b) return "the id range {" + std::to_string(a) + ", " + std::to_string(b) + "} is empty (first > last)";
    if (std::string e = check_id(def, a); !e.empty()) return e;
    if (std::string e = check_id(def, b); !e.empty()) return e;
    out->ranges.push_back({static_cast<int>(a), static_cast<int>(b)});
    return {};
  }
  if (const IdsValue* v = test_value<IdsValue>(L, idx, kIdsMeta)) {
    if (!v->error.empty()) return v->error;
    for (int id : v->ids) {
      if (std::string e = check_id(def, id); !e.empty()) return e;
      out->ranges.push_back({id, id});
    }
    return {};
  }
  if (lua_type(L, idx) == LUA_TNUMBER)
    return "id must be an integer, got " + describe_value(L, idx);
  return "the first argument must be an id, {first, last} or ids(...), got " + describe_value(L, idx);
}

int w_marker(lua_State* L) {
  return guarded(L, [&]() -> int {
    Host& h = host_of(L);
    const Where w = where(L);
    if (!h.building) throw LuaFail{w.prefix + "marker() can only be used while the scene loads"};
    SceneDef& def = *h.building;
    def.markers_declared = true;
    lua_settop(L, 2);
    lua_checkstack(L, 16);
    Mapping m;
    m.line = w.line;
    // A refused call keeps a row of its own (no media, no callbacks, matching no marker) so the Scene panel
    // shows it with the reason instead of dropping it.
    auto keep_skipped = [&](const std::string& msg) {
      Mapping bad;
      bad.ids = m.ids;
      bad.line = w.line;
      bad.skipped = msg;
      def.mappings.push_back(std::move(bad));
    };
    auto skip = [&](const std::string& why) {
      const std::string msg = w.prefix + why + "; marker() skipped";
      report(L, 2, msg);
      keep_skipped(msg);
      return 0;
    };
    if (std::string e = read_ids(L, 1, def, &m.ids); !e.empty()) return skip("marker: " + e);
    const std::string label = "marker(" + m.ids.text() + ")";
    if (lua_type(L, 2) != LUA_TTABLE)
      return skip(label + ": the second argument must be a table {media = ..., place = ...}, got " +
                  describe_value(L, 2));
    static const std::vector<std::string_view> kKnown = {"media", "place", "on_enter", "on_update", "on_leave",
                                                         "name"};
    warn_unknown_fields(L, 2, kKnown, w, "");
    for (std::string_view k : kKnown) {   // media 3, place 4, on_enter 5, on_update 6, on_leave 7, name 8
      lua_pushlstring(L, k.data(), k.size());
      lua_rawget(L, 2);
    }
    // media
    bool computed = false;
    if (!lua_isnil(L, 3)) {
      const MediaValue* mv = test_media(L, 3);
      if (!mv)
        return skip(label + ": media must be a media value (image, video, web, text, stage, cube, axes or model), got " +
                    describe_value(L, 3));
      if (!mv->error.empty()) {
        const std::string msg = (mv->where.empty() ? w.prefix : mv->where) + mv->error + "; " + label + " skipped";
        report(L, 2, msg);
        keep_skipped(msg);
        return 0;
      }
      m.media = mv->spec;
      computed = mv->computed;
    }
    // place
    m.place = PlaceSpec::defaults(PlaceKind::on_marker);
    if (lua_type(L, 4) == LUA_TSTRING) {
      const std::string name = lua_tostring(L, 4);
      if (!place_from_name(name, &m.place))
        return skip(label + ": unknown placement '" + shorten(name) + "' (" + place_kind_list() + ")");
    } else if (!lua_isnil(L, 4)) {
      const PlaceValue* pv = test_place(L, 4);
      if (!pv)
        return skip(label + ": place must be a placement (" + place_kind_list() + "), got " + describe_value(L, 4));
      if (!pv->error.empty()) {
        const std::string msg = (pv->where.empty() ? w.prefix : pv->where) + pv->error + "; " + label + " skipped";
        report(L, 2, msg);
        keep_skipped(msg);
        return 0;
      }
      m.place = pv->spec;
    }
    if (is_solid(m.media.kind) && m.place.kind != PlaceKind::on_marker && m.place.kind != PlaceKind::beside)
      return skip(label + ": a " + (m.media.kind == MediaKind::model ? std::string("model") : m.media.describe()) +
                  " stands in the marker's 3D frame: place it on_marker or beside, not " +
                  std::string(place_kind_name(m.place.kind)));
    // callbacks
    for (int i = 5; i <= 7; ++i)
      if (!lua_isnil(L, i) && lua_type(L, i) != LUA_TFUNCTION)
        return skip(label + ": " + std::string(kKnown[static_cast<size_t>(i - 3)]) + " must be a function, got " +
                    describe_value(L, i));
    // name
    if (lua_type(L, 8) == LUA_TSTRING || lua_type(L, 8) == LUA_TNUMBER) {
      lua_pushvalue(L, 8);
      m.name = lua_tostring(L, -1);
      lua_pop(L, 1);
    } else if (!lua_isnil(L, 8)) {
      report(L, 1, w.prefix + label + ": name must be a string, got " + describe_value(L, 8) + "; ignored");
    }
    if (m.media.kind == MediaKind::none && lua_isnil(L, 5) && lua_isnil(L, 6) && lua_isnil(L, 7))
      report(L, 1, w.prefix + label + " has no media and no callbacks");
    // Keep the functions alive in the registry for the life of the state.
    if (computed) {
      push_text_function(L, 3);
      m.text_fn = luaL_ref(L, LUA_REGISTRYINDEX);
    }
    int* refs[3] = {&m.on_enter, &m.on_update, &m.on_leave};
    for (int i = 5; i <= 7; ++i)
      if (lua_type(L, i) == LUA_TFUNCTION) {
        lua_pushvalue(L, i);
        *refs[i - 5] = luaL_ref(L, LUA_REGISTRYINDEX);
      }
    def.mappings.push_back(std::move(m));
    return 0;
  });
}

// ---- __tostring ------------------------------------------------------------------------------------------------

int w_media_tostring(lua_State* L) {
  return guarded(L, [&] {
    const MediaValue* v = test_media(L, 1);
    const std::string s = !v ? "media (finalized)" : v->error.empty() ? v->spec.describe() : "media (invalid: " + v->error + ")";
    lua_pushlstring(L, s.data(), s.size());
    return 1;
  });
}

int w_place_tostring(lua_State* L) {
  return guarded(L, [&] {
    const PlaceValue* v = test_place(L, 1);
    const std::string s = !v ? "placement (finalized)" : v->error.empty() ? v->spec.describe() : "placement (invalid: " + v->error + ")";
    lua_pushlstring(L, s.data(), s.size());
    return 1;
  });
}

int w_ids_tostring(lua_State* L) {
  return guarded(L, [&] {
    const IdsValue* v = test_value<IdsValue>(L, 1, kIdsMeta);
    std::string s = "ids(";
    if (v)
      for (size_t i = 0; i < v->ids.size(); ++i) s += (i ? ", " : "") + std::to_string(v->ids[i]);
    s += ")";
    lua_pushlstring(L, s.data(), s.size());
    return 1;
  });
}

template <class T>
void new_metatable(lua_State* L, const char* name, lua_CFunction tostring) {
  luaL_newmetatable(L, name);
  lua_pushcfunction(L, w_gc<T>);
  lua_setfield(L, -2, "__gc");
  lua_pushcfunction(L, tostring);
  lua_setfield(L, -2, "__tostring");
  lua_pushliteral(L, "locked");   // getmetatable() returns this; setmetatable() refuses
  lua_setfield(L, -2, "__metatable");
  lua_pop(L, 1);
}

const luaL_Reg kGlobals[] = {
    {"dictionary", w_dictionary}, {"marker", w_marker},       {"ids", w_ids},
    {"image", w_image},           {"video", w_video},         {"web", w_web},
    {"text", w_text},             {"stage", w_stage},         {"on_marker", w_on_marker},
    {"beside", w_beside},         {"billboard", w_billboard}, {"screen", w_screen},
    {"cube", w_cube},             {"axes", w_axes},           {"model", w_model},
    {nullptr, nullptr},
};

}  // namespace

// ---- shared with the runtime and the database ------------------------------------------------------------------

bool IdSet::contains(int id) const {
  for (const auto& [a, b] : ranges)
    if (id >= a && id <= b) return true;
  return false;
}

std::string IdSet::text() const {
  std::string s;
  for (size_t i = 0; i < ranges.size(); ++i) {
    if (i == 8) return s + ", ... (" + std::to_string(ranges.size()) + " entries)";
    const auto& [a, b] = ranges[i];
    s += (i ? ", " : "") + std::to_string(a);
    if (b != a) s += "-" + std::to_string(b);
  }
  return s;
}

std::string check_id(const SceneDef& def, long long id) {
  if (id >= 0 && id < def.dict_size) return {};
  return "id " + std::to_string(id) + " is not a marker of " + def.dict_name + " (ids 0 to " +
         std::to_string(def.dict_size - 1) + ")";
}

std::string did_you_mean(std::string_view word, const std::vector<std::string_view>& known) {
  const std::string best = nearest_name(word, known);
  return best.empty() ? std::string() : "did you mean '" + best + "'?";
}

const MediaValue* test_media(lua_State* L, int idx) { return test_value<MediaValue>(L, idx, kMediaMeta); }
const PlaceValue* test_place(lua_State* L, int idx) { return test_value<PlaceValue>(L, idx, kPlaceMeta); }

void push_text_function(lua_State* L, int idx) {
  if (lua_type(L, idx) == LUA_TUSERDATA) lua_getiuservalue(L, idx, 1);
  else lua_pushnil(L);
}

bool place_from_name(std::string_view name, PlaceSpec* out) {
  for (PlaceKind k : {PlaceKind::on_marker, PlaceKind::beside, PlaceKind::billboard, PlaceKind::screen})
    if (place_kind_name(k) == name) {
      *out = PlaceSpec::defaults(k);
      return true;
    }
  return false;
}

std::string place_kind_list() { return "on_marker, beside, billboard, screen"; }

void open_scene_api(lua_State* L) {
  new_metatable<MediaValue>(L, kMediaMeta, w_media_tostring);
  new_metatable<PlaceValue>(L, kPlaceMeta, w_place_tostring);
  new_metatable<IdsValue>(L, kIdsMeta, w_ids_tostring);
  lua_pushglobaltable(L);
  luaL_setfuncs(L, kGlobals, 0);
  lua_pop(L, 1);
}

}  // namespace arwb::script
