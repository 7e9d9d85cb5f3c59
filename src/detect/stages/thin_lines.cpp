// quad_fit's two ways to a marker that thin lines join to other shapes: cut_thin_lines, its quad from the straight
// runs of the shape's outline, and split_thin_lines, the shape split where its outline runs along both sides of a line.
#include "detect/stages/thin_lines.hpp"

#include "detect/stages/polygon.hpp"
#include "detect/stages/side_lines.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace arwb::stages {
namespace {

// The fine polygon gives up past kMaxRunVertices corners (clutter); of its long edges (runs), the kMaxRuns longest
// are tried as sides.
constexpr int kMaxRunVertices = 32;
constexpr int kMaxRuns = 10;
// An edge of the fine polygon.
struct Run {
  int first = 0, last = 0;   // contour indices, last after first (modulo the contour's size)
  double length = 0;
  cv::Point2d from, to, u;   // its ends, and its way as a unit vector
  int line = 0;
};
// A line of runs: a x + b y = c with (a, b) unit, and its way along the contour.
struct RunLine {
  cv::Vec3d eq;
  cv::Point2d way;
  double angle = 0;
};

cv::Vec3d line_through(cv::Point2d p0, cv::Point2d u) { return {-u.y, u.x, -u.y * p0.x + u.x * p0.y}; }

// The best of the quads that four of `lines` make with `runs` (in contour order), as its four lines' indices, or
// false: each turn clockwise by 20 to 160 degrees, each line's runs together along the contour, each side the way its
// runs go, covered by them for 0.4 of its length and the four for 0.7, no larger than the contour's `area` (5 %
// spare), no vertex of the polygon `at` inside it by more than eps and one at least `stub` outside.
bool best_four(const std::vector<cv::Point>& contour, double area, const std::array<int, kMaxRunVertices + 1>& at,
               int n,
               const std::array<Run, kMaxRunVertices>& runs, int count, const std::array<RunLine, kMaxRuns>& lines,
               int line_count, double eps, double stub, double min_run, double min_perimeter,
               std::array<int, 4>* pick) {
  double best = 0;
  // Which line may follow which (a clockwise turn of 20 to 160 degrees), and where each line's runs are.
  std::array<std::array<bool, kMaxRuns>, kMaxRuns> turns{};
  std::array<unsigned, kMaxRuns> at_runs{};
  std::array<int, kMaxRuns> first{}, last{};
  for (int i = 0; i < count; ++i) at_runs[size_t(runs[size_t(i)].line)] |= 1u << i;
  for (int l = 0; l < line_count; ++l) {
    first[size_t(l)] = std::countr_zero(at_runs[size_t(l)]);
    last[size_t(l)] = 31 - std::countl_zero(at_runs[size_t(l)]);
    for (int m = 0; m < line_count; ++m) {
      double t = lines[size_t(m)].angle - lines[size_t(l)].angle;
      if (t < 0) t += 2 * CV_PI;
      turns[size_t(l)][size_t(m)] = t > 20 * CV_PI / 180 && t < 160 * CV_PI / 180;
    }
  }
  // Lines are numbered as their first runs come: b's, c's and d's runs together, and a's before b's or after d's.
  auto between = [](int from, int to) { return to < from ? 0u : ((2u << to) - 1) & ~((1u << from) - 1); };
  for (int a = 0; a < line_count; ++a)
    for (int b = a + 1; b < line_count; ++b) {
      if (!turns[size_t(a)][size_t(b)]) continue;
      for (int c = b + 1; c < line_count; ++c) {
        if (!turns[size_t(b)][size_t(c)] || last[size_t(b)] > first[size_t(c)]) continue;
        for (int d = c + 1; d < line_count; ++d) {
          if (!turns[size_t(c)][size_t(d)] || !turns[size_t(d)][size_t(a)] || last[size_t(c)] > first[size_t(d)] ||
              (at_runs[size_t(a)] & between(first[size_t(b)], last[size_t(d)])) != 0)
            continue;
          const std::array<int, 4> four = {a, b, c, d};
          std::array<cv::Vec3d, 4> sides;
          for (size_t k = 0; k < 4; ++k) sides[k] = lines[size_t(four[k])].eq;
          Quad q;
          if (!meet_sides(sides, &q)) continue;
          double covered = 0, around = 0, quad_area = 0;
          bool fits = true;
          for (size_t k = 0; k < 4 && fits; ++k) {
            const cv::Point2d c0 = q[k], c1 = q[(k + 1) % 4];
            const double len = cv::norm(c1 - c0);
            const cv::Point2d u = (c1 - c0) / std::max(len, 1e-9);
            fits = u.dot(lines[size_t(four[k])].way) > 0 && len >= min_run;
            double on = 0;
            for (int i = 0; i < count && fits; ++i) {
              const Run& r = runs[size_t(i)];
              if (r.line != four[k]) continue;
              const double t0 = u.dot(r.from - c0), t1 = u.dot(r.to - c0);
              fits = t0 >= -2 * eps && t1 <= len + 2 * eps;
              on += std::clamp(t1, 0.0, len) - std::clamp(t0, 0.0, len);
            }
            fits = fits && on >= 0.4 * len;
            covered += on;
            around += len;
            quad_area += c0.x * c1.y - c1.x * c0.y;
          }
          if (!fits || covered < 0.7 * around || covered <= best || around < min_perimeter ||
              quad_area / 2 > 1.05 * area)
            continue;
          // The marker is solid to its edge: the contour never goes inside. And a line leaves it: a vertex at
          // least `stub` outside (else the shape is a quad with a corner cut off, or a blob).
          bool outside = false;
          for (int v = 0; v < n && fits; ++v) {
            const cv::Point2d r = contour[size_t(at[size_t(v)])];
            double inside = 1e30;
            for (size_t k = 0; k < 4; ++k)
              inside = std::min(inside, sides[k][0] * r.x + sides[k][1] * r.y - sides[k][2]);
            fits = inside <= eps;
            outside = outside || inside <= -stub;
          }
          if (!fits || !outside) continue;
          best = covered;
          *pick = four;
        }
      }
    }
  return best > 0;
}

// A thin line in a polygon: two of its edges the opposite way (within 15 degrees), on lines at most `width` apart,
// side by side for half the shorter's length: the line's two sides.
bool has_thin_line(const std::array<Run, kMaxRunVertices>& edges, int count, double width) {
  for (int i = 0; i < count; ++i)
    for (int j = i + 1; j < count; ++j) {
      const Run &e = edges[size_t(i)], &f = edges[size_t(j)];
      if (e.u.dot(f.u) > -std::cos(15 * CV_PI / 180)) continue;
      const cv::Point2d mid = (f.from + f.to) / 2 - e.from;
      const double apart = std::abs(e.u.x * mid.y - e.u.y * mid.x);
      if (apart > width && apart > 0.5 * std::min(e.length, f.length)) continue;
      // f's ends along e, from e's start: f runs back, from its start at t0 to its end at t1 < t0.
      const double t0 = e.u.dot(f.from - e.from), t1 = e.u.dot(f.to - e.from);
      if (std::min(e.length, t0) - std::max(0.0, t1) >= 0.5 * std::min(e.length, f.length)) return true;
    }
  return false;
}

// Runs on one line: the same way within 25 degrees, every end of them within 2 eps of the chord between the two
// outermost (a side that a line cut: near the cut, blur bends each piece's end). A line's rough equation is
// that chord's.
// Each run's `line` is set; the lines into `lines`, their number returned.
int join_runs(std::array<Run, kMaxRunVertices>& runs, int count, double eps, std::array<RunLine, kMaxRuns>* lines) {
  std::array<std::pair<cv::Point2d, cv::Point2d>, kMaxRuns> span;
  std::array<unsigned, kMaxRuns> members{};
  int line_count = 0;
  for (int i = 0; i < count; ++i) {
    Run& r = runs[size_t(i)];
    r.line = -1;
    for (int l = 0; l < line_count && r.line < 0; ++l) {
      if ((*lines)[size_t(l)].way.dot(r.u) < std::cos(25 * CV_PI / 180)) continue;
      cv::Point2d a = span[size_t(l)].first, b = span[size_t(l)].second;
      const cv::Point2d was = (*lines)[size_t(l)].way;
      if (was.dot(r.from - a) < 0) a = r.from;
      if (was.dot(r.to - a) > was.dot(b - a)) b = r.to;
      const cv::Point2d u = (b - a) / cv::norm(b - a);
      auto near = [&](const Run& q) {
        return std::abs(u.x * (q.from.y - a.y) - u.y * (q.from.x - a.x)) <= 2 * eps &&
               std::abs(u.x * (q.to.y - a.y) - u.y * (q.to.x - a.x)) <= 2 * eps;
      };
      bool all = near(r);
      for (unsigned m = members[size_t(l)]; m != 0 && all; m &= m - 1) all = near(runs[size_t(std::countr_zero(m))]);
      if (!all) continue;
      r.line = l;
      span[size_t(l)] = {a, b};
      (*lines)[size_t(l)].way = u;
    }
    if (r.line < 0) {
      r.line = line_count++;
      span[size_t(r.line)] = {r.from, r.to};
      (*lines)[size_t(r.line)].way = r.u;
    }
    members[size_t(r.line)] |= 1u << i;
  }
  for (int l = 0; l < line_count; ++l) {
    const cv::Point2d u = (*lines)[size_t(l)].way;
    (*lines)[size_t(l)].eq = line_through(span[size_t(l)].first, u);
    (*lines)[size_t(l)].angle = std::atan2(u.y, u.x);
  }
  return line_count;
}

// A convex quad's perimeter is at most 4.6 times the root of its area unless it is longer than 3:1; a line adds
// length and next to no area.
bool long_for_its_area(const std::vector<cv::Point>& contour, double area, int factor) {
  const double perimeter = contour_length(contour, factor);
  return perimeter * perimeter >= 4.6 * 4.6 * area;
}

// The stretches of a closed outline's mask that hold `value`, in order, each from its first point (an index that
// may run past the mask's end: take it modulo the size) for `length` points; none when the whole mask holds it or
// none of it does.
struct Stretch {
  int first, length;
};
std::vector<Stretch> stretches(const std::vector<char>& mask, char value) {
  const int n = int(mask.size());
  std::vector<Stretch> out;
  int t = 0;
  while (t < n && mask[size_t(t)] == value) ++t;   // from a point without it, so that no stretch wraps past the start
  if (t == n) return out;
  for (int i = t + 1; i <= t + n; ++i) {
    if (mask[size_t(i % n)] != value) continue;
    if (mask[size_t((i - 1) % n)] != value) out.push_back({i, 0});
    ++out.back().length;
  }
  return out;
}

}  // namespace

