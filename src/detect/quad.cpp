#include "detect/quad.hpp"

namespace arwb {

double quad_perimeter(const Quad& q) {
  double s = 0;
  for (size_t i = 0; i < 4; ++i) s += cv::norm(q[i] - q[(i + 1) % 4]);
  return s;
}

cv::Point2f quad_centre(const Quad& q) {
  cv::Point2f c(0, 0);
  for (const auto& p : q) c += p * 0.25f;
  return c;
}

}  // namespace arwb
