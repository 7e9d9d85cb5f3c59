#include "workbench/scene_stage.hpp"

#include <algorithm>

namespace arwb {

SceneStage::SceneStage(media::StoreMode mode, script::ScriptLimits limits)
    : store_(mode), runtime_(std::make_unique<script::SceneRuntime>(store_, limits)) {}

SceneStage::~SceneStage() = default;

bool SceneStage::load(const std::string& path) {
  if (path.empty()) {
    runtime_->unload();
    tracker_.clear();
    file_.clear();
    store_.trim();
    return true;
  }
  const bool ok = runtime_->load(path);
  // A failed first load still names the file, so the editor can open it and the watcher can pick up the fix.
  file_ = path;
  tracker_.clear();   // a (re)loaded scene starts with every marker entering
  store_.trim();
  return ok;
}

std::string SceneStage::dictionary() const { return runtime_->dictionary(); }
const SceneStatus& SceneStage::status() const { return runtime_->status(); }
std::vector<std::string> SceneStage::take_errors() { return runtime_->take_errors(); }

void SceneStage::run(Frame& f, double t_s, double poll_s) {
  if (!file_.empty() && (last_poll_ < 0 || t_s - last_poll_ >= poll_s || t_s < last_poll_)) {
    last_poll_ = t_s;
    if (runtime_->reload_if_changed()) tracker_.clear();
  }
  // The tracker follows the frame's parameters (its One Euro filter) and camera: the loaded calibration, or the
  // paper's default values for the frame's size (marked assumed). The marker's side is the frame's
  // pose_marker_side (the printed size the user gave, else 1: tvec in marker sides).
  SmoothingSettings sm;
  sm.on = f.params.tracking_smoothing != 0;
  sm.min_cutoff_hz = f.params.tracking_min_cutoff_hz;
  sm.beta = f.params.tracking_beta;
  sm.d_cutoff_hz = f.params.tracking_d_cutoff_hz;
  tracker_.set_smoothing(sm);
  tracker_.set_hold(f.params.tracking_hold_s);
  if (f.loaded_calibration) f.pose_camera = *f.loaded_calibration;
  else if (f.image.cols > 0 && f.image.rows > 0) f.pose_camera = default_calibration(f.image.size());
  if (!(f.pose_marker_side > 0)) f.pose_marker_side = 1, f.pose_unit = "marker sides";
  tracker_.set_camera(f.pose_camera, f.pose_marker_side);
  const std::vector<TrackEvent> events = tracker_.update(f.trace.markers, t_s);
  if (file_.empty()) {   // no scene: the tracks alone (with their poses)
    f.tracks = tracker_.tracks();
    return;
  }
  const double dt = last_t_ < 0 ? 0.0 : std::clamp(t_s - last_t_, 0.0, 1.0);
  last_t_ = t_s;
  script::SceneInput in;
  in.tracks = &tracker_.tracks();
  in.events = &events;
  in.t_s = t_s;
  in.dt_s = dt;
  in.frame = f.image.size();
  in.views = f.views[0].empty() && f.views[1].empty() ? nullptr : &f.views;
  in.frame_index = f.index;
  in.camera = &f.pose_camera;
  in.marker_side = f.pose_marker_side;
  in.pose_unit = f.pose_unit;
  f.overlays = runtime_->update(in);
  f.tracks = tracker_.tracks();
  f.scene = runtime_->status();
}

}  // namespace arwb
