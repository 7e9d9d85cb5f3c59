// quad_fit: a contour approximated by a convex quad (Douglas-Peucker as cv::approxPolyDP, then its sides fitted to
// the contour's points), clockwise on screen, or the rejection.
#include "detect/pipeline.hpp"

#include "detect/kernels/kernels.hpp"
#include "detect/stages/polygon.hpp"
#include "detect/stages/rejection.hpp"
#include "detect/stages/side_lines.hpp"
#include "detect/stages/thin_lines.hpp"

#include <opencv2/imgproc.hpp>

#include <cstddef>

namespace arwb::stages {

Farthest farthest_point(const cv::Point* c, int n, cv::Point p0, cv::Point dir, bool from_line) {
  static_assert(sizeof(cv::Point) == sizeof(kernels::Point) && offsetof(kernels::Point, y) == sizeof(int),
                "a cv::Point is a kernels::Point");
  return kernels::kernels().farthest_point(reinterpret_cast<const kernels::Point*>(c), n, {p0.x, p0.y},
                                           {dir.x, dir.y}, from_line);
}

namespace {

// A polygon of more corners than this is clutter: its approximation gives up there.
constexpr int kMaxVertices = 8;

// The corners where lines fitted to each side's contour points meet. approxPolyDP's vertices are contour points,
// and a corner that blur or decimation rounded off puts its vertex a pixel or more inside the true corner; the
// sides stay straight. Each side uses the contour between its two vertices, less a fifth at each end (the
// rounding). A side with too few points, or a corner that lands implausibly far from its vertex, keeps the
// vertices as they are. `shift`: what the contour points lack of their block's centre on a decimated search.
Quad corners_from_sides(const std::vector<cv::Point>& contour, const std::array<int, 4>& at, double shift) {
  Quad out;
  std::array<cv::Point, 4> poly;
  for (size_t i = 0; i < 4; ++i) {
    poly[i] = contour[size_t(at[i])];
    out[i] = cv::Point2f(float(poly[i].x + shift), float(poly[i].y + shift));
  }
  const int n = int(contour.size());
  std::array<cv::Vec3d, 4> lines;  // a x + b y = c, (a, b) unit
  std::vector<cv::Point2f> pts;
  for (size_t i = 0; i < 4; ++i) {
    const int from = at[i], len = (at[(i + 1) % 4] - from + n) % n;
    const int trim = len / 5;
    pts.clear();
    for (int k = trim; k <= len - trim; ++k) pts.emplace_back(contour[size_t((from + k) % n)]);
    if (pts.size() < 3) return out;
    lines[i] = fit_side(pts);
  }
  Quad fitted;
  if (!meet_sides(lines, &fitted)) return out;
  for (size_t i = 0; i < 4; ++i) {
    fitted[i] += cv::Point2f(float(shift), float(shift));
    const double side = std::min(cv::norm(poly[i] - poly[(i + 1) % 4]), cv::norm(poly[i] - poly[(i + 3) % 4]));
    if (cv::norm(fitted[i] - out[i]) > 0.25 * side) return out;
  }
  return fitted;
}

}  // namespace

std::optional<Rejection> fit_quad(const std::vector<cv::Point>& contour, cv::Size image, const DetectorParams& p,
                                  Quad* quad, int factor, bool explain, bool* cut_from_lines) {
  const double perimeter = contour_length(contour, factor);
  const double epsilon = p.polygon_epsilon_rate * perimeter;
  std::array<int, kMaxVertices + 1> at{};
  std::pair<int, int> farthest{-1, -1};
  int vertices = approx_polygon(contour, epsilon, &at, &farthest);
  auto polygon = [&](const std::array<int, kMaxVertices + 1>& idx) {
    return std::vector<cv::Point>{contour[size_t(idx[0])], contour[size_t(idx[1])], contour[size_t(idx[2])],
                                  contour[size_t(idx[3])]};
  };
  if (vertices > 4 && contour.size() < 100) {
    // A small contour (under 100 steps) is jagged by whole pixels of the search image, and a corner rounded by blur
    // or decimation can take two vertices. One more try at twice the tolerance, kept only when the polygon still
    // covers the region (a blob is no quad).
    std::array<int, kMaxVertices + 1> coarse{};
    if (approx_polygon(contour, 2 * epsilon, &coarse, &farthest) == 4 &&
        cv::contourArea(polygon(coarse)) >= 0.85 * cv::contourArea(contour)) {
      at = coarse;
      vertices = 4;
    }
  }
  const double shift = (factor - 1) / 2.0 - (factor - 1) / 2;
  Quad cut;
  const bool cut_line = vertices > 4 && p.cut_thin_lines && cut_thin_lines(contour, farthest, p, factor, shift, &cut);
  if (cut_line) vertices = 4;
  if (vertices != 4) {
    std::string why;
    if (explain)
      why = vertices > kMaxVertices ? fmt("polygon has more than %.0f corners, not 4 (polygon_epsilon_rate %g)",
                                          kMaxVertices, p.polygon_epsilon_rate)
                                    : fmt("polygon has %.0f corners, not 4 (polygon_epsilon_rate %g)",
                                          double(vertices), p.polygon_epsilon_rate);
    return reject(Stage::quad_fit, "polygon_epsilon_rate", double(vertices), 4, std::move(why));
  }
  std::vector<cv::Point> poly = polygon(at);
  if (cut_line)
    for (size_t i = 0; i < 4; ++i) poly[i] = cv::Point(cvRound(cut[i].x), cvRound(cut[i].y));
  if (!cv::isContourConvex(poly)) return reject(Stage::quad_fit, "", 0, 0, "quad is not convex");
  double min_side = 1e18;
  for (int i = 0; i < 4; ++i) {
    const cv::Point d = poly[size_t(i)] - poly[size_t((i + 1) % 4)];
    min_side = std::min(min_side, std::sqrt(double(d.dot(d))));
  }
  // Of the quad's own perimeter when a line was cut off (the contour's holds the line's length twice), and half as
  // strict again: a quad cut from a row of a checkerboard's squares, which touch at their corners, is a 3:1 sliver
  // that reads as ARUCO_ORIGINAL 1023 (the lab's empty frames had one); a marker behind a line is not that thin.
  constexpr double kCutSideFactor = 1.5;
  const double min_allowed = cut_line ? kCutSideFactor * p.min_side_rate * cv::arcLength(poly, true)
                                      : p.min_side_rate * perimeter;
  if (min_side < min_allowed)
    return reject(Stage::quad_fit, "min_side_rate", min_side, min_allowed,
                  explain ? fmt("shortest side %.1f px < min_side_rate x perimeter = %.1f px", min_side, min_allowed)
                          : "");
  int edge = 1 << 30;
  for (const auto& pt : poly)
    edge = std::min({edge, pt.x, pt.y, image.width - 1 - pt.x, image.height - 1 - pt.y});
  if (edge < p.min_border_distance_px)
    return reject(Stage::quad_fit, "min_border_distance_px", edge, p.min_border_distance_px,
                  explain ? fmt("corner %.0f px from the image edge < min_border_distance_px %.0f px", edge,
                                p.min_border_distance_px)
                          : "");
  Quad q = cut_line ? cut : corners_from_sides(contour, {at[0], at[1], at[2], at[3]}, shift);
  // Clockwise on screen (y down): the cross product of the first two edges is positive.
  const cv::Point2f a = q[1] - q[0], b = q[2] - q[0];
  if (double(a.x) * b.y - double(a.y) * b.x < 0) std::swap(q[1], q[3]);
  *quad = q;
  if (cut_from_lines) *cut_from_lines = cut_line;
  return std::nullopt;
}

}  // namespace arwb::stages
