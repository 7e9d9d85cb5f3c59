#include "synth/synthetic_source.hpp"

#include <algorithm>
#include <cmath>

namespace arwb {

SourceStatus SyntheticSource::next(double now_s, cv::Mat& out) {
  SyntheticControls& c = world_.controls();
  // The world's clock integrates speed, so changing speed does not make it jump. While animating the clock is
  // published in time_s, so that stopping the animation holds the world where it was; while not animating time_s
  // drives the clock, so resuming continues from where the slider was left.
  // A frame step stands for the time between calls (the first frame is still at the clock's start).
  const double dt = frame_step_ > 0 ? (given_ ? frame_step_ : 0.0)
                    : have_last_ && std::isfinite(now_s) ? std::max(0.0, now_s - last_now_) : 0.0;
  if (std::isfinite(now_s)) last_now_ = now_s, have_last_ = true;
  given_ = true;
  if (c.animate) {
    clock_ += dt * std::clamp(std::isfinite(c.speed) ? c.speed : 1.0, 0.0, 4.0);
    c.time_s = clock_;
  } else {
    clock_ = std::isfinite(c.time_s) ? c.time_s : 0.0;
  }
  SyntheticFrame f = world_.render(clock_);
  out = std::move(f.image);
  truth_ = std::move(f.markers);
  return {};
}

const SynthCamera* SyntheticSource::board_camera() const { return world_.board_camera(); }

SourceInfo SyntheticSource::info() const {
  SourceInfo i;
  i.kind = SourceKind::synthetic;
  i.name = "synthetic";
  i.size = world_.size();
  return i;
}

}  // namespace arwb
