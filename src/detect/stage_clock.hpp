// Timing and recording the detector's stages into the trace: one clock per frame. Internal to the detector.
#pragma once

#include "detect/trace.hpp"

#include <chrono>

namespace arwb {

class StageClock {
 public:
  using Clock = std::chrono::steady_clock;

  // `timed`: the trace records stages (summary or full); `full`: it keeps their pictures.
  StageClock(FrameTrace& trace, bool timed, bool full)
      : trace_(trace), timed_(timed), full_(full), frame_start_(Clock::now()), stage_start_(frame_start_) {}

  // Closes the stage that ran since the last close: its time, its counts and (full trace) its picture.
  void close(Stage s, int in, int out, const cv::Mat& image = {}) {
    if (!timed_) return;
    trace_.stages.push_back(StageRecord{s, ms_since(stage_start_), in, out, full_ ? image : cv::Mat()});
    stage_start_ = Clock::now();
  }
  // The milliseconds since the last close or lap, and starts again from now (a stage that runs in pieces sums
  // its laps and records them with record()).
  double lap() {
    if (!timed_) return 0;
    const double ms = ms_since(stage_start_);
    stage_start_ = Clock::now();
    return ms;
  }
  void record(StageRecord r) {
    if (!timed_) return;
    if (!full_) r.image.release();
    trace_.stages.push_back(std::move(r));
    stage_start_ = Clock::now();
  }
  // Work done for acquisition while a later stage runs (grey pixels converted where it looks): `spent` goes to
  // acquisition's record, the first, and not to the running stage. Returns it in milliseconds.
  double charge_to_acquisition(Clock::duration spent) {
    if (!timed_) return 0;
    stage_start_ += spent;
    const double ms = std::chrono::duration<double, std::milli>(spent).count();
    trace_.stages.front().ms += ms;
    return ms;
  }
  double frame_ms() const { return ms_since(frame_start_); }
  bool timed() const { return timed_; }

  static double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }

 private:
  FrameTrace& trace_;
  bool timed_, full_;
  Clock::time_point frame_start_, stage_start_;
};

}  // namespace arwb
