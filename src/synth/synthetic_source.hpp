// The synthetic source: the synthetic world (synthetic_world.hpp) played in time as a FrameSource, with the exact
// markers of the frame it last gave. And open_source, which opens every kind of source: the synthetic one here,
// the others through capture.
#pragma once

#include "capture/source.hpp"
#include "synth/truth_source.hpp"
#include "synth/chessboard_view.hpp"
#include "synth/synthetic_world.hpp"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace arwb {

class SyntheticSource : public TruthSource {
 public:
  SourceStatus next(double now_s, cv::Mat& out) override;
  SourceInfo info() const override;
  // The world's controls (the workbench's sliders).
  SyntheticWorld& world() { return world_; }
  // The exact markers of the frame `next` last returned, in its pixels.
  const std::vector<TruthMarker>& truth() const override { return truth_; }
  // The camera that the board is seen through while the controls show a calibration board (controls().board not
  // empty): the truth a calibration is compared with. Null while markers are shown.
  const SynthCamera* board_camera() const;
  // > 0: every frame given moves the world's clock on by this many seconds (times the speed slider), whatever the
  // time between the calls, so that a scripted run sees the same frames on a slow machine as on a fast one; 0
  // (the default): the clock follows the time the caller gives.
  void set_frame_step(double seconds) { frame_step_ = std::isfinite(seconds) && seconds > 0 ? seconds : 0.0; }
  double frame_step() const { return frame_step_; }

 private:
  SyntheticWorld world_;
  std::vector<TruthMarker> truth_;
  double clock_ = 0, last_now_ = 0;
  double frame_step_ = 0;
  bool given_ = false;   // a frame was given
  bool have_last_ = false;
};

// Opens any source: the synthetic one, or a camera, video, image or folder (capture's open_capture_source). Null
// and a one-line message when it cannot be opened.
std::unique_ptr<FrameSource> open_source(const SourceSpec& spec, std::string* error);

}  // namespace arwb
