// The scene step of the data flow (detector -> tracker -> Lua behaviours), given one frame's markers and camera:
// the tracker follows the markers with the detector's tracking parameters, the camera poses are computed with is
// the loaded calibration or the paper's default one for the frame's size, and a loaded scene (Lua or XML database)
// turns the tracks into overlays. The workbench's SceneStage runs it on its Frame; the phone player's core runs it
// on the page's frames, so both place media with this code.
#pragma once

#include "detect/params.hpp"
#include "script/scene_runtime.hpp"
#include "track/tracker.hpp"

#include <memory>
#include <string>
#include <vector>

namespace arwb::script {

struct SceneStepInput {
  const std::vector<Marker>* markers = nullptr;   // the detector's, this frame
  const DetectorParams* params = nullptr;         // its tracking_* rows drive the tracker; null: the defaults
  cv::Size image{};                               // the working image's size
  const Calibration* calibration = nullptr;       // fitted to `image`; null: default_calibration (assumed)
  double marker_side = 1;                         // tvec's unit: the printed side (in mm), or 1
  std::string unit = "marker sides";              // its name: "mm" with a printed size; reset when side is not > 0
  double t_s = 0;                                 // frame time, seconds
  uint64_t frame_index = 0;
  const std::array<cv::Mat, kStageCount>* views = nullptr;   // stage pictures for stage media; null: none
};

struct SceneStepOutput {
  std::vector<TrackedMarker> tracks;
  Calibration camera;                    // the one the tracks' poses were computed with
  double marker_side = 1;                // as given, or 1 and "marker sides" when it was not > 0
  std::string unit = "marker sides";
  std::vector<Overlay> overlays;         // empty without a scene
};

class SceneStep {
 public:
  explicit SceneStep(media::MediaProvider& media, ScriptLimits limits = {});
  ~SceneStep();
  SceneStep(const SceneStep&) = delete;
  SceneStep& operator=(const SceneStep&) = delete;

  // Loads a scene (or, with "", unloads it). False and status().error when it fails; the last good scene stays.
  bool load(const std::string& path);
  bool loaded() const { return !file_.empty(); }
  const std::string& file() const { return file_; }
  // Looks for changes to the scene file (at most every `poll_s` seconds of t_s) and reloads it when it changed.
  void poll(double t_s, double poll_s);
  SceneStepOutput run(const SceneStepInput& in);

  const SceneStatus& status() const { return runtime_->status(); }
  std::vector<std::string> take_errors() { return runtime_->take_errors(); }
  std::string dictionary() const { return runtime_->dictionary(); }
  const SceneRuntime& runtime() const { return *runtime_; }

 private:
  media::MediaProvider& media_;
  Tracker tracker_;
  std::unique_ptr<SceneRuntime> runtime_;
  std::string file_;
  double last_t_ = -1, last_poll_ = -1;
};

}  // namespace arwb::script
