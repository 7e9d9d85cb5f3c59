// `arwb detect --marker-size L`: each marker's pose in the JSON and the text, checked against a marker rendered
// with a known pose through a known lens (its calibration file given with --calib); without --calib the default
// camera's pose is marked assumed; in a video the previous frame chooses between an ambiguous view's solutions.
#include "calibration/calibration_file.hpp"
#include "pose/marker_pose.hpp"
#include "synth/marker_view.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include <sstream>

using namespace arwb;
using test::parse;
using test::lines;
using test::q;
using test::run_arwb;
using Json = nlohmann::ordered_json;

namespace {

cv::Vec3d vec(const Json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

struct Rendered {
  cv::Vec3d rvec, tvec;   // metres
};

// A 50 mm marker 40 cm away, tilted 35 degrees, off the image's centre, through SynthCamera's barrel lens.
Rendered render_marker(const std::string& png, const std::string& calib_path) {
  const SynthCamera camera;
  cv::Matx33d T;
  cv::Rodrigues(cv::Vec3d(0.2, 0.55, 0.3), T);
  cv::Vec3d rv;
  cv::Rodrigues(cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1) * T, rv);
  const cv::Vec3d tv(0.08, -0.05, 0.4);
  const MarkerView v = MarkerRenderer(camera, SynthMarker{.dictionary = "ARUCO_ORIGINAL", .id = 9, .side_m = 0.05})
                           .render(rv, tv, 0.5, 1.0, 3);
  EXPECT_TRUE(v.all_inside);
  EXPECT_TRUE(cv::imwrite(png, v.image));
  Calibration c;
  c.camera_matrix = camera.camera_matrix;
  c.distortion = camera.distortion;
  c.image_size = camera.size;
  EXPECT_TRUE(write_calibration(calib_path, c, {}).ok());
  return {rv, tv};
}

}  // namespace

TEST(CliDetectPose, EachMarkerGainsItsPoseInTheUnitOfTheMarkerSize) {
  test::TempDir dir;
  const Rendered truth = render_marker(dir.str("m.png"), dir.str("cam.yml"));
  const auto r = run_arwb("detect --json --calib " + q(dir.str("cam.yml")) + " --marker-size 50 " + q(dir.str("m.png")));
  ASSERT_EQ(r.status, 0) << r.err;
  Json j = parse(lines(r.out).at(0));
  ASSERT_EQ(j["markers"].size(), 1u) << r.out;
  Json& pose = j["markers"][0]["pose"];
  ASSERT_TRUE(pose.is_object()) << j.dump();
  for (const char* k : {"rvec", "tvec", "error_px", "ambiguity", "alternative", "chosen_by_previous", "camera",
                        "distance", "tilt_deg", "yaw_deg", "pitch_deg", "roll_deg"})
    EXPECT_TRUE(pose.contains(k)) << k;
  for (const char* k : {"rvec", "tvec", "error_px"}) EXPECT_TRUE(pose["alternative"].contains(k)) << k;
  EXPECT_EQ(pose["camera"], "calibrated");
  // tvec in mm, as the size was given.
  EXPECT_LT(cv::norm(vec(pose["tvec"]) - truth.tvec * 1000), 4.0) << pose.dump();
  EXPECT_LT(rotation_difference_deg(vec(pose["rvec"]), truth.rvec), 2.0) << pose.dump();
  EXPECT_NEAR(pose["distance"].get<double>(), cv::norm(truth.tvec) * 1000, 4.0);
  EXPECT_LT(pose["error_px"].get<double>(), 0.5);
  EXPECT_GE(pose["alternative"]["error_px"].get<double>(), pose["error_px"].get<double>());
  EXPECT_LT(pose["ambiguity"].get<double>(), 0.3) << "35 degrees of tilt at 40 cm is a clear view";

  // The text says the same in one line per marker.
  const auto text = run_arwb("detect --calib " + q(dir.str("cam.yml")) + " --marker-size 0.05 " + q(dir.str("m.png")));
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find("    pose: t ("), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("assumed camera"), std::string::npos) << text.out;
}

TEST(CliDetectPose, WithoutACalibrationTheDefaultCameraIsUsedAndSaidToBeAssumed) {
  test::TempDir dir;
  render_marker(dir.str("m.png"), dir.str("cam.yml"));
  const auto r = run_arwb("detect --json --marker-size 50 " + q(dir.str("m.png")));
  ASSERT_EQ(r.status, 0) << r.err;
  Json j = parse(lines(r.out).at(0));
  ASSERT_EQ(j["markers"].size(), 1u);
  EXPECT_EQ(j["markers"][0]["pose"]["camera"], "assumed");
  const auto text = run_arwb("detect --marker-size 50 " + q(dir.str("m.png")));
  EXPECT_NE(text.out.find("[assumed camera: no --calib]"), std::string::npos) << text.out;
  // Without --marker-size there is no pose: the JSON's shape is unchanged.
  const auto plain = run_arwb("detect --json " + q(dir.str("m.png")));
  EXPECT_EQ(plain.out.find("\"pose\""), std::string::npos);
}

TEST(CliDetectPose, ABadMarkerSizeIsAUsageErrorNamingTheOption) {
  test::TempDir dir;
  render_marker(dir.str("m.png"), dir.str("cam.yml"));
  for (const char* bad : {"0", "-5", "nan", "abc"}) {
    const auto r = run_arwb("detect --marker-size " + std::string(bad) + " " + q(dir.str("m.png")));
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_NE(r.err.find("--marker-size"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

