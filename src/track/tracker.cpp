#include "track/tracker.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

namespace arwb {
namespace {

// Where the diagonals cross: the projection of the marker's centre, unlike the mean of the corners.
cv::Point2d diagonal_centre(const Quad& q) {
  const cv::Point2d a = q[0], c = q[2], b = q[1], d = q[3];
  const cv::Point2d r = c - a, s = d - b;
  const double den = r.x * s.y - r.y * s.x;
  if (std::abs(den) < 1e-12) return (a + b + c + d) * 0.25;
  const double t = ((b - a).x * s.y - (b - a).y * s.x) / den;
  return a + r * t;
}

double mean_side(const Quad& q) {
  double s = 0;
  for (int i = 0; i < 4; ++i) s += cv::norm(q[(i + 1) % 4] - q[i]);
  return s / 4;
}

// The smoothing factor of an exponential filter with this cutoff, for a step of dt seconds.
double alpha(double cutoff_hz, double dt) {
  const double tau = 1.0 / (2 * std::numbers::pi * std::max(cutoff_hz, 1e-6));
  return 1.0 / (1.0 + tau / dt);
}

}  // namespace

double OneEuro::filter(double x, double t_s, const SmoothingSettings& s) {
  if (!started_) {
    started_ = true;
    x_ = x;
    dx_ = 0;
    t_ = t_s;
    return x;
  }
  const double dt = t_s - t_;
  if (!(dt > 0)) return x_;   // the same frame again (a redetection of a frozen frame): as filtered then
  t_ = t_s;
  const double dx = (x - x_) / dt;
  dx_ += alpha(s.d_cutoff_hz, dt) * (dx - dx_);
  const double cutoff = s.min_cutoff_hz + s.beta * std::abs(dx_);
  x_ += alpha(cutoff, dt) * (x - x_);
  return x_;
}

void Tracker::clear() {
  tracks_.clear();
  filters_.clear();
}

void Tracker::set_camera(const Calibration& camera, double marker_side) {
  camera_ = camera;
  marker_side_ = marker_side > 0 ? marker_side : 1.0;
}

std::vector<TrackEvent> Tracker::update(const std::vector<Marker>& markers, double t_s) {
  // Every (track, detection) pair of one id within the gate, nearest first; taken greedily, so each track gets
  // the detection nearest its predicted centre and two prints of one id moving past each other keep theirs.
  struct Pair {
    double d;
    size_t track, det;
  };
  std::vector<Pair> pairs;
  std::vector<cv::Point2d> det_centre(markers.size());
  std::vector<double> det_side(markers.size());
  for (size_t j = 0; j < markers.size(); ++j) {
    det_centre[j] = diagonal_centre(markers[j].corners);
    det_side[j] = mean_side(markers[j].corners);
  }
  for (size_t i = 0; i < tracks_.size(); ++i) {
    const TrackedMarker& t = tracks_[i];
    const Filters& f = filters_[t.track_id];
    const double ahead = std::clamp(t_s - t.last_seen_s, 0.0, settings_.hold_s);
    const cv::Point2d predicted = f.raw_centre + f.velocity * ahead;
    for (size_t j = 0; j < markers.size(); ++j) {
      if (markers[j].id != t.id) continue;
      const double d = cv::norm(det_centre[j] - predicted);
      if (d <= settings_.gate_sides * std::max(t.side_px, det_side[j])) pairs.push_back({d, i, j});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
    return std::tie(a.d, a.track, a.det) < std::tie(b.d, b.track, b.det);
  });
  std::vector<int> match(tracks_.size(), -1);
  std::vector<bool> used(markers.size(), false);
  for (const Pair& p : pairs) {
    if (match[p.track] >= 0 || used[p.det]) continue;
    match[p.track] = static_cast<int>(p.det);
    used[p.det] = true;
  }

  const SmoothingSettings& sm = settings_.smoothing;
  auto smooth = [&](TrackedMarker& t, Filters& f) {
    for (size_t k = 0; k < 4; ++k) {
      const double x = f.xy[2 * k].filter(t.raw_corners[k].x, t_s, sm);
      const double y = f.xy[2 * k + 1].filter(t.raw_corners[k].y, t_s, sm);
      // The filters run even when smoothing is off, so turning it on does not start from a stale value.
      t.corners[k] = sm.on ? cv::Point2f(float(x), float(y)) : t.raw_corners[k];
    }
  };
  auto pose = [&](TrackedMarker& t) {
    if (!camera_) {
      t.pose.reset();
      return;
    }
    std::optional<MarkerPose> p = estimate_marker_pose(t.corners, marker_side_, *camera_);
    if (p && t.pose) p = resolve_with_previous(*p, t.pose->pose.rvec);
    t.pose = p;
  };

  std::vector<TrackEvent> enters, leaves;
  std::vector<TrackedMarker> next;
  for (size_t i = 0; i < tracks_.size(); ++i) {
    TrackedMarker& t = tracks_[i];
    Filters& f = filters_[t.track_id];
    if (match[i] >= 0) {
      const Marker& m = markers[size_t(match[i])];
      const cv::Point2d c = det_centre[size_t(match[i])];
      const double dt = t_s - t.last_seen_s;
      if (dt > 0) f.velocity = 0.5 * f.velocity + 0.5 * (c - f.raw_centre) * (1.0 / dt);
      f.raw_centre = c;
      t.dict = m.dict;
      t.raw_corners = m.corners;
      smooth(t, f);
      pose(t);
      t.last_seen_s = t_s;
      t.detected = true;
      t.missed = 0;
    } else {
      t.detected = false;
      if (++t.missed > kMaxMissedFrames && t_s - t.last_seen_s > settings_.hold_s) {
        leaves.push_back({TrackEvent::Kind::leave, t.id, t.track_id});
        filters_.erase(t.track_id);
        continue;
      }
    }
    next.push_back(std::move(t));
  }
  for (size_t j = 0; j < markers.size(); ++j) {
    if (used[j]) continue;
    const Marker& m = markers[j];
    TrackedMarker t;
    t.id = m.id;
    t.dict = m.dict;
    t.track_id = next_track_id_++;
    t.raw_corners = m.corners;
    t.first_seen_s = t.last_seen_s = t_s;
    t.detected = true;
    Filters& f = filters_[t.track_id];
    f.raw_centre = det_centre[j];
    smooth(t, f);
    pose(t);
    enters.push_back({TrackEvent::Kind::enter, t.id, t.track_id});
    next.push_back(std::move(t));
  }
  for (TrackedMarker& t : next) {
    t.centre = diagonal_centre(t.corners);
    t.side_px = mean_side(t.corners);
    t.visible_s = t_s - t.first_seen_s;
  }
  // Track ids grow with first appearance: in (id, track_id) order each id's tracks come in their instance order.
  std::sort(next.begin(), next.end(),
            [](const auto& a, const auto& b) { return std::tie(a.id, a.track_id) < std::tie(b.id, b.track_id); });
  for (size_t i = 0; i < next.size(); ++i) next[i].instance = i > 0 && next[i - 1].id == next[i].id
                                                                  ? next[i - 1].instance + 1 : 0;
  auto by_id = [](const TrackEvent& a, const TrackEvent& b) {
    return std::tie(a.id, a.track_id) < std::tie(b.id, b.track_id);
  };
  std::sort(enters.begin(), enters.end(), by_id);
  std::sort(leaves.begin(), leaves.end(), by_id);
  tracks_ = std::move(next);
  enters.insert(enters.end(), leaves.begin(), leaves.end());
  return enters;
}

}  // namespace arwb
