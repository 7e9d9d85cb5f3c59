// fine_search: where a decimated search is searched again at full resolution, from the small shapes it could not
// close or read and the quad-shaped holes of its dark shapes.
#include "detect/stages/region_contours.hpp"

#include <opencv2/imgproc.hpp>

namespace arwb::stages {

std::vector<cv::Rect> plan_fine_search(const std::vector<cv::Rect>& shapes, cv::Size grey, const DetectorParams& p) {
  std::vector<cv::Rect> regions;
  if (p.fine_max_side_px <= 0) return regions;
  const cv::Rect frame(0, 0, grey.width, grey.height);
  // Half a side of margin: a decimated shape may hold only part of a blurred marker. And at least half the
  // threshold's window and two pixels, so that the marker's quiet zone is thresholded against its surroundings.
  const int min_margin = p.threshold_window_px / 2 + 2;
  for (const cv::Rect& b : shapes) {
    const int longer = std::max(b.width, b.height), shorter = std::min(b.width, b.height);
    if (longer > p.fine_max_side_px || 3 * shorter < longer || 2.0 * (b.width + b.height) < 0.75 * p.min_perimeter_px)
      continue;
    const int m = std::max(longer / 2, min_margin);
    const cv::Rect r = cv::Rect(b.x - m, b.y - m, b.width + 2 * m, b.height + 2 * m) & frame;
    if (r.width >= 32 && r.height >= 32) regions.push_back(r);   // less is in the frame's corner: too little to search
  }
  merge_overlapping(regions);
  return regions;
}

std::vector<cv::Rect> quad_holes(const cv::Mat& binary, const std::vector<cv::Rect>& dark, cv::Point origin,
                                 cv::Size grey, const DetectorParams& p, int factor, const std::vector<Quad>& markers) {
  std::vector<cv::Rect> boxes;
  if (p.fine_max_side_px <= 0) return boxes;
  factor = std::max(factor, 1);
  const cv::Rect image(0, 0, binary.cols, binary.rows);
  std::vector<cv::Rect> shapes;   // in the binary's pixels
  for (const cv::Rect& d : dark) {
    if (std::max(d.width, d.height) <= p.fine_max_side_px) continue;
    const cv::Rect box = d - origin;
    const cv::Point tl(box.x / factor, box.y / factor);
    const cv::Point br((box.x + box.width - 1) / factor + 1, (box.y + box.height - 1) / factor + 1);
    shapes.push_back(cv::Rect(tl, br) & image);
  }
  merge_overlapping(shapes);
  // A light region whose centre lies in a marker read is the marker's: one of its cells, or its quiet zone on a
  // dark ground. It is not traced (the cells of a frame's large markers would otherwise be most of this work).
  std::vector<std::vector<cv::Point2f>> outlines;   // the markers' quads as polygons, made once
  for (const Quad& q : markers) outlines.emplace_back(q.begin(), q.end());
  auto outside_markers = [&](const cv::Rect& hole) {
    const cv::Point2f centre(float(hole.x) + 0.5f * float(hole.width), float(hole.y) + 0.5f * float(hole.height));
    return std::none_of(outlines.begin(), outlines.end(),
                        [&](const std::vector<cv::Point2f>& o) { return cv::pointPolygonTest(o, centre, false) >= 0; });
  };
  // A marker's inside is 5/7 of its side (ARUCO_ORIGINAL; more for larger grids): half of min_perimeter_px keeps
  // the insides of the smallest markers the search is for.
  for (const cv::Rect& s : shapes) {
    const cv::Point shift = origin + s.tl() * factor;
    // A light region at the box's edge is not inside the shape (a hole lies within its region's box): not traced.
    auto inside_box = [&](const cv::Rect& in) {
      return in.x >= factor && in.y >= factor && in.x + in.width <= (s.width - 1) * factor &&
             in.y + in.height <= (s.height - 1) * factor;
    };
    std::vector<std::vector<cv::Point>> found =
        region_contours(binary(s), true, p.min_perimeter_px / 2, nullptr, nullptr, factor, int(p.fine_max_side_px),
                              [&](const cv::Rect& in) { return inside_box(in) && outside_markers(in + shift); });
    for (auto& c : found) {
      const cv::Rect in = cv::boundingRect(c);
      for (cv::Point& pt : c) pt += shift;
      Quad q;
      if (!fit_quad(c, grey, p, &q, factor, false)) boxes.push_back(in + shift);
    }
  }
  return boxes;
}

}  // namespace arwb::stages
