#include "track/tracker.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>

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

double area(const Quad& q) {
  double s = 0;
  for (int i = 0; i < 4; ++i) s += double(q[i].x) * q[(i + 1) % 4].y - double(q[(i + 1) % 4].x) * q[i].y;
  return std::abs(s) * 0.5;
}

double mean_side(const Quad& q) {
  double s = 0;
  for (int i = 0; i < 4; ++i) s += cv::norm(q[(i + 1) % 4] - q[i]);
  return s / 4;
}

}  // namespace

std::vector<TrackEvent> Tracker::update(const std::vector<Marker>& markers, double t_s) {
  std::map<int, const Marker*> seen;   // id -> its largest instance this frame
  for (const Marker& m : markers) {
    auto [it, fresh] = seen.emplace(m.id, &m);
    if (!fresh && area(m.corners) > area(it->second->corners)) it->second = &m;
  }
  std::vector<TrackEvent> enters, leaves;
  std::vector<TrackedMarker> next;
  for (TrackedMarker& t : tracks_) {
    auto it = seen.find(t.id);
    if (it != seen.end()) {
      t.dict = it->second->dict;
      t.corners = it->second->corners;
      t.last_seen_s = t_s;
      t.detected = true;
      seen.erase(it);
    } else {
      t.detected = false;
      if (t_s - t.last_seen_s > settings_.hold_s) {
        leaves.push_back({TrackEvent::Kind::leave, t.id});
        continue;
      }
    }
    next.push_back(std::move(t));
  }
  for (const auto& [id, m] : seen) {
    TrackedMarker t;
    t.id = id;
    t.dict = m->dict;
    t.corners = m->corners;
    t.first_seen_s = t.last_seen_s = t_s;
    t.detected = true;
    next.push_back(std::move(t));
    enters.push_back({TrackEvent::Kind::enter, id});
  }
  for (TrackedMarker& t : next) {
    t.centre = diagonal_centre(t.corners);
    t.side_px = mean_side(t.corners);
    t.visible_s = t_s - t.first_seen_s;
  }
  std::sort(next.begin(), next.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  std::sort(leaves.begin(), leaves.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  tracks_ = std::move(next);
  enters.insert(enters.end(), leaves.begin(), leaves.end());
  return enters;
}

}  // namespace arwb
