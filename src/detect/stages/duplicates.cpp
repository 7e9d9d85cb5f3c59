// duplicates: one marker per id and place.
#include "detect/pipeline.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace arwb::stages {

std::vector<size_t> drop_duplicates(const std::vector<FoundMarker>& found, std::vector<std::string>* reasons) {
  reasons->assign(found.size(), {});
  std::vector<size_t> order(found.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const double pa = quad_perimeter(found[a].corners), pb = quad_perimeter(found[b].corners);
    return pa != pb ? pa > pb : found[a].key < found[b].key;
  });
  std::vector<size_t> kept;
  for (size_t k : order) {
    const FoundMarker& m = found[k];
    const cv::Point2f centre = quad_centre(m.corners);
    bool drop = false;
    for (size_t& o : kept) {
      const FoundMarker& big = found[o];
      const std::vector<cv::Point2f> poly(big.corners.begin(), big.corners.end());
      if (cv::pointPolygonTest(poly, centre, false) < 0) continue;
      drop = true;
      const bool same = m.dict == big.dict && m.id == big.id;
      if (same && m.factor < big.factor) {
        (*reasons)[o] = "id " + std::to_string(m.id) + " read by a finer search here";
        o = k;
        break;
      }
      (*reasons)[k] = same ? "id " + std::to_string(m.id) + " already found here"
                           : "inside marker " + std::to_string(big.id);
      break;
    }
    if (!drop) kept.push_back(k);
  }
  std::sort(kept.begin(), kept.end(), [&](size_t a, size_t b) {
    if (found[a].dict != found[b].dict) return found[a].dict < found[b].dict;
    if (found[a].id != found[b].id) return found[a].id < found[b].id;
    return found[a].key < found[b].key;
  });
  return kept;
}

}  // namespace arwb::stages
