// Cross-validation (mrcal's way): two calibrations compared over the image after fitting the rotation between
// their frames. The comparison itself on cameras whose difference is known, then the solve's report on views of a
// known camera: views that cover the image give halves that agree everywhere; views that stay in the middle give
// halves that agree in the middle and part in the corners, and the heatmap says so.
#include "calibration/cross_validation.hpp"
#include "calibration/solve.hpp"
#include "synth/chessboard_view.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <cstdio>
#include <random>

namespace arwb {
namespace {

const cv::Size kSize{640, 480};

Calibration camera(double fx, double fy, double cx, double cy, std::vector<double> d) {
  Calibration c;
  c.camera_matrix = cv::Matx33d(fx, 0, cx, 0, fy, cy, 0, 0, 1);
  c.distortion = std::move(d);
  c.image_size = kSize;
  return c;
}

TEST(ProjectionDiff, TheSameCameraAgreesEverywhere) {
  const Calibration a = camera(560, 555, 322, 236, {-0.25, 0.08, 0, 0, 0});
  const ProjectionDiff d = projection_diff(a, a, kSize);
  ASSERT_EQ(d.diff.size(), cv::Size(32, 24));
  EXPECT_LT(d.max_px, 1e-3);
  EXPECT_EQ(cv::countNonZero(d.diff != d.diff), 0) << "a cell was NaN";
}

TEST(ProjectionDiff, APrincipalPointShiftIsMostlyARotationAndIsForgiven) {
  // Moving cx by 4 px turns the camera's axis by about 0.4 degrees: nothing a user projects changes near the
  // centre. Without the fitted rotation every cell would differ by 4 px.
  const Calibration a = camera(560, 555, 322, 236, {-0.25, 0.08, 0, 0, 0});
  const Calibration b = camera(560, 555, 326, 236, {-0.25, 0.08, 0, 0, 0});
  const ProjectionDiff d = projection_diff(a, b, kSize);
  EXPECT_LT(d.diff(12, 16), 0.05) << "the centre should agree once the rotation is fitted";
  EXPECT_LT(d.median_px, 1.0);
  EXPECT_LT(d.max_px, 4.0);
}

TEST(ProjectionDiff, ADistortionDifferenceShowsInTheCornersNotTheCentre) {
  const Calibration a = camera(560, 555, 322, 236, {-0.25, 0.08, 0, 0, 0});
  const Calibration b = camera(560, 555, 322, 236, {-0.25, 0.14, 0, 0, 0});   // k2 off: it grows with r^4
  const ProjectionDiff d = projection_diff(a, b, kSize);
  const float centre = d.diff(12, 16), corner = std::max({d.diff(0, 0), d.diff(0, 31), d.diff(23, 0), d.diff(23, 31)});
  EXPECT_LT(centre, 0.05);
  EXPECT_GT(corner, 1.0);
  EXPECT_NEAR(d.max_px, corner, 1e-3) << "the largest difference is in a corner";
}

// Views of the paper's board seen by `cam` at `poses`, corners projected exactly and then jittered by 0.1 px, as a
// good detector's would be.
std::vector<CalibrationView> views_at(const SynthCamera& cam, const std::vector<std::pair<cv::Vec3d, cv::Vec3d>>& poses) {
  const BoardSpec board{};
  std::vector<cv::Point3f> object;
  for (const cv::Point3f& p : board.object_points()) object.emplace_back(p.x / 1000, p.y / 1000, 0);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0, 0.1f);
  std::vector<CalibrationView> views;
  for (size_t i = 0; i < poses.size(); ++i) {
    std::vector<cv::Point2f> corners;
    cv::projectPoints(object, poses[i].first, poses[i].second, cv::Mat(cam.camera_matrix), cv::Mat(cam.distortion),
                      corners);
    for (cv::Point2f& p : corners) {   // one draw per statement: argument order differs between compilers
      const float dy = noise(rng), dx = noise(rng);
      p += cv::Point2f(dx, dy);
    }
    views.push_back({"view " + std::to_string(i), corners, {}});
  }
  return views;
}

TEST(CrossValidation, ViewsThatCoverTheImageAgreeAndViewsInTheMiddleDoNotInTheCorners) {
  const SynthCamera cam;
  const SynthChessboard paper{9, 6, 0.025, 1.0};
  const Result<Solution> good = solve_calibration(views_at(cam, chessboard_poses(cam, paper, 24, 7)), BoardSpec{},
                                                  cam.size);
  ASSERT_TRUE(good.ok()) << good.error();

  // The board far away in the middle of the image, turned a little each time: the lens's edge is never seen.
  std::vector<std::pair<cv::Vec3d, cv::Vec3d>> middle;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> tilt(-0.45, 0.45), shift(-0.02, 0.02);
  for (int i = 0; i < 24; ++i) {
    const double roll = tilt(rng), ty = tilt(rng), tx = tilt(rng), sy = shift(rng), sx = shift(rng);
    middle.push_back({cv::Vec3d(tx, ty, roll * 0.3), cv::Vec3d(-0.1 + sx, -0.0625 + sy, 0.75)});
  }
  const Result<Solution> poor = solve_calibration(views_at(cam, middle), BoardSpec{}, cam.size);
  ASSERT_TRUE(poor.ok()) << poor.error();

  const QualityReport& g = good->report;
  const QualityReport& p = poor->report;
  ASSERT_FALSE(g.cross_validation.empty());
  ASSERT_FALSE(p.cross_validation.empty());
  const auto within = [](const cv::Mat1f& m, float px) { return double(cv::countNonZero(m <= px)) / double(m.total()); };
  std::printf("cross-validation, views covering the image: median %.3f px, max %.3f px, %.0f %% of cells within 0.5 px\n",
              g.cross_validation_median_px, g.cross_validation_max_px, 100 * within(g.cross_validation, 0.5f));
  std::printf("cross-validation, views in the middle only:  median %.3f px, max %.3f px, %.0f %% of cells within 0.5 px\n",
              p.cross_validation_median_px, p.cross_validation_max_px, 100 * within(p.cross_validation, 0.5f));
  // Well spread views: the halves agree over most of the image; only the far corners, which no board reached,
  // are left to extrapolation.
  EXPECT_LT(g.cross_validation_median_px, 0.25);
  EXPECT_GT(within(g.cross_validation, 0.5f), 0.8);
  // Views in the middle: the corners part by far more, and the heatmap shows it.
  EXPECT_GT(p.cross_validation_max_px, 4 * g.cross_validation_max_px);
  EXPECT_LT(within(p.cross_validation, 0.5f), 0.6);
  // In the middle, where both sets of views were, both agree.
  EXPECT_LT(p.cross_validation(12, 16), 0.5);

  const std::string text = solution_text(*good);
  EXPECT_NE(text.find("cross-validation (two halves"), std::string::npos) << text;
  EXPECT_NE(text.find(" px at worst (the "), std::string::npos) << text;
  EXPECT_NE(solution_json(*good, BoardSpec{}).find("\"cross_validation\""), std::string::npos);
}

TEST(CrossValidation, TooFewViewsToSplitLeaveItEmptyAndSaySo) {
  const SynthCamera cam;
  const SynthChessboard paper{9, 6, 0.025, 1.0};
  const Result<Solution> s = solve_calibration(views_at(cam, chessboard_poses(cam, paper, 8, 7)), BoardSpec{}, cam.size);
  ASSERT_TRUE(s.ok()) << s.error();
  EXPECT_TRUE(s->report.cross_validation.empty());
  EXPECT_NE(solution_text(*s).find("cross-validation: needs"), std::string::npos);
}

}  // namespace
}  // namespace arwb
