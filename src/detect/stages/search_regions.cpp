// search_regions: where the search looks on this frame, the whole frame or around the markers earlier frames found.
#include "detect/pipeline.hpp"

#include <opencv2/imgproc.hpp>

#include <cmath>

namespace arwb::stages {

void merge_overlapping(std::vector<cv::Rect>& rects) {
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t i = 0; i < rects.size() && !merged; ++i)
      for (size_t j = i + 1; j < rects.size() && !merged; ++j)
        if ((rects[i] & rects[j]).area() > 0) {
          rects[i] |= rects[j];
          rects.erase(rects.begin() + long(j));
          merged = true;
        }
  }
  std::sort(rects.begin(), rects.end(),
            [](const cv::Rect& a, const cv::Rect& b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
}

SearchPlan plan_search(cv::Size grey, const std::vector<Quad>& known, const DetectorParams& p) {
  SearchPlan plan;
  const cv::Rect frame(0, 0, grey.width, grey.height);
  plan.factor = decimation_used(grey, p);
  plan.regions = {frame};
  if (known.empty() || frame.empty()) return plan;
  double smallest = 1e30;
  std::vector<cv::Rect> regions;
  for (const Quad& q : known) {
    const double side = quad_perimeter(q) / 4;
    if (!std::isfinite(side) || side <= 0) continue;
    smallest = std::min(smallest, side);
    const cv::Rect box = cv::boundingRect(std::vector<cv::Point2f>(q.begin(), q.end()));
    const int m = int(std::ceil(p.region_margin_rate * side));
    const cv::Rect r = cv::Rect(box.x - m, box.y - m, box.width + 2 * m, box.height + 2 * m) & frame;
    if (!r.empty()) regions.push_back(r);
  }
  if (regions.empty()) return plan;
  const int f = std::clamp(int(smallest / std::max(1.0, p.region_min_side_px)), 1, 4);
  // Whole decimated pixels, from the frame's origin, so that a region's blocks are the frame's blocks; and at least
  // 16 decimated pixels a side, enough for the threshold's window to see past a marker.
  const int min_side = 16 * f;
  for (cv::Rect& r : regions) {
    int x0 = r.x / f * f, y0 = r.y / f * f;
    int x1 = std::max(r.br().x, x0 + min_side), y1 = std::max(r.br().y, y0 + min_side);
    x1 = (x1 + f - 1) / f * f;
    y1 = (y1 + f - 1) / f * f;
    r = cv::Rect(cv::Point(x0, y0), cv::Point(x1, y1)) & frame;
  }
  merge_overlapping(regions);   // no contour is found twice
  double area = 0;
  for (const cv::Rect& r : regions) area += r.area();
  plan.whole = false;
  plan.factor = f;
  if (area > 0.7 * frame.area()) {
    plan.regions = {frame};   // most of the frame: one search over it costs less than several
  } else {
    plan.regions = std::move(regions);
  }
  return plan;
}

bool cut_by_region(const cv::Rect& box, const cv::Rect& region, cv::Size grey, int factor) {
  const int reach = factor;   // a contour's points are block centres: within a block of the edge touches it
  return (region.x > 0 && box.x - region.x < reach) || (region.y > 0 && box.y - region.y < reach) ||
         (region.br().x < grey.width && region.br().x - box.br().x < reach) ||
         (region.br().y < grey.height && region.br().y - box.br().y < reach);
}

}  // namespace arwb::stages
