// nested_filter: quads that trace the same border twice become one, the outer (or the finer search's) kept.
#include "detect/pipeline.hpp"

#include <opencv2/imgproc.hpp>

namespace arwb::stages {

std::vector<int> nested_filter(const std::vector<Quad>& quads, const DetectorParams& p,
                               const std::vector<int>* factors) {
  // Thick borders give two contours for one marker (outer and inner edge of the thresholded line); keep the
  // outer one. Two quads are the same when, for some cyclic pairing of corners, their mean corner distance is
  // below min_marker_distance_rate times the smaller perimeter.
  const size_t n = quads.size();
  std::vector<double> perim(n);
  std::vector<cv::Rect> box(n);
  for (size_t i = 0; i < n; ++i) {
    perim[i] = quad_perimeter(quads[i]);
    box[i] = cv::boundingRect(std::vector<cv::Point2f>(quads[i].begin(), quads[i].end()));
  }
  std::vector<int> replaced_by(n, -1);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      if ((box[i] & box[j]).area() <= 0) continue;
      const double limit = p.min_marker_distance_rate * std::min(perim[i], perim[j]);
      double best = 1e18;
      for (int shift = 0; shift < 4; ++shift) {
        double d = 0;
        for (int k = 0; k < 4; ++k) d += cv::norm(quads[i][size_t(k)] - quads[j][size_t((k + shift) % 4)]);
        best = std::min(best, d / 4);
      }
      if (best >= limit) continue;
      size_t inner = perim[i] < perim[j] ? i : j, outer = inner == i ? j : i;
      if (factors && (*factors)[inner] < (*factors)[outer])
        std::swap(inner, outer);   // the finer one stays
      if (replaced_by[inner] < 0) replaced_by[inner] = static_cast<int>(outer);
    }
  return replaced_by;
}

}  // namespace arwb::stages
