#include "calibration/solve.hpp"

#include "base/decimals.hpp"
#include "calibration/cross_validation.hpp"
#include "base/json_text.hpp"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace arwb {

namespace {

constexpr int kEnoughViews = 10;           // the interactive-calibration app's minimum
constexpr double kMaxRmsPx = 1.0;
constexpr double kMaxRelativeInterval = 0.05;
constexpr double kMinGridCoverage = 0.75;
constexpr double kMaxCentreInterval = 0.025;  // of the image's side: wider, and the principal point is fixed
constexpr double kMaxPixelAspectError = 0.05;  // fy/fx further from 1: a squashed picture, not a camera
constexpr int kGridCols = 8, kGridRows = 6;
// ROS's useful range of each term: a bar is full when the views span this much of it.
constexpr double kRangeX = 0.7, kRangeY = 0.7, kRangeSize = 0.4, kRangeSkew = 0.5;

std::string num(double v, int decimals = 2) { return fixed_text(v, decimals); }

struct Run {
  cv::Mat K, D, std_intrinsics;
  std::vector<double> per_view;
  double rms = 0;
};

Result<Run> run_opencv(const std::vector<CalibrationView>& views, const BoardSpec& board, cv::Size size, int flags,
                       const cv::Mat& K0) {
  Run r;
  r.K = K0.clone();
  r.D = cv::Mat::zeros(1, 5, CV_64F);
  cv::Mat rvecs, tvecs, std_extrinsics, errors;
  if (board.kind == BoardKind::charuco) {
    // OpenCV's ChArUco variant: each view's corners with their ids, the object points taken from the board (its
    // origin is the board's outer corner, one square from ours: the poses differ, the camera does not).
    const cv::Ptr<cv::aruco::CharucoBoard> cb = opencv_charuco_board(board);
    if (!cb) return fail("the ChArUco board's dictionary " + board.dictionary + " is not one of OpenCV's");
    std::vector<cv::Mat> corners, ids;
    for (const CalibrationView& v : views) {
      std::vector<int> vi = v.ids;
      if (vi.empty())
        for (int i = 0; i < int(v.corners.size()); ++i) vi.push_back(i);
      corners.push_back(cv::Mat(v.corners, true));
      ids.push_back(cv::Mat(vi, true));
    }
    try {
      r.rms = cv::aruco::calibrateCameraCharuco(corners, ids, cb, size, r.K, r.D, rvecs, tvecs, r.std_intrinsics,
                                                std_extrinsics, errors, flags);
    } catch (const cv::Exception& e) {
      return fail(std::string("OpenCV's calibrateCameraCharuco failed (") + e.err + ")");
    }
  } else {
    std::vector<std::vector<cv::Point3f>> obj(views.size(), board.object_points());
    std::vector<std::vector<cv::Point2f>> img;
    for (const CalibrationView& v : views) img.push_back(v.corners);
    try {
      // The overload with standard deviations and per-view errors (calibrateCameraExtended in the Python binding).
      r.rms = cv::calibrateCamera(obj, img, size, r.K, r.D, rvecs, tvecs, r.std_intrinsics, std_extrinsics,
                                  errors, flags);
    } catch (const cv::Exception& e) {
      return fail(std::string("OpenCV's calibrateCamera failed (") + e.err + ")");
    }
  }
  errors.reshape(1, 1).convertTo(r.per_view, CV_64F);
  bool finite = std::isfinite(r.rms) && cv::checkRange(r.K) && cv::checkRange(r.D);
  if (!finite || r.K.at<double>(0, 0) <= 0 || r.K.at<double>(1, 1) <= 0)
    return fail("the solve gave no usable camera (values not finite or focal length not positive): the views may "
                "not show the board from enough directions");
  return r;
}

// Where the largest cell of a heatmap over the image is, in words: "the top-left corner", "the centre".
std::string where_worst(const cv::Mat1f& m) {
  cv::Point at(0, 0);
  float worst = -1;
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c)
      if (std::isfinite(m(r, c)) && m(r, c) > worst) worst = m(r, c), at = {c, r};
  const int col = 3 * at.x / std::max(m.cols, 1), row = 3 * at.y / std::max(m.rows, 1);
  static const char* rows[3] = {"top", "middle", "bottom"};
  static const char* cols[3] = {"left", "centre", "right"};
  if (row == 1 && col == 1) return "the centre";
  if (row == 1) return std::string("the ") + cols[col] + " edge";
  if (col == 1) return std::string("the ") + rows[row] + " edge";
  return std::string("the ") + rows[row] + "-" + cols[col] + " corner";
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

}  // namespace

