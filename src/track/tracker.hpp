// Markers over time: which ids are in view, since when, and where. The scene's callbacks (on_enter, on_update,
// on_leave) and video playback hang on this. A marker missed for a moment (a blurred frame, a hand passing)
// keeps its last corners for `hold_s`, so media do not flicker; after that it leaves.
//
// One track per id: when an id is seen twice in a frame, the larger instance is tracked.
#pragma once

#include "detect/trace.hpp"
#include "pose/marker_pose.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace arwb {

struct TrackedMarker {
  int id = -1;
  std::string dict;
  Quad corners{};              // last detected corners (image pixels)
  cv::Point2d centre{};        // intersection of the diagonals
  double side_px = 0;          // mean side length
  double first_seen_s = 0;     // when it entered (this visit)
  double last_seen_s = 0;      // when it was last detected
  double visible_s = 0;        // seconds since it entered
  bool detected = false;       // detected on this frame (false while held)
  uint64_t track_id = 0;       // unique for the tracker's life, never reused
  int instance = 0;            // among the tracks of the same id now: 0, 1, ... in order of first appearance
  Quad raw_corners{};          // as detected on this frame (corners is the filtered version)
  std::optional<MarkerPose> pose;   // with the tracker's camera and marker side
};

struct TrackEvent {
  enum class Kind { enter, leave };
  Kind kind = Kind::enter;
  int id = -1;
};

struct TrackerSettings {
  double hold_s = 0.25;        // how long a missed marker stays (with its last corners) before it leaves
};

class Tracker {
 public:
  explicit Tracker(TrackerSettings s = {}) : settings_(s) {}
  // Feeds one frame's detections, taken at time t_s (seconds, non-decreasing). Returns the frame's events:
  // enters first, then leaves, each in id order.
  std::vector<TrackEvent> update(const std::vector<Marker>& markers, double t_s);
  // Markers in view (detected now or held), in id order.
  const std::vector<TrackedMarker>& tracks() const { return tracks_; }
  void clear() { tracks_.clear(); }

 private:
  TrackerSettings settings_;
  std::vector<TrackedMarker> tracks_;
};

}  // namespace arwb
