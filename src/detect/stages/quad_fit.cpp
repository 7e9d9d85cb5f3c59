// quad_fit: a contour approximated by a convex quad (Douglas-Peucker as cv::approxPolyDP, then its sides fitted to
// the contour's points), clockwise on screen, or the rejection.
#include "detect/pipeline.hpp"

#include "detect/kernels/kernels.hpp"
#include "detect/stages/rejection.hpp"
#include "detect/stages/side_lines.hpp"

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

// quad_fit's polygon: the Douglas-Peucker approximation of a closed contour within `epsilon` px as cv::approxPolyDP
// makes it, as indices into the contour in contour order. The first split is at an approximately farthest pair
// (from the first point, the farthest point three times over); each piece is split at its point farthest from its
// chord while that is more than epsilon away; at the end a vertex within epsilon / sqrt 2 of the line through its
// neighbours, and between them, is dropped. The vertices start at the first of the farthest pair. It gives up once
// there are more than kMaxVertices (a quad has four):
// a shape of many corners costs only its first splits, and no polygon is written.
constexpr int kMaxVertices = 8;
int approx_polygon(const std::vector<cv::Point>& c, double epsilon, std::array<int, kMaxVertices + 1>* out) {
  const int n = int(c.size());
  if (n < 3) return n;
  auto farthest_from = [&](int a) { return farthest_point(c.data(), n, c[size_t(a)], {}, false).at; };
  int a = farthest_from(0);
  a = farthest_from(a);
  const int b = farthest_from(a);
  const double eps2 = epsilon * epsilon;
  {
    const double dx = c[size_t(b)].x - c[size_t(a)].x, dy = c[size_t(b)].y - c[size_t(a)].y;
    if (dx * dx + dy * dy <= eps2) return 1;   // a blob within epsilon of one point
  }
  // Pieces [from, to] along the contour (indices taken modulo n, to > from), split depth first.
  std::array<std::pair<int, int>, 64> stack;
  int top = 0;
  stack[size_t(top++)] = {a, b > a ? b : b + n};
  stack[size_t(top++)] = {b, a > b ? a : a + n};
  std::array<int, kMaxVertices + 1> split{};
  int count = 0;
  split[size_t(count++)] = a;
  split[size_t(count++)] = b;
  while (top > 0) {
    const auto [from, to] = stack[size_t(--top)];
    const cv::Point p0 = c[size_t(from % n)], p1 = c[size_t(to % n)];
    // The farthest point from the chord, as integers (the cross product of whole pixels), in up to two runs of
    // the contour (a piece may wrap past its end).
    const int ix = p1.x - p0.x, iy = p1.y - p0.y;
    int64_t best = -1;
    int at = -1;
    auto scan = [&](int k0, int k1, int shift) {
      if (k1 <= k0) return;
      const Farthest f = farthest_point(c.data() + k0, k1 - k0, p0, {ix, iy}, true);
      if (f.measure > best) best = f.measure, at = k0 + f.at + shift;
    };
    scan(from + 1, std::min(to, n), 0);
    if (to > n) scan(std::max(from + 1, n) - n, to - n, n);
    if (at < 0 || double(best) * double(best) <= eps2 * (double(ix) * ix + double(iy) * iy)) continue;
    if (count == kMaxVertices + 1 || top + 2 > int(stack.size())) return kMaxVertices + 1;
    split[size_t(count++)] = at % n;
    stack[size_t(top++)] = {at, to};
    stack[size_t(top++)] = {from, at};
  }
  std::sort(split.begin(), split.begin() + count);
  // The last pass: drop a vertex nearly on the line through its neighbours and between them.
  int kept = 0;
  std::array<int, kMaxVertices + 1> v{};
  for (int i = 0; i < count; ++i) {
    if (count - (i - kept) <= 2) {   // keep at least three
      v[size_t(kept++)] = split[size_t(i)];
      continue;
    }
    const cv::Point u = kept > 0 ? c[size_t(v[size_t(kept - 1)])] : c[size_t(split[size_t(count - 1)])];
    const cv::Point p = c[size_t(split[size_t(i)])], w = c[size_t(split[size_t((i + 1) % count)])];
    const double dx = w.x - u.x, dy = w.y - u.y;
    const double d = std::abs((p.x - u.x) * dy - (p.y - u.y) * dx);
    const double between = double(p.x - u.x) * (w.x - p.x) + double(p.y - u.y) * (w.y - p.y);
    if (d * d <= 0.5 * eps2 * (dx * dx + dy * dy) && dx != 0 && dy != 0 && between >= 0) continue;
    v[size_t(kept++)] = split[size_t(i)];
  }
  // From the first of the farthest pair (or the vertex after it along the contour, if the last pass dropped it),
  // as approxPolyDP starts.
  int first = 0;
  while (first < kept && v[size_t(first)] < a) ++first;
  for (int i = 0; i < kept; ++i) (*out)[size_t(i)] = v[size_t((first + i) % kept)];
  return kept;
}

