#include "peers/match.hpp"

#include <algorithm>
#include <cmath>

namespace arwb {

namespace {
double length(cv::Point2f d) { return std::sqrt(double(d.x) * d.x + double(d.y) * d.y); }
}  // namespace

double mean_side(const Quad& q) {
  double s = 0;
  for (size_t k = 0; k < 4; ++k) s += length(q[k] - q[(k + 1) % 4]);
  return s / 4;
}

double mean_corner_distance(const Quad& a, const Quad& b) {
  double s = 0;
  for (size_t k = 0; k < 4; ++k) s += length(a[k] - b[k]);
  return s / 4;
}

double match_tolerance_px(const Quad& reference) { return std::max(kMatchMinPx, kMatchSideRate * mean_side(reference)); }

double MarkerMatching::mean_corner_px() const {
  if (pairs.empty()) return 0;
  double s = 0;
  for (const MatchedPair& p : pairs) s += p.corner_px;
  return s / double(pairs.size());
}

MarkerMatching match_markers(const std::vector<Marker>& reference, const std::vector<Marker>& found) {
  MarkerMatching m;
  std::vector<bool> taken(reference.size(), false);
  for (size_t j = 0; j < found.size(); ++j) {
    const Marker& f = found[j];
    size_t best = reference.size();
    double best_d = 0;
    for (size_t i = 0; i < reference.size(); ++i) {
      const Marker& r = reference[i];
      if (taken[i] || r.id != f.id || r.dict != f.dict) continue;
      const double d = mean_corner_distance(r.corners, f.corners);
      if (d > match_tolerance_px(r.corners) || (best < reference.size() && d >= best_d)) continue;
      best = i;
      best_d = d;
    }
    if (best == reference.size()) {
      m.only_found.push_back(j);
      continue;
    }
    taken[best] = true;
    m.pairs.push_back({best, j, best_d});
  }
  for (size_t i = 0; i < reference.size(); ++i)
    if (!taken[i]) m.only_reference.push_back(i);
  return m;
}

}  // namespace arwb
