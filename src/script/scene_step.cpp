#include "script/scene_step.hpp"

#include "media/media_provider.hpp"

#include <algorithm>
#include <cmath>

namespace arwb::script {

SceneStep::SceneStep(media::MediaProvider& media, ScriptLimits limits)
    : media_(media), runtime_(std::make_unique<SceneRuntime>(media, limits)) {}

SceneStep::~SceneStep() = default;

bool SceneStep::load(const std::string& path) {
  if (path.empty()) {
    runtime_->unload();
    tracker_.clear();
    file_.clear();
    media_.trim();
    return true;
  }
  const bool ok = runtime_->load(path);
  // A failed first load still names the file, so the editor can open it and the watcher can pick up the fix.
  file_ = path;
  tracker_.clear();   // a (re)loaded scene starts with every marker entering
  media_.trim();
  return ok;
}

void SceneStep::poll(double t_s, double poll_s) {
  if (file_.empty() || !(last_poll_ < 0 || t_s - last_poll_ >= poll_s || t_s < last_poll_)) return;
  last_poll_ = t_s;
  if (runtime_->reload_if_changed()) tracker_.clear();
}

SceneStepOutput SceneStep::run(const SceneStepInput& in) {
  SceneStepOutput out;
  // The tracker follows the parameters' One Euro filter and hold time, and the camera: the loaded calibration,
  // or the paper's default values for the frame's size (marked assumed).
  const DetectorParams defaults;
  const DetectorParams& p = in.params ? *in.params : defaults;
  SmoothingSettings sm;
  sm.on = p.tracking_smoothing != 0;
  sm.min_cutoff_hz = p.tracking_min_cutoff_hz;
  sm.beta = p.tracking_beta;
  sm.d_cutoff_hz = p.tracking_d_cutoff_hz;
  tracker_.set_smoothing(sm);
  tracker_.set_hold(p.tracking_hold_s);
  if (in.calibration) out.camera = *in.calibration;
  else if (in.image.width > 0 && in.image.height > 0) out.camera = default_calibration(in.image);
  const bool sized = in.marker_side > 0 && std::isfinite(in.marker_side);
  out.marker_side = sized ? in.marker_side : 1.0;
  out.unit = sized ? in.unit : "marker sides";
  tracker_.set_camera(out.camera, out.marker_side);
  static const std::vector<Marker> none;
  const std::vector<TrackEvent> events = tracker_.update(in.markers ? *in.markers : none, in.t_s);
  if (!file_.empty()) {
    const double dt = last_t_ < 0 ? 0.0 : std::clamp(in.t_s - last_t_, 0.0, 1.0);
    last_t_ = in.t_s;
    SceneInput s;
    s.tracks = &tracker_.tracks();
    s.events = &events;
    s.t_s = in.t_s;
    s.dt_s = dt;
    s.frame = in.image;
    s.views = in.views;
    s.frame_index = in.frame_index;
    s.camera = &out.camera;
    s.marker_side = out.marker_side;
    s.pose_unit = out.unit;
    out.overlays = runtime_->update(s);
  }
  out.tracks = tracker_.tracks();
  return out;
}

}  // namespace arwb::script
