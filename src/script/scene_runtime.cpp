// The scene runtime's frame step: which markers the scene sees, enter and leave, on_update and the play
// position, then the overlays in declaration order and the Scene panel's rows. Loading, callbacks and media
// content live beside it (scene_runtime_impl.hpp lists the files).
#include "script/scene_runtime_impl.hpp"

#include <algorithm>
#include <cstdio>

namespace arwb::script {
namespace {

std::string upper_dict(std::string s) {
  for (char& c : s) c = static_cast<char>((c >= 'a' && c <= 'z') ? c - 32 : c);
  if (s.rfind("DICT_", 0) == 0) s = s.substr(5);
  return s;
}

std::string fmt1(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", v);
  return b;
}

// The Scene panel shows a mapping's name where MappingRow has a field for it.
template <class Row>
void set_row_name(Row& row, const std::string& name) {
  if constexpr (requires { row.name = name; }) row.name = name;
  else if (!name.empty()) row.ids += " (" + name + ")";
}

// The line of the first "display:LINE:" in a message, wherever it stands ("on_update disabled after ...:
// scene.lua:4: attempt to ..."); 0 when there is none.
int line_in(const std::string& msg, const std::string& display) {
  const std::string key = display + ":";
  for (size_t at = msg.find(key); at != std::string::npos; at = msg.find(key, at + 1)) {
    size_t i = at + key.size();
    int line = 0;
    bool digits = false;
    while (i < msg.size() && msg[i] >= '0' && msg[i] <= '9' && line < 100'000'000) {
      line = line * 10 + (msg[i++] - '0');
      digits = true;
    }
    if (digits && i < msg.size() && msg[i] == ':') return line;
  }
  return 0;
}

}  // namespace

std::vector<Overlay> SceneRuntime::Impl::update(const SceneInput& in) {
  frame_ms = 0;
  pose_side = in.marker_side > 0 ? in.marker_side : 1;
  pose_unit = in.pose_unit;
  ++frame_no;
  skipped = false;
  cards.clear();
  std::vector<Overlay> overlays;
  if (!prog) {
    status.mappings.clear();
    status.script_ms = 0;
    return overlays;
  }
  Program& p = *prog;
  if (p.lua) p.lua->begin_frame();
  static const std::vector<TrackedMarker> kNoTracks;
  static const std::vector<TrackEvent> kNoEvents;
  const auto& tracks = in.tracks ? *in.tracks : kNoTracks;
  const auto& events = in.events ? *in.events : kNoEvents;

  // The markers this scene sees: all, or those of its dictionary when it named one; one entry per track, in id
  // order (then instance).
  std::vector<const TrackedMarker*> seen;
  std::map<uint64_t, const TrackedMarker*> by_track;
  const std::string want = upper_dict(p.def.dict_name);
  for (const TrackedMarker& t : tracks) {
    if (!p.def.dictionary.empty() && !t.dict.empty() && upper_dict(t.dict) != want) continue;
    seen.push_back(&t);
    by_track.emplace(t.track_id, &t);
  }
  for (auto& [key, inst] : p.instances) inst.error.clear();

  enter_and_leave(p, events, seen, by_track);
  run_updates(p, seen, in);

  // Overlays: each mapping in declaration order (later ones drawn over earlier ones), its markers in id order,
  // each print of an id with its own.
  std::array<std::shared_ptr<MediaContent>, kStageCount> stages{};
  for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
    const Mapping& m = p.def.mappings[mi];
    if (!m.skipped.empty()) continue;
    for (const TrackedMarker* t : seen)
      if (m.ids.contains(t->id)) add_overlay(p, static_cast<int>(mi), *t, in, stages, overlays);
  }
  if (p.lua) {
    const double before = p.lua->script_ms();
    p.lua->collect_garbage();
    frame_ms += p.lua->script_ms() - before;
    report_suppressed(p);
  }
  if (skipped) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", limits.frame_ms);
    report(1, p.display + ": the scene's calls took over " + b + " ms on this frame; its other on_update and text "
                          "calls wait for the next frame");
  }
  fill_rows(&seen);
  status.script_ms = frame_ms;
  return overlays;
}

