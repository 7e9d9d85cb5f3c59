#include "workbench/scene_stage.hpp"

namespace arwb {

SceneStage::SceneStage(media::StoreMode mode, script::ScriptLimits limits) : store_(mode), step_(store_, limits) {}

SceneStage::~SceneStage() = default;

void SceneStage::run(Frame& f, double t_s, double poll_s) {
  step_.poll(t_s, poll_s);
  script::SceneStepInput in;
  in.markers = &f.trace.markers;
  in.params = &f.params;
  in.image = f.image.size();
  in.calibration = f.loaded_calibration.get();
  in.marker_side = f.pose_marker_side;
  in.unit = f.pose_unit;
  in.t_s = t_s;
  in.frame_index = f.index;
  in.views = f.views[0].empty() && f.views[1].empty() ? nullptr : &f.views;
  script::SceneStepOutput out = step_.run(in);
  f.pose_camera = std::move(out.camera);
  f.pose_marker_side = out.marker_side;
  f.pose_unit = std::move(out.unit);
  f.tracks = std::move(out.tracks);
  if (!step_.loaded()) return;   // no scene: the tracks alone (with their poses)
  f.overlays = std::move(out.overlays);
  f.scene = step_.status();
}

}  // namespace arwb
