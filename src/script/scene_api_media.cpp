// The scene API's media constructors (docs/scene-api.md): image, video, web, text and stage, and the 3D cube,
// axes and model. Each returns a media value; bad arguments never raise: the value carries its error, and
// marker() reports it with the line and skips that call (scene_api.cpp).
// [SECTION] Index
//   Flat media  image, video, web, text, stage
//   3D media    cube, axes, model, and the options they share
#include "script/scene_api_values.hpp"

#include "detect/trace.hpp"
#include "media/media_path.hpp"
#include "track/mesh.hpp"

#include <cmath>
#include <cstdio>

namespace arwb::script::api {
namespace {

std::string stage_list() {
  std::string all;
  for (int i = 0; i < kStageCount; ++i) all += (i ? ", " : "") + std::string(stage_name(static_cast<Stage>(i)));
  return all;
}

// [SECTION] Flat media

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

// [SECTION] 3D media

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

const luaL_Reg kMediaConstructors[] = {
    {"image", w_image}, {"video", w_video}, {"web", w_web},   {"text", w_text},
    {"stage", w_stage}, {"cube", w_cube},   {"axes", w_axes}, {"model", w_model},
    {nullptr, nullptr},
};

}  // namespace

void open_media_constructors(lua_State* L) {
  lua_pushglobaltable(L);
  luaL_setfuncs(L, kMediaConstructors, 0);
  lua_pop(L, 1);
}

}  // namespace arwb::script::api
