// Calibration against a known camera: synthetic chessboard views through a lens with barrel distortion, found by
// our board detection and solved by solve_calibration, must give back the camera (fx, fy within 0.5 %, cx, cy
// within 2 px, k1 within 0.02); the choice of views refuses what it should, with its reason.
#include "calibration/board.hpp"
#include "calibration/solve.hpp"
#include "synth/chessboard_view.hpp"
#include "support/sanitizers.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <cstdio>

namespace arwb {
namespace {

const BoardSpec kBoard{};   // the paper's: 9x6 inner corners, 25 mm

struct Views {
  SynthCamera camera;
  std::vector<CalibrationView> views;
  double mean_corner_error = 0;   // detected against true corners, px
};

Views make_views(int count, double noise, unsigned seed = 7) {
  Views v;
  const SynthChessboard board{kBoard.cols, kBoard.rows, kBoard.square_mm / 1000, 1.0};
  static const ChessboardRenderer renderer(v.camera, board);   // one per binary: it undistorts every pixel
  double err = 0;
  int n = 0;
  const auto poses = chessboard_poses(v.camera, board, count, seed);
  for (size_t i = 0; i < poses.size(); ++i) {
    const ChessboardView view = renderer.render(poses[i].first, poses[i].second, 0.6, noise, unsigned(seed * 1000 + i + 1));
    const BoardDetection d = detect_chessboard(view.image, kBoard);
    if (!d.found) continue;
    // The board may be found turned half a turn: compare with the truth in whichever order matches.
    double fwd = 0, back = 0;
    for (size_t k = 0; k < d.corners.size(); ++k) {
      fwd += cv::norm(d.corners[k] - view.corners[k]);
      back += cv::norm(d.corners[k] - view.corners[d.corners.size() - 1 - k]);
    }
    err += std::min(fwd, back) / double(d.corners.size());
    ++n;
    v.views.push_back({"view " + std::to_string(i), d.corners, {}});
  }
  v.mean_corner_error = n ? err / n : 1e9;
  return v;
}

TEST(CalibrationSolve, FindsTheKnownCameraFromSyntheticChessboardViews) {
  const Views v = make_views(20, 2.0);
  ASSERT_GE(v.views.size(), 18u) << "the board was not found in most views";
  EXPECT_LT(v.mean_corner_error, 0.15) << "detected corners are not where the renderer put them";
  const Result<Solution> s = solve_calibration(v.views, kBoard, v.camera.size);
  ASSERT_TRUE(s.ok()) << s.error();
  const cv::Matx33d& K = s->calibration.camera_matrix;
  const cv::Matx33d& T = v.camera.camera_matrix;
  EXPECT_NEAR(K(0, 0), T(0, 0), 0.005 * T(0, 0));
  EXPECT_NEAR(K(1, 1), T(1, 1), 0.005 * T(1, 1));
  EXPECT_NEAR(K(0, 2), T(0, 2), 2.0);
  EXPECT_NEAR(K(1, 2), T(1, 2), 2.0);
  EXPECT_NEAR(s->calibration.distortion[0], v.camera.distortion[0], 0.02);
  EXPECT_LT(s->rms, 0.5);

  // The benchmark line: OpenCV's calibrateCamera with its defaults on the same views.
  std::vector<std::vector<cv::Point3f>> obj(v.views.size(), kBoard.object_points());
  std::vector<std::vector<cv::Point2f>> img;
  for (const CalibrationView& cv_view : v.views) img.push_back(cv_view.corners);
  cv::Mat K2, D2;
  std::vector<cv::Mat> rv, tv;
  const double rms2 = cv::calibrateCamera(obj, img, v.camera.size, K2, D2, rv, tv);
  std::printf("truth   fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f k2 %.4f\n", T(0, 0), T(1, 1), T(0, 2), T(1, 2),
              v.camera.distortion[0], v.camera.distortion[1]);
  std::printf("ours    fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f k2 %.4f rms %.4f px, %zu views, corners %.3f px off\n",
              K(0, 0), K(1, 1), K(0, 2), K(1, 2), s->calibration.distortion[0], s->calibration.distortion[1], s->rms,
              s->view_names.size(), v.mean_corner_error);
  std::printf("opencv  fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f k2 %.4f rms %.4f px (calibrateCamera, default flags)\n",
              K2.at<double>(0, 0), K2.at<double>(1, 1), K2.at<double>(0, 2), K2.at<double>(1, 2), D2.at<double>(0),
              D2.at<double>(1), rms2);
  for (const std::string& n : s->notes) std::printf("note: %s\n", n.c_str());
  EXPECT_LE(s->rms, rms2 + 0.01) << "ours must not be worse than OpenCV's defaults";
  // The benchmark the report carries is that same run.
  EXPECT_NEAR(s->opencv_defaults.camera_matrix(0, 0), K2.at<double>(0, 0), 1e-6);
  EXPECT_NEAR(s->opencv_defaults_rms, rms2, 1e-9);
}

// The 95 % intervals are honest: over seeds (other poses, other noise), the true camera lies within them about 95
// times in 100, and they are not made honest by being wide. findChessboardCornersSB's own corners, pulled toward
// the image's centre on tilted views, put fx and fy outside their intervals in 5 seeds of 10.
TEST(CalibrationSolve, TheTruthLiesWithinThe95PercentIntervalsInMostSeeds) {
  ARWB_SKIP_WHEN_SANITIZED("ten seeds of what FindsTheKnownCameraFromSyntheticChessboardViews runs once");
  constexpr int kSeeds = 10;
  const char* names[5] = {"fx", "fy", "cx", "cy", "k1"};
  int inside[5] = {};
  for (unsigned seed = 1; seed <= kSeeds; ++seed) {
    const Views v = make_views(16, 2.0, 100 + seed);
    const Result<Solution> s = solve_calibration(v.views, kBoard, v.camera.size);
    ASSERT_TRUE(s.ok()) << s.error();
    ASSERT_FALSE(s->fixed_principal_point) << "these views determine the principal point";
    const cv::Matx33d& K = s->calibration.camera_matrix;
    const cv::Matx33d& T = v.camera.camera_matrix;
    const double got[5] = {K(0, 0), K(1, 1), K(0, 2), K(1, 2), s->calibration.distortion[0]};
    const double truth[5] = {T(0, 0), T(1, 1), T(0, 2), T(1, 2), v.camera.distortion[0]};
    const double sd[5] = {s->std_intrinsics[0], s->std_intrinsics[1], s->std_intrinsics[2], s->std_intrinsics[3],
                          s->std_distortion[0]};
    std::printf("seed %u:", seed);
    for (int i = 0; i < 5; ++i) {
      inside[i] += std::abs(got[i] - truth[i]) <= 1.96 * sd[i];
      std::printf(" %s %.2f sd (%.4g +- %.3g)", names[i], (got[i] - truth[i]) / sd[i], got[i], 1.96 * sd[i]);
    }
    std::printf("\n");
    EXPECT_LT(1.96 * sd[0], 0.005 * truth[0]) << "fx's interval is too wide to say anything";
    EXPECT_LT(1.96 * sd[2], 3.0) << "cx's interval is too wide to say anything";
  }
  // 8 of 10 or more: 95 % coverage gives fewer than 8 one time in 90.
  for (int i = 0; i < 5; ++i) EXPECT_GE(inside[i], 8) << names[i] << " within its 95 % interval in " << inside[i] << " seeds of " << kSeeds;
}

TEST(CalibrationSolve, ReportsTheChecklistCoverageAndWorstViewFirst) {
  const Views v = make_views(16, 1.0);
  const Result<Solution> s = solve_calibration(v.views, kBoard, v.camera.size);
  ASSERT_TRUE(s.ok()) << s.error();
  const QualityReport& r = s->report;
  ASSERT_EQ(r.checklist.size(), 5u);
  EXPECT_EQ(r.checklist[3].name, "square pixels");
  EXPECT_TRUE(r.checklist[3].ok) << r.checklist[3].detail;
  EXPECT_EQ(r.checklist[0].name, "enough views");
  EXPECT_TRUE(r.checklist[0].ok) << r.checklist[0].detail;
  EXPECT_TRUE(r.checklist[1].ok) << r.checklist[1].detail;   // RMS
  EXPECT_TRUE(r.checklist[2].ok) << r.checklist[2].detail;   // intervals
  EXPECT_GT(r.bars.x, 0.5);
  EXPECT_GT(r.bars.y, 0.5);
  ASSERT_EQ(r.worst_first.size(), s->view_names.size());
  for (size_t i = 1; i < r.worst_first.size(); ++i) EXPECT_GE(r.worst_first[i - 1].second, r.worst_first[i].second);
  EXPECT_EQ(s->std_intrinsics.size(), 4u);
  EXPECT_GT(s->std_intrinsics[0], 0.0);
}

TEST(CalibrationSolve, DropsAViewWithMisplacedCornersAndSaysWhich) {
  Views v = make_views(16, 1.0);
  ASSERT_GE(v.views.size(), 12u);
  // A misdetection: one view's corners shifted by a few pixels in a pattern no camera makes.
  for (size_t k = 0; k < v.views[3].corners.size(); ++k) v.views[3].corners[k].x += (k % 2 ? 4.f : -4.f);
  const Result<Solution> s = solve_calibration(v.views, kBoard, v.camera.size);
  ASSERT_TRUE(s.ok()) << s.error();
  bool named = false;
  for (const std::string& n : s->notes) named = named || n.rfind("dropped " + v.views[3].name + " ", 0) == 0;
  EXPECT_TRUE(named) << "the outlier view is not named in the notes";
  EXPECT_EQ(s->view_names.size(), v.views.size() - 1);
  EXPECT_NEAR(s->calibration.camera_matrix(0, 0), v.camera.camera_matrix(0, 0), 0.005 * v.camera.camera_matrix(0, 0));
}

// Views of the board's corners projected through `camera` at `poses` (metres), with Gaussian noise: the solve's
// input without rendering, for lenses and poses the renderer's set does not give.
std::vector<CalibrationView> projected_views(const SynthCamera& camera,
                                             const std::vector<std::pair<cv::Vec3d, cv::Vec3d>>& poses, double noise) {
  std::vector<cv::Point3f> board;
  for (const cv::Point3f& p : kBoard.object_points()) board.push_back(p * 0.001f);
  cv::RNG rng(3);
  std::vector<CalibrationView> out;
  for (size_t i = 0; i < poses.size(); ++i) {
    std::vector<cv::Point2f> px;
    cv::projectPoints(board, poses[i].first, poses[i].second, cv::Mat(camera.camera_matrix), camera.distortion, px);
    for (cv::Point2f& p : px) p += cv::Point2f(float(rng.gaussian(noise)), float(rng.gaussian(noise)));
    out.push_back({"view " + std::to_string(i), px, {}});
  }
  return out;
}

// What the solve fixes is what the views cannot determine, measured by the free solve's own uncertainty, not a
// coverage threshold: views whose board stayed in the middle fifth of the width still pin the principal point (the
// coverage rule fixed it at the image's centre, 2.5 px from the truth), and fronto-parallel views, which cannot,
// get it fixed, said, and shown as fixed rather than "± 0.00".
TEST(CalibrationSolve, FixesThePrincipalPointOnlyWhenTheViewsCannotDetermineIt) {
  Views v = make_views(16, 1.0);
  std::vector<CalibrationView> centred;
  for (const CalibrationView& view : v.views) {
    if (view_pose(view.corners, kBoard, v.camera.size).x > 0.3 && view_pose(view.corners, kBoard, v.camera.size).x < 0.7)
      centred.push_back(view);
  }
  ASSERT_GE(centred.size(), 6u) << "the pose set has too few centred views";
  const Result<Solution> s = solve_calibration(centred, kBoard, v.camera.size);
  ASSERT_TRUE(s.ok()) << s.error();
  EXPECT_LT(s->report.bars.x, 0.5) << "the views are centred: the old rule would have fixed the point";
  EXPECT_FALSE(s->fixed_principal_point);
  EXPECT_NEAR(s->calibration.camera_matrix(0, 2), v.camera.camera_matrix(0, 2), 2.0);
  EXPECT_NEAR(s->calibration.camera_matrix(1, 2), v.camera.camera_matrix(1, 2), 2.0);

  // Fronto-parallel views: the principal point trades against the board's position.
  std::vector<std::pair<cv::Vec3d, cv::Vec3d>> flat;
  for (int i = 0; i < 8; ++i) flat.push_back({cv::Vec3d(0, 0, 0), cv::Vec3d(-0.15 + 0.02 * i, -0.07 + 0.01 * (i % 3), 0.45)});
  const Result<Solution> f = solve_calibration(projected_views(v.camera, flat, 0.1), kBoard, v.camera.size);
  ASSERT_TRUE(f.ok()) << f.error();
  EXPECT_TRUE(f->fixed_principal_point);
  bool said = false;
  for (const std::string& n : f->notes) said = said || n.rfind("principal point fixed at the image centre: the views leave it uncertain (cx ± ", 0) == 0;
  EXPECT_TRUE(said);
  EXPECT_DOUBLE_EQ(f->calibration.camera_matrix(0, 2), (v.camera.size.width - 1) / 2.0);
  const std::string text = solution_text(*f);
  EXPECT_NE(text.find(" cx 319.50 (fixed)  cy 239.50 (fixed) px"), std::string::npos) << text;
  EXPECT_NE(text.find("cx fixed, cy fixed"), std::string::npos) << text;   // the intervals' check
}

// k3 is fixed at 0 (and said) when the views cannot tell it from 0, as with a lens that has none; a lens with a
// real k3, seen in views that cover the image, has it solved with its interval.
TEST(CalibrationSolve, FixesK3WhenTheViewsCannotTellItFromNone) {
  const Views few = make_views(8, 1.0);   // the synthetic lens has no k3
  const Result<Solution> a = solve_calibration(few.views, kBoard, few.camera.size);
  ASSERT_TRUE(a.ok()) << a.error();
  ASSERT_EQ(a->calibration.distortion.size(), 5u);
  EXPECT_EQ(a->calibration.distortion[4], 0.0);
  EXPECT_TRUE(a->fixed_k3);
  bool said = false;
  for (const std::string& n : a->notes) said = said || n.rfind("k3 fixed at 0: the views cannot tell it from 0 (", 0) == 0;
  EXPECT_TRUE(said);
  EXPECT_NE(solution_text(*a).find("k3 0.0000 (fixed)"), std::string::npos) << solution_text(*a);

  SynthCamera lens;
  lens.distortion = {-0.25, 0.08, 0, 0, 0.12};
  const SynthChessboard board{kBoard.cols, kBoard.rows, kBoard.square_mm / 1000, 1.0};
  const Result<Solution> b =
      solve_calibration(projected_views(lens, chessboard_poses(lens, board, 30, 7), 0.1), kBoard, lens.size);
  ASSERT_TRUE(b.ok()) << b.error();
  EXPECT_FALSE(b->fixed_k3) << solution_text(*b);
  EXPECT_NEAR(b->calibration.distortion[4], 0.12, 0.05);
  EXPECT_GT(b->std_distortion[4], 0.0) << "a solved k3 has an uncertainty";
}

// Pictures resized without keeping their aspect calibrate as a camera with oblong pixels: the check says so.
TEST(CalibrationSolve, SquashedPicturesFailTheSquarePixelCheck) {
  SynthCamera squashed;
  squashed.camera_matrix(1, 1) = 555 * 0.75;   // 640x480 views of a 16:9 camera
  squashed.camera_matrix(1, 2) = 236 * 0.75 + 60;
  const SynthChessboard board{kBoard.cols, kBoard.rows, kBoard.square_mm / 1000, 1.0};
  const Result<Solution> s =
      solve_calibration(projected_views(squashed, chessboard_poses(squashed, board, 16, 7), 0.1), kBoard, squashed.size);
  ASSERT_TRUE(s.ok()) << s.error();
  const Check& c = s->report.checklist[3];
  EXPECT_EQ(c.name, "square pixels");
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.detail.find("fy/fx 0.74"), std::string::npos) << c.detail;
  EXPECT_NE(c.detail.find("squashed or stretched"), std::string::npos) << c.detail;
  EXPECT_FALSE(s->report.good());
}

TEST(CalibrationSolve, RefusesTooFewViews) {
  Views v = make_views(4, 1.0);
  const Result<Solution> s = solve_calibration(v.views, kBoard, v.camera.size);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("at least 6 are needed"), std::string::npos) << s.error();
}

