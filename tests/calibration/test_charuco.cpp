// ChArUco end to end against a known camera: synthetic views of OpenCV 4.6's layout (proved by OpenCV's own
// charuco functions reading them), found by detect_board with each corner's id, chosen by ViewSelector (partial
// views included) and solved by solve_calibration, must give back the camera (fx, fy within 0.5 %, cx, cy within
// 2 px, k1 within 0.02), no worse than OpenCV's calibrateCameraCharuco with its defaults.
#include "calibration/board.hpp"
#include "calibration/solve.hpp"
#include "synth/chessboard_view.hpp"

#include <gtest/gtest.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <cstdio>

namespace arwb {
namespace {

BoardSpec charuco(int cols = 5, int rows = 7) {
  return BoardSpec{.kind = BoardKind::charuco, .cols = cols, .rows = rows, .square_mm = 35, .marker_mm = 26};
}

const SynthCamera kCamera;

const ChessboardRenderer& renderer_for(const BoardSpec& spec) {
  // One per board and binary: the renderer undistorts every pixel.
  static std::map<std::string, std::unique_ptr<ChessboardRenderer>> made;
  auto& r = made[spec.describe()];
  if (!r) r = std::make_unique<ChessboardRenderer>(kCamera, SynthChessboard::of(spec));
  return *r;
}

// A view facing the camera, the board's centre on the optical axis, 0.5 m away.
ChessboardView frontal(const BoardSpec& spec, double blur = 0.6) {
  const double w = spec.square_mm / 1000 * (spec.cols - 2), h = spec.square_mm / 1000 * (spec.rows - 2);
  return renderer_for(spec).render({0.1, -0.15, 0.05}, {-w / 2, -h / 2, 0.55}, blur, 1.0);
}

// The largest distance from a detected corner to the rendered truth of the same id.
double worst_corner_error(const std::vector<cv::Point2f>& corners, const std::vector<int>& ids,
                          const ChessboardView& truth) {
  double worst = 0;
  for (size_t i = 0; i < ids.size(); ++i) worst = std::max(worst, double(cv::norm(corners[i] - truth.corners[size_t(ids[i])])));
  return worst;
}

TEST(Charuco, OpenCVsOwnFunctionsReadOurRenderingAtTheRightCorners) {
  // 5x7 (odd rows) and 6x6 (even rows, where boards printed for OpenCV's older layout differ).
  for (const BoardSpec& spec : {charuco(5, 7), charuco(6, 6)}) {
    const ChessboardView v = frontal(spec);
    ASSERT_TRUE(v.all_inside) << spec.describe();
    const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
        spec.cols, spec.rows, float(spec.square_mm), float(spec.marker_mm),
        cv::aruco::getPredefinedDictionary(cv::aruco::DICT_5X5_100));
    std::vector<std::vector<cv::Point2f>> markers;
    std::vector<int> marker_ids;
    cv::aruco::detectMarkers(v.image, board->dictionary, markers, marker_ids);
    EXPECT_EQ(marker_ids.size(), board->ids.size()) << spec.describe() << ": every marker read by OpenCV";
    std::vector<cv::Point2f> corners;
    std::vector<int> ids;
    cv::aruco::interpolateCornersCharuco(markers, marker_ids, v.image, board, corners, ids);
    EXPECT_EQ(int(ids.size()), spec.inner_corners().area()) << spec.describe();
    // Corners are a square (about 40 px) apart: an id at the wrong corner would be far off. OpenCV 4.6's own
    // interpolation is half a pixel off (detect_board refines its corners again).
    EXPECT_LT(worst_corner_error(corners, ids, v), 1.0) << spec.describe() << ": an id at the wrong corner";
    // And OpenCV's board agrees with ours on where corner k is: one square in from the outer corner.
    const std::vector<cv::Point3f> ours = spec.object_points();
    for (size_t k = 0; k < ours.size(); ++k) {
      EXPECT_FLOAT_EQ(board->chessboardCorners[k].x, ours[k].x + float(spec.square_mm));
      EXPECT_FLOAT_EQ(board->chessboardCorners[k].y, ours[k].y + float(spec.square_mm));
    }
  }
}

TEST(Charuco, DetectBoardGivesEachCornerItsIdAndASharpnessThatBlurRaises) {
  const BoardSpec spec = charuco();
  const ChessboardView sharp = frontal(spec, 0.6);
  const BoardDetection d = detect_board(sharp.image, spec);
  ASSERT_TRUE(d.found);
  ASSERT_EQ(d.ids.size(), d.corners.size());
  EXPECT_EQ(int(d.ids.size()), spec.inner_corners().area());
  for (size_t i = 1; i < d.ids.size(); ++i) EXPECT_LT(d.ids[i - 1], d.ids[i]) << "ids sorted";
  EXPECT_LT(worst_corner_error(d.corners, d.ids, sharp), 0.25);
  double mean = 0;
  for (size_t i = 0; i < d.ids.size(); ++i) mean += cv::norm(d.corners[i] - sharp.corners[size_t(d.ids[i])]);
  EXPECT_LT(mean / double(d.ids.size()), 0.12) << "corners not refined";
  EXPECT_GT(d.edge_width_px, 0.5);
  EXPECT_LT(d.edge_width_px, 3.5);
  const ChessboardView blurred = frontal(spec, 1.6);
  const BoardDetection b = detect_board(blurred.image, spec);
  ASSERT_TRUE(b.found);
  EXPECT_GT(b.edge_width_px, d.edge_width_px + 1.0) << "blur must widen the edges";
}

TEST(Charuco, APartialViewIsFoundWithTheIdsOfTheCornersInside) {
  const BoardSpec spec = charuco();
  const auto poses = partial_board_poses(kCamera, SynthChessboard::of(spec), 6, 3);
  ASSERT_EQ(poses.size(), 6u);
  int found = 0;
  for (const auto& [rv, tv] : poses) {
    const ChessboardView v = renderer_for(spec).render(rv, tv, 0.6, 1.0);
    EXPECT_FALSE(v.all_inside);
    const BoardDetection d = detect_board(v.image, spec);
    if (!d.found) continue;
    ++found;
    EXPECT_LT(int(d.ids.size()), spec.inner_corners().area());
    // Ids at their corners (a wrong one would be a square off); a few corners of steeply tilted views stay up to
    // a pixel off after OpenCV's interpolation, most within a tenth.
    EXPECT_LT(worst_corner_error(d.corners, d.ids, v), 1.5);
    double mean = 0;
    for (size_t i = 0; i < d.ids.size(); ++i) mean += cv::norm(d.corners[i] - v.corners[size_t(d.ids[i])]);
    EXPECT_LT(mean / double(d.ids.size()), 0.2);
  }
  EXPECT_GE(found, 4);
}

TEST(Charuco, TooFewCornersOrNoneIsNoBoard) {
  const BoardSpec spec = charuco();
  const ChessboardView v = frontal(spec);
  EXPECT_FALSE(detect_board(cv::Mat(480, 640, CV_8U, cv::Scalar(128)), spec).found);
  // Only a corner of the board left: one or two ChArUco corners are not a view.
  cv::Mat part(v.image.size(), CV_8U, cv::Scalar(200));
  const cv::Rect keep(cv::Point(v.corners[0]) - cv::Point(60, 60), cv::Size(100, 100));
  v.image(keep).copyTo(part(keep));
  const BoardDetection d = detect_board(part, spec);
  EXPECT_FALSE(d.found) << d.ids.size() << " corners";
  // Markers of another dictionary than the board's are not read.
  BoardSpec other = spec;
  other.dictionary = "DICT_4X4_50";
  EXPECT_FALSE(detect_board(v.image, other).found);
}

TEST(Charuco, TheSelectorMeasuresMotionOverTheIdsBothFramesHold) {
  const BoardSpec spec = charuco();
  ViewSelector sel(spec, SelectOptions{});
  const std::vector<cv::Point2f> a{{100, 100}, {150, 100}, {200, 100}, {100, 150}, {150, 150}, {200, 150}, {100, 200}};
  BoardDetection first{true, a, {0, 1, 2, 4, 5, 6, 8}, 1.0};
  EXPECT_EQ(sel.consider(first, {640, 480}).kind, "moving");   // nothing to compare with
  // The same corners again, one more seen and one lost: still, and the view says it is part of the board.
  BoardDetection second{true, {{150, 100}, {200, 100}, {250, 100}, {100, 150}, {150, 150}, {200, 150}, {100, 200}},
                        {1, 2, 3, 4, 5, 6, 8}, 1.0};
  const Verdict v = sel.consider(second, {640, 480});
  EXPECT_TRUE(v.keep) << v.reason;
  EXPECT_NE(v.reason.find("7 of 24 corners"), std::string::npos) << v.reason;
  // No id in common with the previous frame: moving, and said so.
  BoardDetection third{true, a, {10, 11, 12, 14, 15, 16, 18}, 1.0};
  const Verdict w = sel.consider(third, {640, 480});
  EXPECT_EQ(w.kind, "moving");
  EXPECT_NE(w.reason.find("no corner"), std::string::npos) << w.reason;
  // Moved by 5 px: moving.
  BoardDetection fourth = third;
  for (cv::Point2f& p : fourth.corners) p.x += 5;
  EXPECT_EQ(sel.consider(fourth, {640, 480}).kind, "moving");
}

struct CharucoViews {
  std::vector<CalibrationView> views;
  int partial = 0;
};

CharucoViews charuco_views(const BoardSpec& spec, int full, int partial) {
  CharucoViews out;
  const ChessboardRenderer& r = renderer_for(spec);
  auto poses = chessboard_poses(kCamera, SynthChessboard::of(spec), full, 5);
  const auto more = partial_board_poses(kCamera, SynthChessboard::of(spec), partial, 9);
  poses.insert(poses.end(), more.begin(), more.end());
  ViewSelector sel(spec, SelectOptions{.video = false});
  for (size_t i = 0; i < poses.size(); ++i) {
    const ChessboardView v = r.render(poses[i].first, poses[i].second, 0.6, 1.5, unsigned(i + 1));
    const BoardDetection d = detect_board(v.image, spec);
    const Verdict verdict = sel.consider(d, kCamera.size);
    if (!verdict.keep) continue;
    out.views.push_back({"view " + std::to_string(i), d.corners, d.ids});
    out.partial += int(d.ids.size()) < spec.inner_corners().area();
  }
  return out;
}

TEST(Charuco, CalibratesTheKnownCameraFromFullAndPartialViews) {
  const BoardSpec spec = charuco();
  const CharucoViews v = charuco_views(spec, 16, 8);
  ASSERT_GE(v.views.size(), 16u);
  EXPECT_GE(v.partial, 4) << "partial views must be kept too";
  const Result<Solution> s = solve_calibration(v.views, spec, kCamera.size);
  ASSERT_TRUE(s.ok()) << s.error();
  const cv::Matx33d& K = s->calibration.camera_matrix;
  const cv::Matx33d& T = kCamera.camera_matrix;
  EXPECT_NEAR(K(0, 0), T(0, 0), 0.005 * T(0, 0));
  EXPECT_NEAR(K(1, 1), T(1, 1), 0.005 * T(1, 1));
  EXPECT_NEAR(K(0, 2), T(0, 2), 2.0);
  EXPECT_NEAR(K(1, 2), T(1, 2), 2.0);
  EXPECT_NEAR(s->calibration.distortion[0], kCamera.distortion[0], 0.02);
  EXPECT_LT(s->rms, 0.5);

  // The benchmark: OpenCV's calibrateCameraCharuco with its default flags on the same views.
  const cv::Ptr<cv::aruco::CharucoBoard> board = opencv_charuco_board(spec);
  ASSERT_TRUE(board);
  std::vector<cv::Mat> corners, ids;
  for (const CalibrationView& view : v.views) {
    corners.push_back(cv::Mat(view.corners, true));
    ids.push_back(cv::Mat(view.ids, true));
  }
  cv::Mat K2, D2;
  const double rms2 = cv::aruco::calibrateCameraCharuco(corners, ids, board, kCamera.size, K2, D2);
  std::printf("truth   fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f k2 %.4f\n", T(0, 0), T(1, 1), T(0, 2), T(1, 2),
              kCamera.distortion[0], kCamera.distortion[1]);
  std::printf("ours    fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f k2 %.4f rms %.4f px, %zu views (%d partial)\n",
              K(0, 0), K(1, 1), K(0, 2), K(1, 2), s->calibration.distortion[0], s->calibration.distortion[1], s->rms,
              s->view_names.size(), v.partial);
  std::printf("opencv  fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f k2 %.4f rms %.4f px (calibrateCameraCharuco, "
              "default flags)\n",
              K2.at<double>(0, 0), K2.at<double>(1, 1), K2.at<double>(0, 2), K2.at<double>(1, 2), D2.at<double>(0),
              D2.at<double>(1), rms2);
  for (const std::string& n : s->notes) std::printf("note: %s\n", n.c_str());
  EXPECT_LE(s->rms, rms2 + 0.01) << "ours must not be worse than OpenCV's defaults";
  EXPECT_NEAR(s->opencv_defaults.camera_matrix(0, 0), K2.at<double>(0, 0), 1e-6);
  EXPECT_NEAR(s->opencv_defaults_rms, rms2, 1e-9);
}

TEST(Charuco, DropsAViewWithMisplacedCornersAndSaysWhich) {
  const BoardSpec spec = charuco();
  CharucoViews v = charuco_views(spec, 16, 0);
  ASSERT_GE(v.views.size(), 12u);
  for (size_t k = 0; k < v.views[2].corners.size(); ++k) v.views[2].corners[k].x += (k % 2 ? 4.f : -4.f);
  const Result<Solution> s = solve_calibration(v.views, spec, kCamera.size);
  ASSERT_TRUE(s.ok()) << s.error();
  bool named = false;
  for (const std::string& n : s->notes) named = named || n.rfind("dropped " + v.views[2].name + " ", 0) == 0;
  EXPECT_TRUE(named) << "the outlier view is not named in the notes";
  EXPECT_EQ(s->view_names.size(), v.views.size() - 1);
}

}  // namespace
}  // namespace arwb
