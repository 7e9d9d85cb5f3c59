// Pose in the real window (xvfb-run): a marker rendered with a known pose through the default camera (no
// calibration loaded) gets its pose, marked assumed; the live view draws the paper's cube over it when asked
// (--actions pose=cube) and nothing 3D when not; the Pose panel opens in every arrangement without clipping.
#include "pose/marker_pose.hpp"
#include "synth/marker_view.hpp"
#include "support/support.hpp"
#include "support/window.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <string>

namespace arwb {
namespace {

using test::RunResult;
using test::TempDir;

using test::stats;
using test::window_args;

// One 6-side-away marker tilted 30 degrees, through the default camera the workbench assumes without a
// calibration: its pose in marker sides is then the truth.
std::string marker_image(const TempDir& tmp, cv::Vec3d* tvec) {
  const Calibration cam = default_calibration({640, 480});
  SynthCamera camera;
  camera.camera_matrix = cam.camera_matrix;
  camera.distortion = cam.distortion;
  cv::Matx33d T;
  cv::Rodrigues(cv::Vec3d(0.45, 0.25, 0.2), T);
  cv::Vec3d rv;
  cv::Rodrigues(cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1) * T, rv);
  *tvec = cv::Vec3d(0.4, 0.3, 6.0);
  const MarkerView v = MarkerRenderer(camera, SynthMarker{.dictionary = "ARUCO_ORIGINAL", .id = 12, .side_m = 1})
                           .render(rv, *tvec, 0.5, 1.0, 1);
  cv::Mat bgr;
  cv::cvtColor(v.image, bgr, cv::COLOR_GRAY2BGR);
  const std::string path = tmp.str("marker.png");
  cv::imwrite(path, bgr);
  return path;
}

int cube_pixels(const cv::Mat& shot) {   // the cube's cyan (80, 220, 255)
  int n = 0;
  for (int y = 0; y < shot.rows; ++y)
    for (int x = 0; x < shot.cols; ++x) {
      const cv::Vec3b p = shot.at<cv::Vec3b>(y, x);
      n += p[0] > 220 && p[1] > 190 && p[2] < 130;
    }
  return n;
}

TEST(PoseView, TheMarkersPoseIsShownWithTheAssumedCameraAndItsCubeDrawn) {
  TempDir tmp;
  cv::Vec3d truth;
  const std::string image = marker_image(tmp, &truth);
  const std::string with = tmp.str("with.png"), without = tmp.str("without.png");
  const RunResult r = test::run_arwb_window(window_args(
      tmp, "--source '" + image + "' --frames 30 --stats --screenshot '" + with + "' --actions '0:pose=cube,axes'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json s = stats(r);
  ASSERT_EQ(s["poses"].size(), 1u) << r.out;
  const nlohmann::json& p = s["poses"][0];
  EXPECT_EQ(p["id"], 12);
  EXPECT_EQ(s["pose_camera"], "assumed");
  EXPECT_NEAR(p["tvec"][0].get<double>(), truth[0], 0.05);
  EXPECT_NEAR(p["tvec"][1].get<double>(), truth[1], 0.05);
  EXPECT_NEAR(p["tvec"][2].get<double>(), truth[2], 0.1);
  EXPECT_EQ(s["pose_drawn"], 1);
  const RunResult plain = test::run_arwb_window(
      window_args(tmp, "--source '" + image + "' --frames 30 --stats --screenshot '" + without + "'"));
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(stats(plain)["pose_drawn"], 0);
  const cv::Mat a = cv::imread(with), b = cv::imread(without);
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  // The window has a few pixels of that colour elsewhere (widgets): the cube's edges add many.
  EXPECT_GT(cube_pixels(a), cube_pixels(b) + 150) << "the cube's edges are not on the screenshot";
}

TEST(PoseView, ThePosePanelFitsInEveryWorkspaceItIsIn) {
  TempDir tmp;
  cv::Vec3d truth;
  const std::string image = marker_image(tmp, &truth);
  for (const char* ws : {"Script", "Teach"}) {
    SCOPED_TRACE(ws);
    const RunResult r = test::run_arwb_window(window_args(
        tmp, "--source '" + image + "' --frames 30 --stats --actions '0:workspace=" + std::string(ws) +
                 ";2:open=pose;2:pose=all'"));
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json s = stats(r);
    EXPECT_EQ(s["layout"]["overlaps"], 0) << s["layout"];
    EXPECT_TRUE(s["layout"]["clipped"].empty()) << s["layout"]["clipped"];
    bool front = false;
    for (const auto& region : s["layout"]["regions"]) front = front || region["front"] == "pose";
    EXPECT_TRUE(front) << s["layout"];
  }
}

// The printed size puts positions in its unit: --marker-size 50 (mm) at start, and marker_size= while running
// (as the Pose panel's field does), both scale tvec by it; 0 goes back to marker sides.
TEST(PoseView, TheMarkerSizeGivesPositionsInItsUnit) {
  TempDir tmp;
  cv::Vec3d truth;
  const std::string image = marker_image(tmp, &truth);
  const RunResult mm = test::run_arwb_window(
      window_args(tmp, "--source '" + image + "' --frames 30 --stats --marker-size 50"));
  ASSERT_EQ(mm.status, 0) << mm.err;
  nlohmann::json s = stats(mm);
  ASSERT_EQ(s["poses"].size(), 1u) << mm.out;
  EXPECT_EQ(s["pose_marker_side"], 50.0);
  EXPECT_NEAR(s["poses"][0]["tvec"][2].get<double>(), truth[2] * 50, 5);
  EXPECT_NEAR(s["poses"][0]["distance"].get<double>(), cv::norm(truth) * 50, 5);
  const RunResult back = test::run_arwb_window(window_args(
      tmp, "--source '" + image + "' --frames 30 --stats --marker-size 50 --actions '5:marker_size=0'"));
  ASSERT_EQ(back.status, 0) << back.err;
  s = stats(back);
  ASSERT_EQ(s["poses"].size(), 1u) << back.out;
  EXPECT_EQ(s["pose_marker_side"], 1.0);
  EXPECT_NEAR(s["poses"][0]["tvec"][2].get<double>(), truth[2], 0.1);
  const RunResult bad = test::run_arwb_window(
      window_args(tmp, "--source '" + image + "' --frames 5 --actions '0:marker_size=big'"));
  EXPECT_NE(bad.err.find("marker_size: a size from 0"), std::string::npos) << bad.err;
}

// A calibration given with --calib is the camera poses are made with from the first frame (it was once attached
// to the frame only after the tracker had run, so poses stayed on the assumed camera).
TEST(PoseView, ALoadedCalibrationIsThePosesCamera) {
  TempDir tmp;
  cv::Vec3d truth;
  const std::string image = marker_image(tmp, &truth);
  const Calibration cam = default_calibration({640, 480});
  test::write_file(tmp.str("cam.yml"),
                   "%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ " +
                       std::to_string(cam.camera_matrix(0, 0)) + ", 0., 319.5, 0., " +
                       std::to_string(cam.camera_matrix(1, 1)) + ", 239.5, 0., 0., 1. ]\n"
                       "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n"
                       "   data: [ 0., 0., 0., 0., 0. ]\nimage_width: 640\nimage_height: 480\n");
  const RunResult r = test::run_arwb_window(
      window_args(tmp, "--source '" + image + "' --frames 30 --stats --calib '" + tmp.str("cam.yml") + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json s = stats(r);
  ASSERT_EQ(s["poses"].size(), 1u) << r.out;
  EXPECT_NE(s["pose_camera"].get<std::string>().find("cam.yml"), std::string::npos) << s["pose_camera"];
  EXPECT_NEAR(s["poses"][0]["tvec"][2].get<double>(), truth[2], 0.1);
}

}  // namespace
}  // namespace arwb