// The corners where lines fitted to each side's contour points meet. approxPolyDP's vertices are contour points,
// and a corner that blur or decimation rounded off puts its vertex a pixel or more inside the true corner; the
// sides stay straight. Each side uses the contour between its two vertices, less a fifth at each end (the
// rounding). A side with too few points, or a corner that lands implausibly far from its vertex, keeps the
// vertices as they are. `shift`: what the contour points lack of their block's centre on a decimated search.
// `max_off`: points farther than this from the chord between the side's vertices are not the side's (a line's stub).
Quad corners_from_sides(const std::vector<cv::Point>& contour, const std::array<int, 4>& at, double shift,
                        double max_off = 1e30) {
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
    const cv::Point2d p0 = poly[i], d = cv::Point2d(poly[(i + 1) % 4]) - p0;
    const double chord = std::max(cv::norm(d), 1.0);
    for (int k = trim; k <= len - trim; ++k) {
      const cv::Point c = contour[size_t((from + k) % n)];
      if (std::abs((c.x - p0.x) * d.y - (c.y - p0.y) * d.x) <= max_off * chord) pts.emplace_back(c);
    }
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

// A polygon of 5 to kMaxVertices corners that is a quad with a thin line's stub: four of its corners (in contour
// order) make a convex quad no larger than the contour (5 % spare), at least min_perimeter_px around; the others
// are one run between two of the four, at least one at least 3 blocks outside the quad (the stub's end), none
// inside it by more than `epsilon` (a notch: no marker), and the run's first and last within `epsilon` of the side
// it leaves (where the line leaves it and comes back). Of several, the largest quad. Text, rings, blobs and other
// polygons do not pass; what does is read like any quad.
bool quad_under_stub(const std::vector<cv::Point>& contour, double area, const std::array<int, kMaxVertices + 1>& at,
                     int n, double epsilon, int factor, double min_perimeter, std::array<int, 4>* four) {
  const double stub = 3.0 * factor;
  double best = 0;
  std::array<cv::Point2f, 4> q;
  auto cross = [&](int k) {
    const cv::Point2f u = q[size_t((k + 1) % 4)] - q[size_t(k)], w = q[size_t((k + 2) % 4)] - q[size_t((k + 1) % 4)];
    return double(u.x) * w.y - double(u.y) * w.x;
  };
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b)
      for (int c = b + 1; c < n; ++c)
        for (int d = c + 1; d < n; ++d) {
          const int idx[4] = {a, b, c, d};
          for (int k = 0; k < 4; ++k) q[size_t(k)] = contour[size_t(at[size_t(idx[k])])];
          const double turn0 = cross(0);
          if (turn0 == 0 || turn0 * cross(1) <= 0 || turn0 * cross(2) <= 0 || turn0 * cross(3) <= 0) continue;
          double quad_area = 0;
          for (int k = 0; k < 4; ++k) quad_area += double(q[size_t(k)].x) * q[size_t((k + 1) % 4)].y -
                                                   double(q[size_t((k + 1) % 4)].x) * q[size_t(k)].y;
          quad_area = std::abs(quad_area) / 2;
          if (quad_area <= best || quad_area > 1.05 * area) continue;
          double around = 0;
          for (int k = 0; k < 4; ++k) around += cv::norm(q[size_t((k + 1) % 4)] - q[size_t(k)]);
          if (around < min_perimeter) continue;
          // The run: the one gap between consecutive chosen corners (cyclically) that holds the others.
          const int gaps[4] = {b - a - 1, c - b - 1, d - c - 1, n - d - 1 + a};
          int gap = -1;
          for (int k = 0; k < 4; ++k)
            if (gaps[k] > 0) gap = gap < 0 ? k : 4;
          if (gap < 0 || gap == 4 || gaps[gap] < 2) continue;
          const cv::Point2f s0 = q[size_t(gap)], s1 = q[size_t((gap + 1) % 4)];
          const double len = std::max(double(cv::norm(s1 - s0)), 1.0);
          auto off_side = [&](int v) {
            const cv::Point2f r = cv::Point2f(contour[size_t(at[size_t(v % n)])]) - s0;
            return std::abs(double(r.x) * (s1 - s0).y - double(r.y) * (s1 - s0).x) / len;
          };
          if (off_side(idx[gap] + 1) > epsilon || off_side(idx[gap] + gaps[gap]) > epsilon) continue;
          const std::vector<cv::Point2f> poly(q.begin(), q.end());
          bool outside = false, notch = false;
          for (int v = 0; v < n; ++v) {
            if (v == a || v == b || v == c || v == d) continue;
            const double dist = cv::pointPolygonTest(poly, cv::Point2f(contour[size_t(at[size_t(v)])]), true);
            outside = outside || dist <= -stub;
            notch = notch || dist > epsilon;
          }
          if (!outside || notch) continue;
          best = quad_area;
          *four = {at[size_t(a)], at[size_t(b)], at[size_t(c)], at[size_t(d)]};
        }
  return best > 0;
}

