// `arwb bench --tracking`: how steady the tracker's corners and poses are on a still marker under sensor noise
// (jitter) and how far they trail a marker moving at a steady speed (lag), filtered (the One Euro filter with
// the table's tracking_* values; on even when tracking_smoothing is 0) against the detections as they are.
// Synthetic sequences rendered by MarkerRenderer, detected by arwb, followed by the Tracker at 30 frames a second.
#pragma once

#include "detect/params.hpp"

#include <string>

namespace arwb {

struct TrackingBenchOptions {
  int frames = 90;           // per sequence
  unsigned seed = 1;
  double noise = 6;          // grey levels of sensor noise on every frame
  double speed_px_s = 120;   // the moving marker's speed, about (it moves at a steady speed in metres)
  DetectorParams params{};   // the detector's and the tracker's (tracking_*)
};

struct TrackingFigures {
  double jitter_px = 0;       // still marker: RMS frame-to-frame motion of its corners
  double jitter_deg = 0;      // still marker: RMS frame-to-frame change of its pose's rotation
  double lag_px = 0;          // moving marker: mean corner offset behind the truth, along the motion
  double error_px = 0;        // moving marker: mean corner distance to the truth
};

struct TrackingBench {
  TrackingFigures raw, filtered;
  double speed_px_s = 0;      // the moving marker's mean corner speed in the images
  int still_frames = 0, moving_frames = 0;   // frames where the marker was detected (and measured)
  std::string error;          // non-empty when a sequence could not be measured
};

TrackingBench run_tracking_bench(const TrackingBenchOptions& o);

// The --tracking part of arwb bench: prints the table (or JSON) and returns the exit status.
int bench_tracking(const TrackingBenchOptions& o, bool as_json);

}  // namespace arwb
