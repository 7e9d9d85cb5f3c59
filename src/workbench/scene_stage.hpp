// The scene step of the data flow (detector -> tracker -> Lua behaviours -> compositor) on the workbench's Frame,
// shared by the workbench's worker and `arwb render`: script::SceneStep (which the phone player's core runs too)
// with the desktop's media store, its input taken from the frame and its result written back.
#pragma once

#include "workbench/frame.hpp"
#include "media/media_store.hpp"
#include "script/scene_step.hpp"

#include <string>
#include <vector>

namespace arwb {

class SceneStage {
 public:
  explicit SceneStage(media::StoreMode mode, script::ScriptLimits limits = {});
  ~SceneStage();

  // Loads a scene (or, with "", unloads it). False and status().error when it fails; the last good scene stays.
  bool load(const std::string& path) { return step_.load(path); }
  bool loaded() const { return step_.loaded(); }
  const std::string& file() const { return step_.file(); }
  // The dictionary the scene declared ("" if none).
  std::string dictionary() const { return step_.dictionary(); }

  // Follows f.trace's markers at time t_s and fills f.tracks (with their poses, through f.pose_camera: the loaded
  // calibration or the default camera), and with a scene loaded f.overlays and f.scene. Looks for changes to the
  // scene file first (at most every `poll_s` seconds of t_s) and reloads it when it changed on disk.
  void run(Frame& f, double t_s, double poll_s = 0.25);
  const SceneStatus& status() const { return step_.status(); }
  // Error lines the scene reported since the last call, each text once per load (SceneRuntime::take_errors).
  std::vector<std::string> take_errors() { return step_.take_errors(); }
  // The scene runtime itself, for what the stage does not pass on (the mappings' ids for `arwb export`).
  const script::SceneRuntime& runtime() const { return step_.runtime(); }

 private:
  media::MediaStore store_;
  script::SceneStep step_;
};

}  // namespace arwb
