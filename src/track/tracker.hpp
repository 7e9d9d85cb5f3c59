// Markers over time: which markers are in view, since when, and where. The scene's callbacks (on_enter,
// on_update, on_leave) and video playback hang on this. A marker missed for a moment (a blurred frame, a hand
// passing) keeps its last corners for `hold_s`, so media do not flicker; after that it leaves.
//
// One track per physical marker: two prints of the same id are two tracks. A frame's detections are matched to
// the tracks of their id by the nearest predicted centre, within a gate of a couple of marker sides; what is
// left over enters as a new track. Each track's corners are smoothed over time by the One Euro filter (Casiez,
// Roussel and Vogel, CHI 2012), and its pose is computed from the smoothed corners with the tracker's camera,
// the ambiguity resolved by the track's previous pose.
#pragma once

#include "detect/trace.hpp"
#include "pose/marker_pose.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace arwb {

struct TrackedMarker {
  int id = -1;
  std::string dict;
  uint64_t track_id = 0;       // unique for the tracker's life, never reused
  int instance = 0;            // among the tracks of the same id now: 0, 1, ... in order of first appearance
  Quad corners{};              // last corners (image pixels), smoothed when the filter is on
  Quad raw_corners{};          // as detected on the last frame it was seen (corners is the filtered version)
  cv::Point2d centre{};        // intersection of the diagonals of `corners`
  double side_px = 0;          // mean side length
  double first_seen_s = 0;     // when it entered (this visit)
  double last_seen_s = 0;      // when it was last detected
  double visible_s = 0;        // seconds since it entered
  bool detected = false;       // detected on this frame (false while held)
  int missed = 0;              // frames missed in a row (0 while detected)
  std::optional<MarkerPose> pose;   // from `corners` with the tracker's camera and marker side
};

struct TrackEvent {
  enum class Kind { enter, leave };
  Kind kind = Kind::enter;
  int id = -1;
  uint64_t track_id = 0;
};

// The One Euro filter's settings (DetectorParams' tracking_* rows carry them in the parameter table).
struct SmoothingSettings {
  bool on = true;
  double min_cutoff_hz = 1.0;   // cutoff of a still corner: lower is steadier, and lags more when it starts moving
  double beta = 1.0;            // how much the cutoff rises with speed (per px/s): higher lags less when moving
  double d_cutoff_hz = 1.0;     // cutoff of the speed estimate the cutoff follows
};

// A marker missed on this many frames in a row or fewer stays, whatever the time: at 4 fps one missed frame is
// already half a second.
inline constexpr int kMaxMissedFrames = 2;

struct TrackerSettings {
  double hold_s = 0.25;        // how long a missed marker stays (with its last corners) before it leaves; it also
                               // stays while missed on at most kMaxMissedFrames frames in a row
  double gate_sides = 2.0;     // a detection joins a track whose predicted centre is within this many sides
  SmoothingSettings smoothing{};
};

// One scalar through the One Euro filter: a low-pass whose cutoff rises with the signal's speed, so a still
// value is smoothed hard and a moving one follows closely.
class OneEuro {
 public:
  // The filtered value of x at time t_s. The first call, or one at a time not after the last, passes x through
  // (a time not after the last is the same frame seen again: its value is taken as is).
  double filter(double x, double t_s, const SmoothingSettings& s);
  void reset() { started_ = false; }

 private:
  bool started_ = false;
  double x_ = 0, dx_ = 0, t_ = 0;
};

class Tracker {
 public:
  explicit Tracker(TrackerSettings s = {}) : settings_(s) {}
  // Feeds one frame's detections, taken at time t_s (seconds, non-decreasing). Returns the frame's events:
  // enters first, then leaves, each in id order (then track_id).
  std::vector<TrackEvent> update(const std::vector<Marker>& markers, double t_s);
  // Markers in view (detected now or held), in id order, then instance.
  const std::vector<TrackedMarker>& tracks() const { return tracks_; }
  void clear();

  void set_smoothing(const SmoothingSettings& s) { settings_.smoothing = s; }
  void set_hold(double hold_s) { settings_.hold_s = hold_s; }
  // The camera poses are computed with, and the marker's side (tvec in its unit; 1: in marker sides). Without a
  // camera (the default) tracks have no pose.
  void set_camera(const Calibration& camera, double marker_side = 1.0);
  const TrackerSettings& settings() const { return settings_; }

 private:
  struct Filters {
    std::array<OneEuro, 8> xy;   // x and y of the four corners
    cv::Point2d velocity{};      // of the raw centre, px/s, for the prediction that matches detections
    cv::Point2d raw_centre{};
  };
  TrackerSettings settings_;
  std::vector<TrackedMarker> tracks_;
  std::map<uint64_t, Filters> filters_;   // per track_id
  uint64_t next_track_id_ = 1;
  std::optional<Calibration> camera_;
  double marker_side_ = 1.0;
};

}  // namespace arwb