bool cut_thin_lines(const std::vector<cv::Point>& contour, std::pair<int, int> farthest, const DetectorParams& p,
                    int factor, double shift, Quad* quad) {
  const double area = cv::contourArea(contour);
  if (!long_for_its_area(contour, area, factor)) return false;
  const double eps = 1.5 * factor;
  std::array<int, kMaxRunVertices + 1> at{};
  const int n = approx_polygon(contour, eps, &at, &farthest);
  if (n < 5 || n > kMaxRunVertices) return false;
  const int size = int(contour.size());
  // The edges of 2 eps or more, and the long ones (runs).
  const double min_run = std::max(4.0 * factor, p.min_perimeter_px / 8);
  std::array<Run, kMaxRunVertices> runs, edges;
  int count = 0, edge_count = 0;
  for (int i = 0; i < n; ++i) {
    const int a = at[size_t(i)], b = at[size_t((i + 1) % n)];
    const cv::Point2d from = contour[size_t(a)], to = contour[size_t(b)];
    const double len = cv::norm(to - from);
    if (len < 2 * eps) continue;
    edges[size_t(edge_count++)] = {a, b > a ? b : b + size, len, from, to, (to - from) / len, 0};
    if (len >= min_run) runs[size_t(count++)] = edges[size_t(edge_count - 1)];
  }
  if (count < 4 || !has_thin_line(edges, edge_count, 2 * eps)) return false;
  if (count > kMaxRuns) {
    std::partial_sort(runs.begin(), runs.begin() + kMaxRuns, runs.begin() + count,
                      [](const Run& x, const Run& y) { return x.length > y.length; });
    count = kMaxRuns;
    std::sort(runs.begin(), runs.begin() + count, [](const Run& x, const Run& y) { return x.first < y.first; });
  }
  std::array<RunLine, kMaxRuns> lines;
  const int line_count = join_runs(runs, count, eps, &lines);
  std::array<int, 4> four{};
  if (line_count < 4 || !best_four(contour, area, at, n, runs, count, lines, line_count, eps, 3.0 * factor, min_run,
                                   p.min_perimeter_px, &four))
    return false;
  // The four sides fitted to their runs' points, less an eighth at each end of each run (a corner's rounding) and
  // those more than eps off the rough line (where a line leaves).
  std::array<cv::Vec3d, 4> sides;
  std::vector<cv::Point2d> pts;
  for (size_t k = 0; k < 4; ++k) {
    pts.clear();
    for (int i = 0; i < count; ++i) {
      const Run& r = runs[size_t(i)];
      if (r.line != four[k]) continue;
      const int trim = (r.last - r.first) / 8;
      const cv::Vec3d& rough = lines[size_t(four[k])].eq;
      for (int j = r.first + trim; j <= r.last - trim; ++j) {
        const cv::Point2d q = contour[size_t(j % size)];
        if (std::abs(rough[0] * q.x + rough[1] * q.y - rough[2]) <= eps) pts.push_back(q);
      }
    }
    if (pts.size() < 4) return false;
    sides[k] = fit_side(pts);
  }
  if (!meet_sides(sides, quad)) return false;
  for (auto& c : *quad) c += cv::Point2f(float(shift), float(shift));
  return true;
}

