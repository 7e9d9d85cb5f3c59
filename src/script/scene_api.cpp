// The scene API's globals (docs/scene-api.md): dictionary, marker, ids and the placements (on_marker, beside,
// billboard, screen), the values' metatables, and what the runtime and the database share with them. The media
// constructors are in scene_api_media.cpp; what both files use, in scene_api_values.hpp.
//
// Every C function here is a small w_ function whose body runs in guarded() (lua_host.hpp): C++ exceptions
// become Lua errors, tables are read with raw access, and Lua errors are raised only once the body's C++
// objects are gone. Bad values never raise: a constructor returns a value carrying its error, and marker()
// reports it with the line and skips that call (its row stays, marked skipped), so the rest of the scene still
// works.
// [SECTION] Index
//   Placements              on_marker, beside, billboard, screen
//   ids, dictionary, marker the scene's declarations
//   Metatables and globals  __tostring and __gc of the values, the globals' table
//   Shared                  with the runtime and the database: ids, names, the values' tests
#include "script/scene_api_values.hpp"

#include "base/text.hpp"
#include "detect/dictionary.hpp"

namespace arwb::script::api {
namespace {

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

// [SECTION] Placements

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
      opt.boolean("overlap", &s.overlap);
      opt.finish({"opacity", "side", "gap", "size", "overlap"});
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

// [SECTION] ids, dictionary, marker

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

// More ids than any dictionary holds (the largest has 1024): a list longer is a mistake, not a scene.
constexpr lua_Unsigned kMaxIdList = 4096;

// A table of ids: {from = 100, to = 199}, a range that cannot be read as a list; {3, 7, 12}, a list; and the old
// {first, last}, still the range from first to last, with a `warning` that it reads as one ({0, 2} covered 1 too).
std::string read_id_table(lua_State* L, int idx, const SceneDef& def, IdSet* out, std::string* warning) {
  long long a = 0, b = 0;
  lua_getfield(L, idx, "from");
  lua_getfield(L, idx, "to");
  const bool named = !lua_isnil(L, -2) || !lua_isnil(L, -1);
  const bool both = get_integer(L, -2, &a) && get_integer(L, -1, &b);
  lua_pop(L, 2);
  const lua_Unsigned n = lua_rawlen(L, idx);
  if (named || n == 2) {
    if (named && !both) return "an id range is {from = first, to = last} with two integers";
    if (!named) {
      lua_rawgeti(L, idx, 1);
      lua_rawgeti(L, idx, 2);
      const bool ok = get_integer(L, -2, &a) && get_integer(L, -1, &b);
      lua_pop(L, 2);
      if (!ok) return "an id list holds integers only, such as {3, 7, 12}";
      *warning = "{" + std::to_string(a) + ", " + std::to_string(b) + "} is read as the range " + std::to_string(a) +
                 " to " + std::to_string(b) + "; write {from = " + std::to_string(a) + ", to = " + std::to_string(b) +
                 "} for the range, or ids(" + std::to_string(a) + ", " + std::to_string(b) + ") for the two ids";
    }
    if (a > b) return "the id range " + std::to_string(a) + " to " + std::to_string(b) + " is empty (first > last)";
    if (std::string e = check_id(def, a); !e.empty()) return e;
    if (std::string e = check_id(def, b); !e.empty()) return e;
    out->ranges.push_back({static_cast<int>(a), static_cast<int>(b)});
    return {};
  }
  if (n == 0) return "an empty table has no ids; a list is {3, 7, 12}, a range {from = 100, to = 199}";
  if (n > kMaxIdList) return "a list of more than " + std::to_string(kMaxIdList) + " ids; use a range";
  for (lua_Unsigned i = 1; i <= n; ++i) {
    lua_rawgeti(L, idx, lua_Integer(i));
    const bool ok = get_integer(L, -1, &a);
    lua_pop(L, 1);
    if (!ok) return "an id list holds integers only, such as {3, 7, 12}";
    if (std::string e = check_id(def, a); !e.empty()) return e;
    out->ranges.push_back({static_cast<int>(a), static_cast<int>(a)});
  }
  return {};
}

// The ids argument of marker(): an id, a table (read_id_table), or ids(...). "" or the problem.
std::string read_ids(lua_State* L, int idx, const SceneDef& def, IdSet* out, std::string* warning) {
  long long a = 0;
  if (get_integer(L, idx, &a)) {
    if (std::string e = check_id(def, a); !e.empty()) return e;
    out->ranges.push_back({static_cast<int>(a), static_cast<int>(a)});
    return {};
  }
  if (lua_type(L, idx) == LUA_TTABLE) return read_id_table(L, idx, def, out, warning);
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
  return "the first argument must be an id, a list {3, 7}, a range {from = 100, to = 199} or ids(...), got " +
         describe_value(L, idx);
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
    std::string ids_warning;
    if (std::string e = read_ids(L, 1, def, &m.ids, &ids_warning); !e.empty()) return skip("marker: " + e);
    if (!ids_warning.empty()) report(L, 1, w.prefix + "marker: " + ids_warning);
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

// [SECTION] Metatables and globals

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
    {"on_marker", w_on_marker},   {"beside", w_beside},       {"billboard", w_billboard},
    {"screen", w_screen},         {nullptr, nullptr},
};

}  // namespace
}  // namespace arwb::script::api

namespace arwb::script {

// [SECTION] Shared

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
    // Appended piece by piece: GCC 12 warns wrongly (-Wrestrict) on "-" + a temporary string here.
    if (i) s += ", ";
    s += std::to_string(a);
    if (b != a) s.append("-").append(std::to_string(b));
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

const MediaValue* test_media(lua_State* L, int idx) { return api::test_value<MediaValue>(L, idx, api::kMediaMeta); }
const PlaceValue* test_place(lua_State* L, int idx) { return api::test_value<PlaceValue>(L, idx, api::kPlaceMeta); }

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
  api::new_metatable<MediaValue>(L, api::kMediaMeta, api::w_media_tostring);
  api::new_metatable<PlaceValue>(L, api::kPlaceMeta, api::w_place_tostring);
  api::new_metatable<IdsValue>(L, api::kIdsMeta, api::w_ids_tostring);
  lua_pushglobaltable(L);
  luaL_setfuncs(L, api::kGlobals, 0);
  lua_pop(L, 1);
  api::open_media_constructors(L);
}

}  // namespace arwb::script