// Enter and leave: the tracker's events, then whatever they missed (markers in view when the scene loaded).
void SceneRuntime::Impl::enter_and_leave(Program& p, const std::vector<TrackEvent>& events,
                                         const std::vector<const TrackedMarker*>& seen,
                                         const std::map<uint64_t, const TrackedMarker*>& by_track) {
  for (const TrackEvent& e : events) {
    if (e.kind == TrackEvent::Kind::enter) {
      if (auto it = by_track.find(e.track_id); it != by_track.end() && !p.inside.count(e.track_id))
        enter(p, *it->second);
    } else if (p.inside.count(e.track_id)) {
      leave(p, e.track_id);
    }
  }
  for (const TrackedMarker* t : seen)
    if (!p.inside.count(t->track_id)) enter(p, *t);
  std::vector<uint64_t> gone;
  for (const auto& [track, slot] : p.inside)
    if (!by_track.count(track)) gone.push_back(track);
  for (const uint64_t track : gone) leave(p, track);
}

// on_update, and the play position. When the frame's time ran out last frame, this one starts with the marker
// that waited, so every marker gets its turn.
void SceneRuntime::Impl::run_updates(Program& p, const std::vector<const TrackedMarker*>& seen,
                                     const SceneInput& in) {
  std::vector<const TrackedMarker*> order = seen;
  const auto first = std::find_if(order.begin(), order.end(), [&](const TrackedMarker* t) {
    return std::pair<int, uint64_t>(t->id, t->track_id) >= resume;
  });
  std::rotate(order.begin(), first, order.end());
  resume = {-1, 0};
  for (const TrackedMarker* t : order) {
    const int id = t->id;
    p.last[t->track_id] = *t;
    for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
      const Mapping& m = p.def.mappings[mi];
      if (!m.skipped.empty() || !m.ids.contains(id)) continue;
      Instance& inst = instance_of(p, static_cast<int>(mi), *t);
      if (!inst.fresh) inst.position += std::max(0.0, in.dt_s);
      inst.fresh = false;
      run_callback(p, static_cast<int>(mi), m.on_update, *t, !t->detected, &in.dt_s, "on_update", inst);
    }
  }
}

void SceneRuntime::Impl::add_overlay(Program& p, int mi, const TrackedMarker& t, const SceneInput& in,
                                     std::array<std::shared_ptr<MediaContent>, kStageCount>& stages,
                                     std::vector<Overlay>& overlays) {
  const Mapping& m = p.def.mappings[static_cast<size_t>(mi)];
  const int id = t.id;
  Instance& inst = instance_of(p, mi, t);
  MediaSpec spec = inst.media_set ? inst.media : m.media;
  if (spec.kind == MediaKind::none) {
    content_for(p, m, inst, spec, in, stages);   // pauses a video the media was before
    return;
  }
  const int fn = inst.media_set ? inst.text_fn : m.text_fn;
  if (spec.kind == MediaKind::text && fn != LUA_NOREF) {
    if (!p.lua || !call(p, mi, fn, t, !t.detected, nullptr, "text", &inst)) return;
    lua_State* L = p.lua->L();
    if (lua_type(L, -1) == LUA_TSTRING || lua_type(L, -1) == LUA_TNUMBER) {
      spec.text = lua_tostring(L, -1);
    } else {
      const std::string msg = function_prefix(p, fn) + "a text function must return a string, not " +
                              luaL_typename(L, -1) + " (text of marker " + std::to_string(id) + ")";
      lua_pop(L, 1);
      report(2, msg);
      inst.error = msg;
      return;
    }
    lua_pop(L, 1);
  }
  const PlaceSpec& place = inst.place_set ? inst.place : m.place;
  if (is_solid(spec.kind)) {
    content_for(p, m, inst, spec, in, stages);   // pauses a video the media was before
    Overlay o;
    o.marker_id = id;
    o.track_id = t.track_id;
    o.mapping = mi;
    o.place = place;
    if (!solid_overlay(p, m, inst, spec, place, t, in, &o)) return;
    o.media = std::move(spec);
    overlays.push_back(std::move(o));
    return;
  }
  std::shared_ptr<MediaContent> content = content_for(p, m, inst, spec, in, stages);
  if (!content) return;
  const cv::Size size = content->size();
  if (size.width <= 0 || size.height <= 0) return;
  std::string why;
  // Text and web cards keep clear of the cards placed before them (in declaration order, then id order).
  const bool card = spec.kind == MediaKind::text || spec.kind == MediaKind::web;
  const double aspect = double(size.width) / double(size.height);
  Side side = place.side;
  const std::optional<MediaQuad> quad =
      card ? place_apart(place, t.corners, aspect, in.frame, cards, inst.card_side, &side, &why)
           : arwb::place(place, t.corners, aspect, in.frame, &why);
  if (!quad) {
    const std::string msg = p.display + ":" + std::to_string(m.line) + ": marker " + std::to_string(id) +
                            ": " + (why.empty() ? "cannot be placed" : why);
    report(1, msg);
    inst.error = why;
    return;
  }
  Overlay o;
  o.marker_id = id;
  o.track_id = t.track_id;
  o.mapping = mi;
  o.media = std::move(spec);
  o.place = place;
  o.place.side = side;   // where it is drawn, which may not be the side asked for
  if (card) inst.card_side = side;
  o.quad = *quad;
  o.content = std::move(content);
  through_lens(t, in, &o);
  overlays.push_back(std::move(o));
}