CoverageBars coverage_bars(const std::vector<ViewPose>& poses) {
  const auto bar = [&](double ViewPose::*term, double range) {
    if (poses.empty()) return 0.0;
    double lo = 1, hi = 0;
    for (const ViewPose& p : poses) lo = std::min(lo, p.*term), hi = std::max(hi, p.*term);
    return std::clamp((hi - lo) / range, 0.0, 1.0);
  };
  return {bar(&ViewPose::x, kRangeX), bar(&ViewPose::y, kRangeY), bar(&ViewPose::size, kRangeSize),
          bar(&ViewPose::skew, kRangeSkew)};
}

cv::Mat1i corner_grid(const std::vector<CalibrationView>& views, cv::Size size) {
  cv::Mat1i grid(kGridRows, kGridCols, 0);
  if (size.area() <= 0) return grid;
  for (const CalibrationView& v : views)
    for (const cv::Point2f& p : v.corners)
      ++grid(std::clamp(int(double(p.y) * kGridRows / size.height), 0, kGridRows - 1),
             std::clamp(int(double(p.x) * kGridCols / size.width), 0, kGridCols - 1));
  return grid;
}

bool QualityReport::good() const {
  return std::all_of(checklist.begin(), checklist.end(), [](const Check& c) { return c.ok; });
}

// What the views can determine, measured by the free solve's own uncertainty rather than guessed from where the
// board was (a board spanning a third of the width pinned the centre within a pixel, where fixing it at the
// image's middle put it 7.6 px off): the principal point is fixed at the image's centre when its 95 % interval is
// wider than kMaxCentreInterval of the image (a lens's centre is nearer the middle than that), and k3 at 0 when
// its interval holds 0 (the views cannot tell it from none, and it would trade against k1 and k2). The flags to
// add, each with its note.
int fixed_by_measure(const std::vector<CalibrationView>& views, const BoardSpec& board, cv::Size size,
                     const cv::Mat& K0, std::vector<std::string>& notes) {
  const Result<Run> free = run_opencv(views, board, size, cv::CALIB_USE_INTRINSIC_GUESS, K0);
  if (!free) return cv::CALIB_FIX_K3;   // the solve proper says why, if it fails too
  const cv::Mat sd = free->std_intrinsics.reshape(1, 1);
  int flags = 0;
  const double cx95 = 1.96 * sd.at<double>(0, 2), cy95 = 1.96 * sd.at<double>(0, 3);
  if (cx95 > kMaxCentreInterval * size.width || cy95 > kMaxCentreInterval * size.height) {
    flags |= cv::CALIB_FIX_PRINCIPAL_POINT;
    notes.push_back("principal point fixed at the image centre: the views leave it uncertain (cx ± " + num(cx95, 1) +
                    " px, cy ± " + num(cy95, 1) + " px at 95 %, more than " + num(100 * kMaxCentreInterval, 1) +
                    " % of the image); move the board to the image's edges and tilt it");
  }
  const double k3 = free->D.at<double>(0, 4), k3_95 = 1.96 * sd.at<double>(0, 8);
  if (!(std::abs(k3) > k3_95)) {
    flags |= cv::CALIB_FIX_K3;
    notes.push_back("k3 fixed at 0: the views cannot tell it from 0 (" + num(k3, 3) + " ± " + num(k3_95, 3) +
                    " at 95 %)");
  }
  return flags;
}