TEST(ViewSelection, KeepsStillNewViewsAndSaysWhyOthersAreRefused) {
  const SynthCamera camera;
  const SynthChessboard board{kBoard.cols, kBoard.rows, kBoard.square_mm / 1000, 1.0};
  const ChessboardRenderer renderer(camera, board);
  const auto poses = chessboard_poses(camera, board, 3, 11);
  ASSERT_EQ(poses.size(), 3u);
  ViewSelector sel(kBoard, SelectOptions{});
  const auto look = [&](const ChessboardView& view) { return detect_chessboard(view.image, kBoard); };
  const ChessboardView a = renderer.render(poses[0].first, poses[0].second, 0.6, 1, 1);
  EXPECT_EQ(sel.consider(look(a), camera.size).kind, "moving");   // nothing before it to compare with
  EXPECT_TRUE(sel.consider(look(a), camera.size).keep);           // still: the same place again
  EXPECT_EQ(sel.consider(look(a), camera.size).kind, "similar");  // still, but nothing new
  // The board jumps to another pose: moving; then held there: kept.
  const ChessboardView b = renderer.render(poses[1].first, poses[1].second, 0.6, 1, 2);
  EXPECT_EQ(sel.consider(look(b), camera.size).kind, "moving");
  EXPECT_TRUE(sel.consider(look(b), camera.size).keep);
  // Blurred: a Gaussian of 4 px widens the edges past the limit (if the board is still found at all).
  const ChessboardView c = renderer.render(poses[2].first, poses[2].second, 4.0, 1, 3);
  const BoardDetection dc = look(c);
  if (dc.found) {
    sel.consider(dc, camera.size);
    const Verdict blurred = sel.consider(dc, camera.size);
    EXPECT_EQ(blurred.kind, "blurred") << blurred.reason;
  }
  EXPECT_EQ(sel.consider(BoardDetection{}, camera.size).reason, "no board");
  // Near the edge: the same corners moved to touch the image's left side.
  BoardDetection edge = look(b);
  const float dx = edge.corners[0].x;
  for (cv::Point2f& p : edge.corners) p.x -= dx - 3;
  ViewSelector stills(kBoard, SelectOptions{.video = false});
  const Verdict v = stills.consider(edge, camera.size);
  EXPECT_EQ(v.kind, "edge") << v.reason;
}

