// The scene step of the data flow (detector -> tracker -> Lua behaviours -> compositor), shared by the
// workbench's worker and `arwb render`, so both place media with the same code: the tracker follows the frame's
// markers, the scene runtime (Lua or XML database) turns them into overlays, and the frame carries the result.
#pragma once

#include "workbench/frame.hpp"
#include "track/tracker.hpp"
#include "media/media_store.hpp"
#include "script/scene_runtime.hpp"

#include <memory>
#include <string>
#include <vector>

namespace arwb {

class SceneStage {
 public:
  explicit SceneStage(media::StoreMode mode, script::ScriptLimits limits = {});
  ~SceneStage();

  // Loads a scene (or, with "", unloads it). False and status().error when it fails; the last good scene stays.
  bool load(const std::string& path);
  bool loaded() const { return !file_.empty(); }
  const std::string& file() const { return file_; }
  // The dictionary the scene declared ("" if none).
  std::string dictionary() const;

  // Follows f.trace's markers at time t_s and fills f.tracks (with their poses, through f.pose_camera: the loaded
  // calibration or the default camera), and with a scene loaded f.overlays and f.scene. Looks for changes to the
  // scene file first (at most every `poll_s` seconds of t_s) and reloads it when it changed on disk.
  void run(Frame& f, double t_s, double poll_s = 0.25);
  const SceneStatus& status() const;
  // Error lines the scene reported since the last call, each text once per load (SceneRuntime::take_errors).
  std::vector<std::string> take_errors();
  // The scene runtime itself, for what the stage does not pass on (the mappings' ids for `arwb export`).
  const script::SceneRuntime& runtime() const { return *runtime_; }

 private:
  media::MediaStore store_;
  Tracker tracker_;
  std::unique_ptr<script::SceneRuntime> runtime_;
  std::string file_;
  double last_t_ = -1, last_poll_ = -1;
};

}  // namespace arwb