Result<Solution> solve_calibration(const std::vector<CalibrationView>& all, const BoardSpec& board, cv::Size size,
                                   const SolveOptions& opt) {
  if (int(all.size()) < opt.min_views)
    return fail(std::to_string(all.size()) + (all.size() == 1 ? " view" : " views") + "; at least " + std::to_string(opt.min_views) +
                " are needed: show the board in more places, tilted several ways");
  Solution s;
  // What the views can determine, decided before the solve from where the board was.
  std::vector<ViewPose> poses;
  for (const CalibrationView& v : all) poses.push_back(view_pose(v.corners, v.ids, board, size));
  QualityReport& rep = s.report;
  rep.bars = coverage_bars(poses);
  const cv::Mat1i grid = corner_grid(all, size);
  rep.grid = grid;
  rep.grid_coverage = double(cv::countNonZero(grid)) / double(grid.total());

  int flags = cv::CALIB_USE_INTRINSIC_GUESS;
  cv::Mat K0 = (cv::Mat_<double>(3, 3) << size.width, 0, (size.width - 1) / 2.0, 0, size.width,
                (size.height - 1) / 2.0, 0, 0, 1);
  flags |= fixed_by_measure(all, board, size, K0, s.notes);
  s.fixed_principal_point = flags & cv::CALIB_FIX_PRINCIPAL_POINT;
  s.fixed_k3 = flags & cv::CALIB_FIX_K3;
  std::vector<CalibrationView> views = all;
  Result<Run> run = run_opencv(views, board, size, flags, K0);
  if (!run) return fail(run.error());
  // Outliers: a view far worse than the others is a misdetection or a moving board; dropped, then solved again.
  const double med = median(run->per_view);
  std::vector<size_t> order(views.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return run->per_view[a] > run->per_view[b]; });
  std::vector<bool> drop(views.size(), false);
  const size_t max_drop = views.size() / 5;
  size_t dropped = 0;
  for (size_t i : order) {
    const double e = run->per_view[i];
    if (dropped >= max_drop || int(views.size() - dropped) <= opt.min_views) break;
    if (e > opt.outlier_factor * med && e > opt.outlier_floor_px) {
      drop[i] = true;
      ++dropped;
      s.notes.push_back("dropped " + views[i].name + " (error " + num(e) + " px, median " + num(med) + " px)");
    }
  }
  if (dropped > 0) {
    std::vector<CalibrationView> kept;
    for (size_t i = 0; i < views.size(); ++i)
      if (!drop[i]) kept.push_back(views[i]);
    views = std::move(kept);
    run = run_opencv(views, board, size, flags, K0);
    if (!run) return fail(run.error());
  }

  s.calibration.camera_matrix = cv::Matx33d(run->K);
  s.calibration.distortion.assign(run->D.begin<double>(), run->D.end<double>());
  s.calibration.image_size = size;
  s.rms = run->rms;
  s.per_view_errors = run->per_view;
  for (const CalibrationView& v : views) s.view_names.push_back(v.name);
  const cv::Mat sd = run->std_intrinsics.reshape(1, 1);
  for (int i = 0; i < 4; ++i) s.std_intrinsics.push_back(sd.at<double>(0, i));
  for (size_t i = 0; i < s.calibration.distortion.size(); ++i) s.std_distortion.push_back(sd.at<double>(0, int(4 + i)));

  // The interactive-calibration app's four criteria.
  rep.checklist.push_back({"enough views", int(views.size()) >= kEnoughViews,
                           std::to_string(views.size()) + " views (need " + std::to_string(kEnoughViews) + ")"});
  rep.checklist.push_back({"RMS reprojection error", s.rms <= kMaxRmsPx,
                           num(s.rms, 3) + " px (need at most " + num(kMaxRmsPx, 1) + " px)"});
  const double values[4] = {s.calibration.camera_matrix(0, 0), s.calibration.camera_matrix(1, 1),
                            s.calibration.camera_matrix(0, 2), s.calibration.camera_matrix(1, 2)};
  const char* names[4] = {"fx", "fy", "cx", "cy"};
  std::string detail;
  bool intervals_ok = true;
  for (int i = 0; i < 4; ++i) {
    if (i >= 2 && s.fixed_principal_point) {   // a value fixed has no interval, not one of 0
      detail += std::string(", ") + names[i] + " fixed";
      continue;
    }
    const double rel = 1.96 * s.std_intrinsics[size_t(i)] / std::abs(values[i]);
    intervals_ok = intervals_ok && rel < kMaxRelativeInterval;
    detail += std::string(i ? ", " : "") + names[i] + " " + num(100 * rel, 2) + " %";
  }
  rep.checklist.push_back({"95 % intervals under 5 %", intervals_ok, detail});
  // Square pixels: a picture resized without keeping its aspect calibrates as a camera with fy/fx far from 1, and
  // every check above would still pass.
  const double aspect = values[1] / values[0];
  rep.checklist.push_back({"square pixels", std::abs(aspect - 1) <= kMaxPixelAspectError,
                           "fy/fx " + num(aspect, 3) + (std::abs(aspect - 1) <= kMaxPixelAspectError
                                                             ? std::string(" (need 1 ± ") + num(kMaxPixelAspectError, 2) + ")"
                                                             : std::string(": the pictures are squashed or stretched "
                                                                           "(resized without keeping their aspect?)"))});
  rep.checklist.push_back({"image coverage", rep.grid_coverage >= kMinGridCoverage,
                           num(100 * rep.grid_coverage, 0) + " % of an 8x6 grid holds corners (need " +
                               num(100 * kMinGridCoverage, 0) + " %)"});
  // The benchmark line: OpenCV's defaults on every view given (for ChArUco, its calibrateCameraCharuco's).
  if (Result<Run> plain = run_opencv(all, board, size, 0, K0)) {
    s.opencv_defaults.camera_matrix = cv::Matx33d(plain->K);
    s.opencv_defaults.distortion.assign(plain->D.begin<double>(), plain->D.end<double>());
    s.opencv_defaults.image_size = size;
    s.opencv_defaults_rms = plain->rms;
    s.opencv_defaults_call = board.kind == BoardKind::charuco ? "calibrateCameraCharuco" : "calibrateCamera";
  }
  // Cross-validation: the views used, split alternately (so that each half spans the session), solved apart with
  // the same flags, and compared over the image.
  if (views.size() >= 2 * size_t(opt.min_views)) {
    std::vector<CalibrationView> half[2];
    for (size_t i = 0; i < views.size(); ++i) half[i % 2].push_back(views[i]);
    Result<Run> a = run_opencv(half[0], board, size, flags, K0), b = run_opencv(half[1], board, size, flags, K0);
    if (a && b) {
      const auto as_calibration = [&](const Run& r) {
        Calibration c;
        c.camera_matrix = cv::Matx33d(r.K);
        c.distortion.assign(r.D.begin<double>(), r.D.end<double>());
        c.image_size = size;
        return c;
      };
      const ProjectionDiff d = projection_diff(as_calibration(*a), as_calibration(*b), size);
      rep.cross_validation = d.diff;
      rep.cross_validation_max_px = d.max_px;
      rep.cross_validation_median_px = d.median_px;
    }
  }
  for (size_t i = 0; i < views.size(); ++i) rep.worst_first.emplace_back(views[i].name, s.per_view_errors[i]);
  std::stable_sort(rep.worst_first.begin(), rep.worst_first.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  return s;
}

