// The lines of a quad's sides, fitted to points and met at the corners: quad_fit and corner_refinement's. Internal
// to the stages.
#pragma once

#include "detect/quad.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <cmath>
#include <iterator>

namespace arwb::stages {

// A side of a quad as the line a x + b y = c, (a, b) unit, fitted through its points by least squares (the line
// through their centroid along the principal axis of their scatter, as cv::fitLine's DIST_L2, without its
// allocations: the refinement fits four lines a pass).
template <class Points>
inline cv::Vec3d fit_side(const Points& pts) {
  double mx = 0, my = 0;
  for (const auto& q : pts) mx += q.x, my += q.y;
  const double n = double(std::size(pts));
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0, syy = 0;
  for (const auto& q : pts) {
    const double dx = q.x - mx, dy = q.y - my;
    sxx += dx * dx;
    sxy += dx * dy;
    syy += dy * dy;
  }
  const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);   // the direction of largest spread
  const double vx = std::cos(angle), vy = std::sin(angle);
  return cv::Vec3d(-vy, vx, -vy * mx + vx * my);
}

// Corner i where side i-1 meets side i, for the four corners; false when two neighbouring sides are parallel.
inline bool meet_sides(const std::array<cv::Vec3d, 4>& sides, Quad* corners) {
  for (size_t i = 0; i < 4; ++i) {
    const cv::Vec3d &l1 = sides[(i + 3) % 4], &l2 = sides[i];
    const double det = l1[0] * l2[1] - l1[1] * l2[0];
    if (std::abs(det) < 1e-9) return false;
    (*corners)[i] = cv::Point2f(float((l1[2] * l2[1] - l1[1] * l2[2]) / det),
                                float((l1[0] * l2[2] - l1[2] * l2[0]) / det));
  }
  return true;
}

}  // namespace arwb::stages
