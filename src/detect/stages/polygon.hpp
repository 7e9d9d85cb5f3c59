// quad_fit's polygon approximation, for quad_fit and its cut_thin_lines. Internal to the stages.
#pragma once

#include "detect/pipeline.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace arwb::stages {

// quad_fit's polygon: the Douglas-Peucker approximation of a closed contour within `epsilon` px as cv::approxPolyDP
// makes it, as indices into the contour in contour order. The first split is at an approximately farthest pair
// (from the first point, the farthest point three times over); each piece is split at its point farthest from its
// chord while that is more than epsilon away; at the end a vertex within epsilon / sqrt 2 of the line through its
// neighbours, and between them, is dropped. The vertices start at the first of the farthest pair. It gives up once
// there are more than Cap - 1 (Cap when it does): a shape of many corners costs only its first splits. `pair`, when
// given, keeps the farthest pair for the contour's next polygon (at -1 until found).
template <size_t Cap>
int approx_polygon(const std::vector<cv::Point>& c, double epsilon, std::array<int, Cap>* out,
                   std::pair<int, int>* pair = nullptr) {
  constexpr int kMax = int(Cap) - 1;
  const int n = int(c.size());
  if (n < 3) return n;
  auto farthest_from = [&](int from) { return farthest_point(c.data(), n, c[size_t(from)], {}, false).at; };
  std::pair<int, int> own{-1, -1};
  if (!pair) pair = &own;
  if (pair->first < 0) {
    const int start = farthest_from(farthest_from(0));
    *pair = {start, farthest_from(start)};
  }
  const int a = pair->first, b = pair->second;
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
  std::array<int, Cap> split{};
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
    if (count == kMax + 1 || top + 2 > int(stack.size())) return kMax + 1;
    split[size_t(count++)] = at % n;
    stack[size_t(top++)] = {at, to};
    stack[size_t(top++)] = {from, at};
  }
  std::sort(split.begin(), split.begin() + count);
  // The last pass: drop a vertex nearly on the line through its neighbours and between them.
  int kept = 0;
  std::array<int, Cap> v{};
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

}  // namespace arwb::stages
