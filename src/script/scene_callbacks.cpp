// Calling the scene's Lua functions (on_enter, on_update, on_leave, computed text) with a marker, under the
// instruction budget and memory cap, and applying what a callback returns ({media = ..., place = ...}).
#include "script/scene_runtime_impl.hpp"

#include <algorithm>
#include <cstdio>

namespace arwb::script {
namespace {

// The pose's unit: its name, and the marker's side in it (m.pose.x / m.pose.side is in marker sides either way).
struct PoseUnit {
  const std::string& name;
  double side;
};

void push_marker(lua_State* L, const TrackedMarker& t, const std::string& dict, bool held, const PoseUnit& unit) {
  lua_createtable(L, 0, 10);
  lua_pushinteger(L, t.id);
  lua_setfield(L, -2, "id");
  lua_pushinteger(L, t.instance);
  lua_setfield(L, -2, "instance");
  lua_pushinteger(L, static_cast<lua_Integer>(t.track_id));
  lua_setfield(L, -2, "track");
  lua_pushlstring(L, dict.data(), dict.size());
  lua_setfield(L, -2, "dict");
  lua_createtable(L, 4, 0);
  for (int k = 0; k < 4; ++k) {
    lua_createtable(L, 0, 2);
    lua_pushnumber(L, t.corners[static_cast<size_t>(k)].x);
    lua_setfield(L, -2, "x");
    lua_pushnumber(L, t.corners[static_cast<size_t>(k)].y);
    lua_setfield(L, -2, "y");
    lua_rawseti(L, -2, k + 1);
  }
  lua_setfield(L, -2, "corners");
  lua_createtable(L, 0, 2);
  lua_pushnumber(L, t.centre.x);
  lua_setfield(L, -2, "x");
  lua_pushnumber(L, t.centre.y);
  lua_setfield(L, -2, "y");
  lua_setfield(L, -2, "centre");
  lua_pushnumber(L, t.side_px);
  lua_setfield(L, -2, "side");
  lua_pushnumber(L, t.visible_s);
  lua_setfield(L, -2, "seconds");
  lua_pushboolean(L, held);
  lua_setfield(L, -2, "held");
  if (!t.pose) return;
  // Its pose (pose/marker_pose.hpp) through the loaded calibration or the default camera, in `unit`.
  const PoseAngles a = pose_angles(t.pose->pose);
  lua_createtable(L, 0, 10);
  const std::pair<const char*, double> fields[] = {
      {"x", t.pose->pose.tvec[0]}, {"y", t.pose->pose.tvec[1]},   {"z", t.pose->pose.tvec[2]},
      {"distance", a.distance},    {"tilt", a.tilt_deg},          {"yaw", a.yaw_deg},
      {"pitch", a.pitch_deg},      {"roll", a.roll_deg},          {"ambiguity", t.pose->ambiguity}};
  for (const auto& [name, value] : fields) {
    lua_pushnumber(L, value);
    lua_setfield(L, -2, name);
  }
  lua_pushboolean(L, t.pose->assumed_camera);
  lua_setfield(L, -2, "assumed");
  lua_pushlstring(L, unit.name.data(), unit.name.size());
  lua_setfield(L, -2, "unit");
  lua_pushnumber(L, unit.side);
  lua_setfield(L, -2, "side");
  lua_setfield(L, -2, "pose");
}

}  // namespace

std::string SceneRuntime::Impl::dict_of(const Program& p, const TrackedMarker& t) const {
  return t.dict.empty() ? p.def.dict_name : t.dict;
}

std::string SceneRuntime::Impl::function_prefix(Program& p, int fn) {
  lua_State* L = p.lua->L();
  lua_rawgeti(L, LUA_REGISTRYINDEX, fn);
  lua_Debug ar;
  lua_getinfo(L, ">S", &ar);
  return p.display + ":" + std::to_string(std::max(0, ar.linedefined)) + ": ";
}

bool SceneRuntime::Impl::call(Program& p, int mi, int fn, const TrackedMarker& t, bool held, const double* dt,
                              const std::string& what, Instance* inst) {
  if (fn == LUA_NOREF || p.disabled.count(fn)) return false;
  // Enter and leave happen once and always run; what runs every frame waits once the frame's time is used.
  if ((what == "on_update" || what == "text") && frame_ms >= limits.frame_ms) {
    if (!skipped && what == "on_update") resume = {t.id, t.track_id};
    skipped = true;
    return false;
  }
  LuaState& ls = *p.lua;
  lua_State* L = ls.L();
  lua_checkstack(L, 8);
  lua_rawgeti(L, LUA_REGISTRYINDEX, fn);
  push_marker(L, t, dict_of(p, t), held, PoseUnit{pose_unit, pose_side});
  int nargs = 1;
  if (dt) {
    lua_pushnumber(L, *dt);
    nargs = 2;
  }
  const double before = ls.script_ms();
  const LuaState::Outcome out = ls.pcall(nargs, 1);
  frame_ms += ls.script_ms() - before;
  if (out.ok) {
    p.streaks.erase({fn, t.id});
    return true;
  }
  const std::string ctx = what + " of marker " + std::to_string(t.id);
  const std::string located =
      out.message.rfind(p.display + ":", 0) == 0 ? out.message : function_prefix(p, fn) + out.message;
  std::string msg;
  if (out.budget || out.time || out.memory || out.overflow) {
    // Each of these costs the frame its full price again if repeated: disabled at once.
    p.disabled.insert(fn);
    msg = out.memory ? function_prefix(p, fn) + "not enough memory (the cap is " + mib(limits.memory_bytes) + ")"
                     : located;
    msg += " in " + ctx + "; disabled until the scene reloads";
    p.mapping_error[static_cast<size_t>(mi)] = msg;
  } else {
    Program::Streak& s = p.streaks[{fn, t.id}];
    if (s.message != out.message) s = {out.message, frame_no, 1};
    else if (s.frame != frame_no) s.frame = frame_no, ++s.frames;
    if (s.frames >= std::max(1, limits.failures_in_a_row)) {
      p.disabled.insert(fn);
      msg = what + " disabled after failing " + std::to_string(s.frames) + " frames in a row: " + located + " (in " +
            ctx + "); it runs again when the scene reloads";
      p.mapping_error[static_cast<size_t>(mi)] = msg;
    } else {
      msg = located + " (in " + ctx + ")";
    }
  }
  report(2, msg);
  if (inst) inst->error = msg;
  return false;
}

void SceneRuntime::Impl::set_media(Program& p, Instance& inst, const MediaSpec& spec, int text_fn) {
  if (inst.text_fn != LUA_NOREF) luaL_unref(p.lua->L(), LUA_REGISTRYINDEX, inst.text_fn);
  inst.media_set = true;
  inst.media = spec;
  inst.text_fn = text_fn;
}

void SceneRuntime::Impl::apply_return(Program& p, int fn, Instance& inst, const std::string& ctx) {
  lua_State* L = p.lua->L();
  const int r = lua_gettop(L);
  if (lua_isnil(L, r)) {
    lua_settop(L, r - 1);
    return;
  }
  if (lua_type(L, r) != LUA_TTABLE) {
    report(1, function_prefix(p, fn) + ctx + " returned a " + luaL_typename(L, r) +
                  "; return nothing or a table {media = ..., place = ...}");
    lua_settop(L, r - 1);
    return;
  }
  static const std::vector<std::string_view> kKnown = {"media", "place"};
  // Only the first fields are looked at: a table of 200,000 unknown fields would cost the frame 0.4 s of
  // messages that say nothing more.
  constexpr int kFieldsRead = 16;
  int fields = 0;
  lua_pushnil(L);
  while (lua_next(L, r) != 0) {
    if (++fields > kFieldsRead) {
      lua_pop(L, 2);
      report(1, function_prefix(p, fn) + ctx + " returned a table of more than " + std::to_string(kFieldsRead) +
                    " fields; only media and place are read");
      break;
    }
    if (lua_type(L, -2) != LUA_TSTRING) {
      report(1, function_prefix(p, fn) + ctx + " returned a table with a value that is not named; ignored");
    } else if (std::string key = lua_tostring(L, -2); key != "media" && key != "place") {
      std::string m = function_prefix(p, fn) + ctx + " returned unknown field '" + key + "'";
      if (std::string d = did_you_mean(key, kKnown); !d.empty()) m += " (" + d + ")";
      report(1, m);
    }
    lua_pop(L, 1);
  }
  lua_pushliteral(L, "media");
  lua_rawget(L, r);
  if (lua_type(L, r + 1) == LUA_TBOOLEAN && !lua_toboolean(L, r + 1)) {
    set_media(p, inst, MediaSpec{}, LUA_NOREF);   // media = false: show nothing
  } else if (!lua_isnil(L, r + 1)) {
    const MediaValue* mv = test_media(L, r + 1);
    if (!mv) {
      report(2, function_prefix(p, fn) + ctx + " returned media that is not a media value (image, video, web, "
                                               "text or stage): " + luaL_typename(L, r + 1) + "; ignored");
    } else if (!mv->error.empty()) {
      report(2, (mv->where.empty() ? function_prefix(p, fn) : mv->where) + mv->error + "; ignored (" + ctx + ")");
    } else {
      int ref = LUA_NOREF;
      if (mv->computed) {
        push_text_function(L, r + 1);
        ref = luaL_ref(L, LUA_REGISTRYINDEX);
      }
      set_media(p, inst, mv->spec, ref);
    }
  }
  lua_settop(L, r);
  lua_pushliteral(L, "place");
  lua_rawget(L, r);
  if (lua_type(L, r + 1) == LUA_TSTRING) {
    PlaceSpec ps;
    const std::string name = lua_tostring(L, r + 1);
    if (place_from_name(name, &ps)) {
      inst.place_set = true;
      inst.place = ps;
    } else {
      report(2, function_prefix(p, fn) + ctx + " returned unknown placement '" + name + "' (" +
                    place_kind_list() + "); ignored");
    }
  } else if (!lua_isnil(L, r + 1)) {
    const PlaceValue* pv = test_place(L, r + 1);
    if (!pv) {
      report(2, function_prefix(p, fn) + ctx + " returned place that is not a placement (" + place_kind_list() +
                    "): " + luaL_typename(L, r + 1) + "; ignored");
    } else if (!pv->error.empty()) {
      report(2, (pv->where.empty() ? function_prefix(p, fn) : pv->where) + pv->error + "; ignored (" + ctx + ")");
    } else {
      inst.place_set = true;
      inst.place = pv->spec;
    }
  }
  lua_settop(L, r - 1);
}

bool SceneRuntime::Impl::run_callback(Program& p, int mi, int fn, const TrackedMarker& t, bool held,
                                      const double* dt, const char* what, Instance& inst) {
  if (fn == LUA_NOREF || !p.lua) return true;
  if (!call(p, mi, fn, t, held, dt, what, &inst)) return false;
  apply_return(p, fn, inst, std::string(what) + " of marker " + std::to_string(t.id));
  return true;
}

void SceneRuntime::Impl::run_event(Program& p, int mi, int fn, const TrackedMarker& t, bool held, const char* what,
                                   Instance& inst) {
  const bool ran = run_callback(p, mi, fn, t, held, nullptr, what, inst);
  p.event_error[size_t(mi)] = ran ? std::string() : inst.error;
}

Instance& SceneRuntime::Impl::instance_of(Program& p, int mi, const TrackedMarker& t) {
  const auto it = p.inside.find(t.track_id);
  return p.instances[{mi, t.id, it == p.inside.end() ? 0 : it->second}];
}

void SceneRuntime::Impl::enter(Program& p, const TrackedMarker& t) {
  // The lowest slot no other track of this id in view holds.
  std::set<int> taken;
  for (const auto& [track, slot] : p.inside)
    if (auto it = p.last.find(track); it != p.last.end() && it->second.id == t.id) taken.insert(slot);
  int slot = 0;
  while (taken.count(slot)) ++slot;
  p.inside[t.track_id] = slot;
  p.last[t.track_id] = t;
  for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
    const Mapping& m = p.def.mappings[mi];
    if (!m.skipped.empty() || !m.ids.contains(t.id)) continue;
    Instance& inst = instance_of(p, static_cast<int>(mi), t);
    inst.inside = true;
    inst.fresh = true;
    run_event(p, static_cast<int>(mi), m.on_enter, t, !t.detected, "on_enter", inst);
  }
}

void SceneRuntime::Impl::leave(Program& p, uint64_t track_id) {
  const auto last = p.last.find(track_id);
  if (last == p.last.end()) {
    p.inside.erase(track_id);
    return;
  }
  const TrackedMarker t = last->second;
  for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
    const Mapping& m = p.def.mappings[mi];
    if (!m.skipped.empty() || !m.ids.contains(t.id)) continue;
    Instance& inst = instance_of(p, static_cast<int>(mi), t);
    inst.inside = false;
    if (inst.video) inst.video->set_clock(inst.position, false);   // paused where it stopped
    run_event(p, static_cast<int>(mi), m.on_leave, t, false, "on_leave", inst);
  }
  p.inside.erase(track_id);
  p.last.erase(track_id);
}

}  // namespace arwb::script