void SceneRuntime::Impl::report_suppressed(Program& p) {
  if (!p.lua || p.lua->suppressed_output() == 0) return;
  report(1, p.display + ": " + std::to_string(p.lua->suppressed_output()) + " more lines of print and warn output " +
                "suppressed on this frame (a frame shows at most " + std::to_string(limits.output_lines_per_frame) +
                " lines, " + std::to_string(limits.output_bytes_per_frame / 1024) + " KiB)");
  p.lua->begin_frame();
}

void SceneRuntime::Impl::fill_rows(const std::vector<const TrackedMarker*>* seen) {
  status.mappings.clear();
  if (!prog) return;
  Program& p = *prog;
  for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
    const Mapping& m = p.def.mappings[mi];
    MappingRow row;
    // A marker() refused for its ids has none to show.
    row.ids = m.ids.ranges.empty() ? std::string("?") : m.ids.text();
    set_row_name(row, m.name);
    row.media = m.skipped.empty() ? m.media.describe() : "-";
    row.placement = m.skipped.empty() ? m.place.describe() : "-";
    row.line = m.line;
    auto fault = [&](MappingHealth h, const std::string& reason) {
      row.health = h;
      row.reason = reason;
      row.reason_line = line_in(reason, p.display);
      if (row.reason_line == 0) row.reason_line = m.line;
      row.state = std::string(mapping_health_name(h)) + ": " + reason;
    };
    if (!m.skipped.empty()) {
      fault(MappingHealth::skipped, m.skipped);
      status.mappings.push_back(std::move(row));
      continue;
    }
    int visible = 0, held = 0;
    double longest = 0;
    std::string error;
    if (seen)
      for (const TrackedMarker* t : *seen) {
        if (!m.ids.contains(t->id)) continue;
        if (t->detected) {
          ++visible;
          longest = std::max(longest, t->visible_s);
        } else {
          ++held;
        }
        if (error.empty()) error = instance_of(p, static_cast<int>(mi), *t).error;
      }
    if (mi < p.mapping_error.size() && !p.mapping_error[mi].empty()) fault(MappingHealth::disabled, p.mapping_error[mi]);
    else if (!error.empty()) fault(MappingHealth::error, error);
    else if (mi < p.event_error.size() && !p.event_error[mi].empty()) fault(MappingHealth::error, p.event_error[mi]);
    else if (visible > 0)
      row.state = "visible " + fmt1(longest) + " s" +
                  (visible + held > 1 ? " (" + std::to_string(visible + held) + " markers)" : "");
    else if (held > 0) row.state = "held";
    else row.state = "waiting";
    status.mappings.push_back(std::move(row));
  }
}

std::vector<std::string> SceneRuntime::Impl::take_errors() {
  std::vector<std::string> out;
  out.swap(fresh_errors);
  return out;
}

SceneRuntime::SceneRuntime(media::MediaProvider& store, ScriptLimits limits)
    : impl_(std::make_unique<Impl>(store, limits)) {}
SceneRuntime::~SceneRuntime() = default;

bool SceneRuntime::load(const std::string& path) { return impl_->load(path); }
bool SceneRuntime::reload_if_changed() { return impl_->reload_if_changed(); }
void SceneRuntime::unload() { impl_->unload(); }
std::vector<Overlay> SceneRuntime::update(const SceneInput& in) { return impl_->update(in); }
const SceneStatus& SceneRuntime::status() const { return impl_->status; }
std::vector<std::string> SceneRuntime::take_errors() { return impl_->take_errors(); }
std::string SceneRuntime::dictionary() const { return impl_->prog ? impl_->prog->def.dictionary : std::string(); }
std::string SceneRuntime::dictionary_name() const {
  return impl_->prog ? impl_->prog->def.dict_name : SceneDef{}.dict_name;
}
std::vector<std::vector<std::pair<int, int>>> SceneRuntime::mapping_ids() const {
  std::vector<std::vector<std::pair<int, int>>> out;
  if (impl_->prog)
    for (const Mapping& m : impl_->prog->def.mappings) out.push_back(m.ids.ranges);
  return out;
}

}  // namespace arwb::script