std::vector<std::vector<cv::Point>> split_thin_lines(const std::vector<cv::Point>& contour, int factor,
                                                     const DetectorParams& p) {
  std::vector<std::vector<cv::Point>> parts;
  factor = std::max(factor, 1);
  const double w = p.split_thin_lines_px;
  const int n = int(contour.size());
  // Along the outline, a line's two sides are apart by the rest of the shape, a corner's two sides by a few steps.
  const int apart = int(std::ceil(3 * w / factor)) + 2;
  if (w <= 0 || n < 4 * apart) return parts;
  // Worth splitting: a marker's square with lines at least as long as its perimeter in all (a perimeter of 6 roots
  // of the area or more; a square alone has 4), and not mostly lines (twice the area over the perimeter, a line's
  // width or a square's half side, at least 1.6 w). Most of a cluttered frame's shapes that no quad fits are one or
  // the other; the split costs a grid of the outline's points.
  const double area = cv::contourArea(contour), perimeter = contour_length(contour, factor);
  if (perimeter * perimeter < 36 * area || 2 * area < 1.6 * w * perimeter) return parts;
  // The points in cells w wide, hashed into buckets (twice as many as points; a bucket may hold several cells'),
  // each bucket's points in `order` from start[bucket] on.
  const int c = std::max(1, int(std::ceil(w)));
  const uint32_t mask = std::bit_ceil(uint32_t(2 * n)) - 1;
  auto bucket = [&](int cx, int cy) { return (uint32_t(cx) * 73856093u ^ uint32_t(cy) * 19349663u) & mask; };
  auto cell_of = [&](cv::Point q) { return cv::Point(q.x >= 0 ? q.x / c : -1, q.y >= 0 ? q.y / c : -1); };
  std::vector<int> start(size_t(mask) + 2, 0), order(contour.size());
  for (const cv::Point& q : contour) ++start[bucket(cell_of(q).x, cell_of(q).y) + 1];
  for (size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
  {
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int i = 0; i < n; ++i) {
      const cv::Point at = cell_of(contour[size_t(i)]);
      order[size_t(fill[bucket(at.x, at.y)]++)] = i;
    }
  }
  // Thin: a point within w of another that is `apart` steps away or more, both ways round. A bucket's points are in
  // the outline's order (the counting sort keeps it): one whose first and last are within `apart` of i, without
  // wrapping past the outline's start, holds no partner of i.
  const int w2 = int(std::floor(w * w));
  auto is_thin = [&](int i) {
    const cv::Point q = contour[size_t(i)], at = cell_of(q);
    for (int y = at.y - 1; y <= at.y + 1; ++y)
      for (int x = at.x - 1; x <= at.x + 1; ++x) {
        const uint32_t b = bucket(x, y);
        const int from = start[b], to = start[b + 1];
        if (from == to || (order[size_t(from)] > i - apart && order[size_t(to - 1)] < i + apart)) continue;
        for (int k = from; k < to; ++k) {
          const int j = order[size_t(k)], d = std::abs(i - j);
          const cv::Point e = contour[size_t(j)] - q;
          if (std::min(d, n - d) >= apart && e.dot(e) <= w2) return true;
        }
      }
    return false;
  };
  // Every `every`-th point first, then those between two that differ: a line's sides are thin for far longer.
  std::vector<char> thin(size_t(n), 0);
  const int every = std::max(1, apart / 2);
  for (int i = 0; i < n; i += every) thin[size_t(i)] = is_thin(i);
  for (int i = 0; i < n; i += every) {
    const int next = i + every < n ? i + every : 0;
    for (int k = i + 1; k < std::min(i + every, n); ++k)
      thin[size_t(k)] = thin[size_t(i)] == thin[size_t(next)] ? thin[size_t(i)] : is_thin(k);
  }
  // Where two shapes touch at a corner (a checkerboard's squares) the outline is thin for about 2 w on each side of
  // the pinch; a line's side is thin along its length and w beyond each end. A thin run under 3 w is a pinch, kept:
  // a square split from its checkerboard neighbours had read as a marker.
  const int min_run = int(std::ceil(3 * w / factor));
  for (const Stretch& r : stretches(thin, 1))
    if (r.length < min_run)
      for (int m = 0; m < r.length; ++m) thin[size_t((r.first + m) % n)] = 0;
  // The outline without its thin points: arcs, each from the point after a thin one to the point before the next.
  const std::vector<Stretch> arcs = stretches(thin, 0);
  // Across a line that met the shape its sides are a line's width apart, and the few points beside the line within
  // w of its far side: each arc goes on at the arc whose start is nearest its end, within 3 w and two steps.
  constexpr size_t kMaxArcs = 256;   // clutter
  if (arcs.empty() || arcs.size() > kMaxArcs) return parts;
  const double gap = 3 * w + 2 * factor;
  std::vector<int> next(arcs.size(), -1);
  for (size_t a = 0; a < arcs.size(); ++a) {
    double best = gap * gap;
    const cv::Point end = contour[size_t((arcs[a].first + arcs[a].length - 1) % n)];
    for (size_t b = 0; b < arcs.size(); ++b) {
      const cv::Point e = contour[size_t(arcs[b].first % n)] - end;
      if (double(e.dot(e)) <= best) best = e.dot(e), next[a] = int(b);
    }
  }
  // Each cycle of arcs is a part: their points in turn.
  std::vector<char> used(arcs.size(), 0);
  for (size_t a = 0; a < arcs.size(); ++a) {
    if (used[a]) continue;
    int b = int(a), steps = 0;
    while (next[size_t(b)] >= 0 && next[size_t(b)] != int(a) && !used[size_t(next[size_t(b)])] &&
           ++steps < int(arcs.size()))
      b = next[size_t(b)];
    if (next[size_t(b)] != int(a)) continue;
    std::vector<cv::Point>& part = parts.emplace_back();
    for (b = int(a);; b = next[size_t(b)]) {
      used[size_t(b)] = 1;
      const Stretch& arc = arcs[size_t(b)];
      for (int i = arc.first; i < arc.first + arc.length; ++i) part.push_back(contour[size_t(i % n)]);
      if (next[size_t(b)] == int(a)) break;
    }
  }
  return parts;
}

}  // namespace arwb::stages
