#include "calibration/coach.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace arwb {
namespace {

// The empty share of the grid's cells in the part named, and the part's name.
struct Part {
  const char* name;
  int r0, r1, c0, c1;   // rows [r0, r1), columns [c0, c1) of an 8x6 grid, scaled to the grid given
};

double empty_share(const cv::Mat1i& grid, const Part& p) {
  const int rows = grid.rows, cols = grid.cols;
  const int r0 = p.r0 * rows / 6, r1 = std::max(r0 + 1, p.r1 * rows / 6);
  const int c0 = p.c0 * cols / 8, c1 = std::max(c0 + 1, p.c1 * cols / 8);
  int empty = 0, all = 0;
  for (int r = r0; r < r1 && r < rows; ++r)
    for (int c = c0; c < c1 && c < cols; ++c) ++all, empty += grid(r, c) == 0;
  return all ? double(empty) / all : 0.0;
}

constexpr Part kLeft{"the left edge", 0, 6, 0, 2}, kRight{"the right edge", 0, 6, 6, 8};
constexpr Part kTop{"the top", 0, 2, 0, 8}, kBottom{"the bottom", 4, 6, 0, 8};
constexpr Part kCorners[] = {{"the top-left corner", 0, 2, 0, 2}, {"the top-right corner", 0, 2, 6, 8},
                             {"the bottom-left corner", 4, 6, 0, 2}, {"the bottom-right corner", 4, 6, 6, 8}};

std::string percent(double v) { return std::to_string(int(std::lround(100 * std::clamp(v, 0.0, 1.0)))) + " %"; }

}  // namespace

std::string coverage_advice(const CoverageBars& bars, const cv::Mat1i& grid, int views) {
  if (views <= 0) return "Show the whole board to the camera, then move it to a new place for each view.";
  const bool has_grid = !grid.empty() && grid.rows > 0 && grid.cols > 0;
  const std::array<std::pair<char, double>, 4> all = {{{'x', bars.x}, {'y', bars.y}, {'s', bars.size}, {'k', bars.skew}}};
  const auto shortest = std::min_element(all.begin(), all.end(), [](auto& a, auto& b) { return a.second < b.second; });
  if (shortest->second < kShortBar) {
    switch (shortest->first) {
      case 'x': {
        const Part& side = !has_grid || empty_share(grid, kLeft) >= empty_share(grid, kRight) ? kLeft : kRight;
        return "X is at " + percent(bars.x) + ": cover " + side.name + " of the image, the board near it.";
      }
      case 'y': {
        const Part& side = !has_grid || empty_share(grid, kTop) >= empty_share(grid, kBottom) ? kTop : kBottom;
        return "Y is at " + percent(bars.y) + ": cover " + side.name + " of the image, the board near it.";
      }
      case 's':
        return "Size is at " + percent(bars.size) + ": bring the board nearer, so that it fills most of the image, "
               "and take it farther away.";
      default:
        return "Skew is at " + percent(bars.skew) + ": tilt the board more, to the left and right and up and down.";
    }
  }
  if (has_grid) {
    const Part* worst = nullptr;
    double most = 0;
    for (const Part& p : kCorners)
      if (const double e = empty_share(grid, p); e > most) most = e, worst = &p;
    for (const Part* p : {&kLeft, &kRight, &kTop, &kBottom})
      if (const double e = empty_share(grid, *p); e >= most && e > 0.5) most = e, worst = p;
    if (worst && most >= 0.5)
      return std::string("No corners in ") + worst->name + " yet: cover it, where the lens bends the most.";
  }
  return "The coverage is complete: more views only replace the worst ones.";
}

}  // namespace arwb