std::string solution_text(const Solution& s) {
  const cv::Matx33d& K = s.calibration.camera_matrix;
  std::string t;
  // A value fixed is said to be, not given an interval of 0.
  const auto sd = [](bool fixed, double v, int decimals) { return fixed ? std::string(" (fixed)") : " ± " + num(v, decimals); };
  t += "fx " + num(K(0, 0)) + sd(false, s.std_intrinsics[0], 2) + "  fy " + num(K(1, 1)) +
       sd(false, s.std_intrinsics[1], 2) + "  cx " + num(K(0, 2)) + sd(s.fixed_principal_point, s.std_intrinsics[2], 2) +
       "  cy " + num(K(1, 2)) + sd(s.fixed_principal_point, s.std_intrinsics[3], 2) + " px\n";
  const char* dn[5] = {"k1", "k2", "p1", "p2", "k3"};
  for (size_t i = 0; i < s.calibration.distortion.size() && i < 5; ++i)
    t += std::string(i ? "  " : "") + dn[i] + " " + num(s.calibration.distortion[i], 4) +
         sd(i == 4 && s.fixed_k3, s.std_distortion[i], 4);
  t += "\nRMS reprojection error " + num(s.rms, 3) + " px over " + std::to_string(s.view_names.size()) + " views\n";
  if (!s.opencv_defaults.distortion.empty()) {
    const cv::Matx33d& O = s.opencv_defaults.camera_matrix;
    t += "OpenCV " + s.opencv_defaults_call + ", default flags, all views: fx " + num(O(0, 0)) + "  fy " + num(O(1, 1)) + "  cx " +
         num(O(0, 2)) + "  cy " + num(O(1, 2)) + "  k1 " + num(s.opencv_defaults.distortion[0], 4) + "  k2 " +
         num(s.opencv_defaults.distortion[1], 4) + "  RMS " + num(s.opencv_defaults_rms, 3) + " px\n";
  }
  for (const std::string& n : s.notes) t += "note: " + n + "\n";
  for (const Check& c : s.report.checklist) t += std::string(c.ok ? "[ok]   " : "[poor] ") + c.name + ": " + c.detail + "\n";
  const CoverageBars& b = s.report.bars;
  t += "coverage: X " + num(100 * b.x, 0) + " %  Y " + num(100 * b.y, 0) + " %  size " + num(100 * b.size, 0) +
       " %  skew " + num(100 * b.skew, 0) + " %\n";
  if (s.report.cross_validation.empty())
    t += "cross-validation: needs twice the fewest views a solve takes (" + std::to_string(s.view_names.size()) +
         " used)\n";
  else
    t += "cross-validation (two halves of the views solved apart): they agree within " +
         num(s.report.cross_validation_median_px) + " px at the median cell, " +
         num(s.report.cross_validation_max_px) + " px at worst (" + where_worst(s.report.cross_validation) + ")\n";
  t += "worst views:";
  for (size_t i = 0; i < s.report.worst_first.size() && i < 5; ++i)
    t += std::string(i ? "," : "") + " " + s.report.worst_first[i].first + " " + num(s.report.worst_first[i].second, 3) +
         " px";
  t += "\n";
  return t;
}

