// "Why isn't my marker detected?": given a region of a frame (the rectangle a user drags on the live view),
// say what became of everything the pipeline saw there, and find the smallest parameter change that makes a
// marker appear in it.
#pragma once

#include "detect/detector.hpp"
#include "detect/params.hpp"
#include "detect/trace.hpp"

#include <opencv2/core.hpp>

#include <atomic>
#include <functional>
#include <string>
#include <vector>

namespace arwb {

struct RegionCandidate {
  int index = -1;          // into FrameTrace::candidates
  Rejection fate;          // fate.stage == Stage::accepted for markers
  int marker_id = -1;      // when accepted
  std::string line;        // one line for the UI: "#12 quad 48x50 px: otsu: stddev 3.1 < otsu_min_stddev 5"
};

struct RegionReport {
  cv::Rect2f region;                       // working-image pixels, clipped to the frame
  std::vector<RegionCandidate> candidates; // every candidate whose contour or quad overlaps the region, the
                                           // furthest first (markers, then by stage reached, then larger)
  // When no candidate overlaps: the earliest stage that had nothing there (adaptive_threshold: no foreground
  // pixels; contours: no border long enough to be traced; size_filter; quad_fit). Stage::accepted otherwise.
  // A summary trace cannot tell the first three apart: size_filter, the latest it can be. A trace at level off
  // records no stages: acquisition.
  Stage lost_at = Stage::accepted;
  std::string summary;                     // one or two sentences for the UI
};

// Needs a full-level trace (stage images and every contour); with a summary trace it says so in `summary`.
RegionReport explain_region(const FrameTrace& trace, cv::Rect2f region);

struct SweepChange {
  std::string param;       // a parameter table name
  double from = 0, to = 0;
};

struct SweepResult {
  bool found = false;
  std::vector<SweepChange> changes;   // the smallest change found (one parameter, or two when none alone works)
  Marker marker;                      // the marker it revealed in the region
  int runs = 0;                       // detector runs made
  std::string message;                // "threshold_offset 7 -> 4 finds ARUCO_ORIGINAL id 12" or why none did
};

// Tries each parameter of the table over its range, nearest values first, and reports the change that is
// smallest relative to the parameter's range and makes a marker whose centre lies in `region` detected.
// `image` is the working image the trace came from. `progress` (0..1) and `cancel` may be null; the sweep
// stops early when cancel becomes true.
SweepResult sweep_region(const cv::Mat& image, const Detector& detector, cv::Rect2f region,
                         std::function<void(double)> progress = {}, const std::atomic<bool>* cancel = nullptr);

}  // namespace arwb