// cut_thin_lines: the four corners of a polygon of more than 4 that is a quad with a stub, into at[0..3]. The stub's
// length counts twice in the contour's perimeter, and so in epsilon: a corner near where the line leaves can fall
// within it. So the polygon is made again at the tolerance of a square of the shape's area.
bool cut_stub(const std::vector<cv::Point>& contour, const DetectorParams& p, int factor, double epsilon,
              int vertices, std::array<int, kMaxVertices + 1>* at) {
  const double area = cv::contourArea(contour);
  const double fine_epsilon = std::min(epsilon, p.polygon_epsilon_rate * 4 * std::sqrt(area));
  std::array<int, kMaxVertices + 1> fine_at = *at;
  const int n = fine_epsilon < epsilon ? approx_polygon(contour, fine_epsilon, &fine_at) : vertices;
  std::array<int, 4> four{};
  if (n <= 4 || n > kMaxVertices ||
      !quad_under_stub(contour, area, fine_at, n, fine_epsilon, factor, p.min_perimeter_px, &four))
    return false;
  std::copy(four.begin(), four.end(), at->begin());
  return true;
}

}  // namespace

std::optional<Rejection> fit_quad(const std::vector<cv::Point>& contour, cv::Size image, const DetectorParams& p,
                                  Quad* quad, int factor, bool explain) {
  const double perimeter = contour_length(contour, factor);
  const double epsilon = p.polygon_epsilon_rate * perimeter;
  std::array<int, kMaxVertices + 1> at{};
  int vertices = approx_polygon(contour, epsilon, &at);
  auto polygon = [&](const std::array<int, kMaxVertices + 1>& idx) {
    return std::vector<cv::Point>{contour[size_t(idx[0])], contour[size_t(idx[1])], contour[size_t(idx[2])],
                                  contour[size_t(idx[3])]};
  };
  if (vertices > 4 && contour.size() < 100) {
    // A small contour (under 100 steps) is jagged by whole pixels of the search image, and a corner rounded by blur
    // or decimation can take two vertices. One more try at twice the tolerance, kept only when the polygon still
    // covers the region (a blob is no quad).
    std::array<int, kMaxVertices + 1> coarse{};
    if (approx_polygon(contour, 2 * epsilon, &coarse) == 4 &&
        cv::contourArea(polygon(coarse)) >= 0.85 * cv::contourArea(contour)) {
      at = coarse;
      vertices = 4;
    }
  }
  // Only a polygon of up to kMaxVertices corners: one of more is clutter, and the stub's search costs.
  const bool stub = vertices > 4 && vertices <= kMaxVertices && p.cut_thin_lines &&
                    cut_stub(contour, p, factor, epsilon, vertices, &at);
  if (stub) vertices = 4;
  if (vertices != 4) {
    std::string why;
    if (explain)
      why = vertices > kMaxVertices ? fmt("polygon has more than %.0f corners, not 4 (polygon_epsilon_rate %g)",
                                          kMaxVertices, p.polygon_epsilon_rate)
                                    : fmt("polygon has %.0f corners, not 4 (polygon_epsilon_rate %g)",
                                          double(vertices), p.polygon_epsilon_rate);
    return reject(Stage::quad_fit, "polygon_epsilon_rate", double(vertices), 4, std::move(why));
  }
  const std::vector<cv::Point> poly = polygon(at);
  if (!cv::isContourConvex(poly)) return reject(Stage::quad_fit, "", 0, 0, "quad is not convex");
  double min_side = 1e18;
  for (int i = 0; i < 4; ++i) {
    const cv::Point d = poly[size_t(i)] - poly[size_t((i + 1) % 4)];
    min_side = std::min(min_side, std::sqrt(double(d.dot(d))));
  }
  // Of the quad's own perimeter when a stub was cut (the contour's holds the line's length twice), and half as
  // strict again: a quad cut from a row of a checkerboard's squares, which touch at their corners, is a 3:1 sliver
  // that reads as ARUCO_ORIGINAL 1023 (the lab's empty frames had one); a marker behind a stub is not that thin.
  constexpr double kStubSideFactor = 1.5;
  const double min_allowed = stub ? kStubSideFactor * p.min_side_rate * cv::arcLength(poly, true)
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
  // A stub's points are off the sides by more than its thickness near where it leaves them.
  Quad q = corners_from_sides(contour, {at[0], at[1], at[2], at[3]}, (factor - 1) / 2.0 - (factor - 1) / 2,
                              stub ? 1.5 * factor : 1e30);
  // Clockwise on screen (y down): the cross product of the first two edges is positive.
  const cv::Point2f a = q[1] - q[0], b = q[2] - q[0];
  if (double(a.x) * b.y - double(a.y) * b.x < 0) std::swap(q[1], q[3]);
  *quad = q;
  return std::nullopt;
}

}  // namespace arwb::stages