std::string solution_json(const Solution& s, const BoardSpec& board) {
  using nlohmann::json;
  const cv::Matx33d& K = s.calibration.camera_matrix;
  json j;
  j["image_width"] = s.calibration.image_size.width;
  j["image_height"] = s.calibration.image_size.height;
  j["board"] = board.describe();
  j["camera_matrix"] = {{K(0, 0), K(0, 1), K(0, 2)}, {K(1, 0), K(1, 1), K(1, 2)}, {K(2, 0), K(2, 1), K(2, 2)}};
  j["fx"] = K(0, 0);
  j["fy"] = K(1, 1);
  j["cx"] = K(0, 2);
  j["cy"] = K(1, 2);
  j["distortion_coefficients"] = s.calibration.distortion;
  j["std_dev_intrinsics_fx_fy_cx_cy"] = s.std_intrinsics;
  j["std_dev_distortion"] = s.std_distortion;
  j["fixed"] = json::array();   // the values the solve did not estimate (their std_dev is 0)
  if (s.fixed_principal_point) j["fixed"].push_back("cx"), j["fixed"].push_back("cy");
  if (s.fixed_k3) j["fixed"].push_back("k3");
  j["avg_reprojection_error"] = s.rms;
  j["view_count"] = s.view_names.size();
  if (!s.opencv_defaults.distortion.empty()) {
    const cv::Matx33d& O = s.opencv_defaults.camera_matrix;
    j["opencv_defaults"] = {{"call", s.opencv_defaults_call}, {"fx", O(0, 0)}, {"fy", O(1, 1)}, {"cx", O(0, 2)}, {"cy", O(1, 2)},
                            {"distortion_coefficients", s.opencv_defaults.distortion},
                            {"avg_reprojection_error", s.opencv_defaults_rms}};
  }
  j["notes"] = s.notes;
  json checks = json::array();
  for (const Check& c : s.report.checklist) checks.push_back({{"name", c.name}, {"ok", c.ok}, {"detail", c.detail}});
  json worst = json::array();
  for (const auto& [name, e] : s.report.worst_first) worst.push_back({{"view", name}, {"error_px", e}});
  json grid = json::array();
  for (int r = 0; r < s.report.grid.rows; ++r) {
    json row = json::array();
    for (int c = 0; c < s.report.grid.cols; ++c) row.push_back(s.report.grid(r, c));
    grid.push_back(row);
  }
  j["report"] = {{"good", s.report.good()},
                 {"checklist", checks},
                 {"coverage", {{"x", s.report.bars.x}, {"y", s.report.bars.y}, {"size", s.report.bars.size},
                               {"skew", s.report.bars.skew}}},
                 {"grid_coverage", s.report.grid_coverage},
                 {"corner_grid_8x6", grid},
                 {"per_view_errors_worst_first", worst}};
  if (!s.report.cross_validation.empty()) {
    json cv_grid = json::array();
    for (int r = 0; r < s.report.cross_validation.rows; ++r) {
      json row = json::array();
      for (int c = 0; c < s.report.cross_validation.cols; ++c) {
        const float v = s.report.cross_validation(r, c);
        row.push_back(std::isfinite(v) ? json(v) : json(nullptr));
      }
      cv_grid.push_back(row);
    }
    j["report"]["cross_validation"] = {{"median_px", s.report.cross_validation_median_px},
                                       {"max_px", s.report.cross_validation_max_px},
                                       {"grid_px", cv_grid}};
  }
  return json_text(j);
}

}  // namespace arwb