TEST(BoardDetection, FindsThePapersBoardAndRefusesGridsOfAnotherSize) {
  const SynthCamera camera;
  const ChessboardRenderer renderer(camera, SynthChessboard{});
  const auto poses = chessboard_poses(camera, SynthChessboard{}, 4, 21);
  int opencv_edge_grids = 0;
  for (const auto& [rv, tv] : poses) {
    const ChessboardView view = renderer.render(rv, tv, 0.6, 1.5, 1);
    const BoardDetection d = detect_chessboard(view.image, kBoard);
    ASSERT_TRUE(d.found);
    EXPECT_FALSE(larger_board(view.image, kBoard, d.corners).has_value());
    // OpenCV alone returns a 7x5 grid along the board's outer edge for some of these poses: refused here.
    std::vector<cv::Point2f> raw;
    opencv_edge_grids += cv::findChessboardCornersSB(view.image, cv::Size(7, 5), raw,
                                                     cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_ACCURACY);
    EXPECT_FALSE(detect_chessboard(view.image, BoardSpec{.cols = 7, .rows = 5}).found);
    EXPECT_FALSE(detect_chessboard(view.image, BoardSpec{.cols = 10, .rows = 7}).found);
    // A correct grid of 7x5 of the board's corners grows back to the whole 9x6 board.
    std::vector<cv::Point2f> part;
    for (int r = 1; r < 6; ++r)
      for (int c = 1; c < 8; ++c) part.push_back(d.corners[size_t(r * 9 + c)]);
    const std::optional<cv::Size> whole = larger_board(view.image, BoardSpec{.cols = 7, .rows = 5}, part);
    ASSERT_TRUE(whole.has_value());
    EXPECT_EQ(*whole, cv::Size(9, 6));
    EXPECT_EQ(find_any_chessboard(view.image, {{7, 5}, {8, 6}, {9, 6}}), std::optional<cv::Size>(cv::Size(9, 6)));
  }
  EXPECT_GT(opencv_edge_grids, 0) << "these poses no longer show OpenCV's edge grids: the test proves nothing";
}

}  // namespace
}  // namespace arwb
