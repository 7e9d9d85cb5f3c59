// What the Calibrate workspace tells the person holding the board next: the one thing the views kept lack most,
// named ("cover the top of the image", "tilt the board more"), from the coverage bars and the grid of corners.
#pragma once

#include "calibration/solve.hpp"

#include <opencv2/core.hpp>

#include <string>

namespace arwb {

// A bar under this is short (the Calibrate workspace draws it in the poor colour).
inline constexpr double kShortBar = 0.5;

// One sentence. With no view yet, where to start; then the shortest bar under kShortBar, its direction read from
// `grid` (corner_grid's 8x6 counts: an X bar short of corners on the left says "the left"); when no bar is short,
// the largest empty part of the grid; when nothing is missing, that the coverage is complete.
std::string coverage_advice(const CoverageBars& bars, const cv::Mat1i& grid, int views);

}  // namespace arwb
