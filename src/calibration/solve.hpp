// The solve: OpenCV's calibrateCameraExtended on the views kept, outlier views dropped and parameters the views
// cannot determine fixed (each said in `notes`), and the quality report a user can act on: the four criteria of
// OpenCV's interactive-calibration app as a checklist, the ROS calibrator's X, Y, size and skew coverage, a
// grid of where the corners fell, and the per-view errors worst first.
#pragma once

#include "base/result.hpp"
#include "calibration/board.hpp"
#include "calibration/calibration_file.hpp"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace arwb {

struct CalibrationView {
  std::string name;                   // "frame 120", "img_004.png": how messages name it
  std::vector<cv::Point2f> corners;   // BoardSpec::object_points' order
  std::vector<int> ids;               // as BoardDetection::ids: empty when corners are all of them, in order
};

struct SolveOptions {
  int min_views = 6;                  // fewer is refused: the solve would fit noise
  double outlier_factor = 3.0;        // a view whose error is over this times the median ...
  double outlier_floor_px = 0.5;      // ... and over this many pixels is dropped (at most a fifth of the views)
};

// ROS's coverage bars: how much of each term's useful range the views span (0..1; 1 is a full bar).
struct CoverageBars {
  double x = 0, y = 0, size = 0, skew = 0;
};

// The bars of views at `poses`, and how many of their corners fell in each cell of an 8x6 grid over an image of
// `size`: the report's coverage, which the Calibrate workspace also fills live as views are kept.
CoverageBars coverage_bars(const std::vector<ViewPose>& poses);
cv::Mat1i corner_grid(const std::vector<CalibrationView>& views, cv::Size size);

struct Check {
  std::string name;     // "enough views", "RMS reprojection error", "95 % intervals under 5 %", "square pixels",
                        // "image coverage"
  bool ok = false;
  std::string detail;   // the figures behind it: "14 views (need 10)"
};

struct QualityReport {
  std::vector<Check> checklist;
  CoverageBars bars;
  cv::Mat1i grid;                      // corners per cell of an 8x6 grid over the image
  double grid_coverage = 0;            // share of the grid's cells holding a corner
  std::vector<std::pair<std::string, double>> worst_first;   // per-view RMS error, px
  // Cross-validation as mrcal does it: the views split in two halves (alternately), each calibrated alone; every
  // cell of a grid over the image is unprojected to a ray by one half's calibration and projected by the other's.
  // The distance between the two, px, per cell (rows x cols of the grid, CV_32F): small where the result can be
  // trusted, large where the views did not pin the lens down. Empty when there are too few views to split.
  cv::Mat1f cross_validation;
  double cross_validation_max_px = 0;   // the largest cell
  double cross_validation_median_px = 0;
  bool good() const;                   // every check passes
};

struct Solution {
  Calibration calibration;
  double rms = 0;                         // over the views used, px
  std::vector<std::string> view_names;    // the views used, in input order
  std::vector<double> per_view_errors;    // theirs, px
  std::vector<double> std_intrinsics;     // fx fy cx cy, one standard deviation (0 for a fixed one)
  bool fixed_principal_point = false;     // cx, cy fixed at the image's centre (notes say why)
  bool fixed_k3 = false;                  // k3 fixed at 0
  std::vector<double> std_distortion;     // as calibration.distortion
  std::vector<std::string> notes;         // "k3 fixed at 0: ...", "dropped frame 12 (2.31 px, median 0.22 px)"
  QualityReport report;
  // The benchmark: OpenCV's calibrateCamera with its default flags on all the views given (none dropped, nothing
  // fixed), to print beside ours.
  Calibration opencv_defaults;
  double opencv_defaults_rms = 0;
  std::string opencv_defaults_call;       // "calibrateCamera", or "calibrateCameraCharuco" for a ChArUco board
};

// Calibrates from `views` of `board` in frames of `size`. Fails with one line: too few views ("4 views; at least 6
// are needed: move the board to more places"), or OpenCV's solve failing or giving values that are not finite.
Result<Solution> solve_calibration(const std::vector<CalibrationView>& views, const BoardSpec& board, cv::Size size,
                                   const SolveOptions& opt = {});

// The report as text lines for the terminal, and everything as one JSON object (for --json).
std::string solution_text(const Solution& s);
std::string solution_json(const Solution& s, const BoardSpec& board);

}  // namespace arwb
