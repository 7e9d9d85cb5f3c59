// Pose against known truth: exact corners through a distorting lens give the pose back; markers rendered with a
// known pose and found by our detector give it within a degree or two; the ambiguity of a frontal marker is seen
// and the previous pose resolves it; bad input gives no pose.
#include "detect/detector.hpp"
#include "pose/marker_pose.hpp"
#include "synth/marker_view.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>

namespace arwb {
namespace {

const SynthCamera kCamera;   // 640x480 with a webcam's barrel distortion

Calibration camera_of(const SynthCamera& c) {
  Calibration cal;
  cal.camera_matrix = c.camera_matrix;
  cal.distortion = c.distortion;
  cal.image_size = c.size;
  return cal;
}

Quad projected(const cv::Vec3d& rvec, const cv::Vec3d& tvec, double side, const Calibration& cam) {
  const auto obj = marker_object_points(side);
  const std::vector<cv::Point2d> img = project_marker_points({obj.begin(), obj.end()}, {rvec, tvec, 0}, cam);
  Quad q;
  for (size_t i = 0; i < 4; ++i) q[i] = cv::Point2f(float(img[i].x), float(img[i].y));
  return q;
}

TEST(DefaultCamera, IsSixtyDegreesAcrossCentredAndWithoutDistortion) {
  const Calibration c = default_calibration({640, 480});
  EXPECT_TRUE(c.assumed);
  EXPECT_NEAR(c.camera_matrix(0, 0), 320 / std::tan(CV_PI / 6), 1e-9);
  EXPECT_EQ(c.camera_matrix(0, 0), c.camera_matrix(1, 1));
  EXPECT_EQ(c.camera_matrix(0, 2), 319.5);
  EXPECT_EQ(c.camera_matrix(1, 2), 239.5);
  for (double d : c.distortion) EXPECT_EQ(d, 0);
  // A marker straight ahead at 10 sides' distance: 554 px of focal length make its side 55 px.
  const Quad q = projected(cv::Vec3d(CV_PI, 0, 0), cv::Vec3d(0, 0, 10), 1, c);
  EXPECT_NEAR(cv::norm(q[1] - q[0]), 55.4, 0.1);
  const auto p = estimate_marker_pose(q, 1, c);
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->assumed_camera);
}

TEST(MarkerPose, ExactCornersThroughTheLensGiveThePoseBack) {
  const Calibration cam = camera_of(kCamera);
  const auto poses = marker_poses(kCamera, 0.05, 40, 0.25, 1.5, 60, 3);
  ASSERT_EQ(poses.size(), 40u);
  int clear = 0;
  for (const auto& [rv, tv] : poses) {
    const auto p = estimate_marker_pose(projected(rv, tv, 0.05, cam), 0.05, cam);
    ASSERT_TRUE(p);
    EXPECT_LT(p->pose.error_px, 1e-3);
    EXPECT_LT(rotation_difference_deg(p->pose.rvec, rv), 0.01);
    EXPECT_LT(cv::norm(p->pose.tvec - tv), 1e-5 * cv::norm(tv));
    EXPECT_GE(p->alternative.error_px, p->pose.error_px);
    EXPECT_FALSE(p->assumed_camera);
    clear += p->ambiguity < 0.1;
  }
  EXPECT_GT(clear, 30) << "exact corners should leave few poses ambiguous";
}

TEST(MarkerPose, IgnoringTheLensWouldBeWrong) {
  // The same corners with the distortion dropped give another pose: the model is used, not just the matrix.
  const Calibration cam = camera_of(kCamera);
  Calibration pinhole = cam;
  pinhole.distortion.clear();
  const cv::Vec3d rv(2.9, 0.3, 0.2), tv(0.22, 0.15, 0.5);   // near the image's corner, where the barrel bends most
  const Quad q = projected(rv, tv, 0.05, cam);
  const auto with = estimate_marker_pose(q, 0.05, cam), without = estimate_marker_pose(q, 0.05, pinhole);
  ASSERT_TRUE(with && without);
  EXPECT_LT(cv::norm(with->pose.tvec - tv), 1e-6);
  EXPECT_GT(cv::norm(without->pose.tvec - tv), 0.01);
}

TEST(MarkerPose, RenderedMarkersFoundByOurDetectorGiveTheirPose) {
  const Calibration cam = camera_of(kCamera);
  const SynthMarker marker{.dictionary = "ARUCO_ORIGINAL", .id = 7, .side_m = 0.05};
  const MarkerRenderer renderer(kCamera, marker);
  const Detector detector({*dictionary_by_name("ARUCO_ORIGINAL")});
  std::vector<double> rot, trans;
  for (const auto& [rv, tv] : marker_poses(kCamera, 0.05, 24, 0.25, 0.8, 50, 11)) {
    const MarkerView view = renderer.render(rv, tv, 0.5, 1.0, 5);
    ASSERT_TRUE(view.all_inside);
    const auto found = detector.detect(view.image);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0].id, 7);
    const auto p = estimate_marker_pose(found[0].corners, 0.05, cam);
    ASSERT_TRUE(p);
    rot.push_back(rotation_difference_deg(p->pose.rvec, rv));
    trans.push_back(cv::norm(p->pose.tvec - tv) / cv::norm(tv));
  }
  std::sort(rot.begin(), rot.end());
  std::sort(trans.begin(), trans.end());
  EXPECT_LT(rot[rot.size() / 2], 1.5) << "median rotation error in degrees";
  EXPECT_LT(trans[trans.size() / 2], 0.01) << "median translation error relative to the distance";
}

TEST(MarkerPose, AFrontalMarkerIsAmbiguousAndThePreviousPoseDecides) {
  const Calibration cam = camera_of(kCamera);
  // Tilted 5 degrees from facing the camera, 47 px across: corner noise of a tenth of a pixel makes the tilt's
  // sign unsure, and the lower-error solution is often the mirrored one.
  cv::Matx33d Rt;
  cv::Rodrigues(cv::Vec3d(0.07, 0.05, 0), Rt);
  cv::Vec3d rv;
  cv::Rodrigues(cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1) * Rt, rv);
  const cv::Vec3d tv(0.01, 0.0, 0.6);
  const Quad exact = projected(rv, tv, 0.05, cam);
  cv::RNG rng(4);
  int ambiguous = 0, resolved = 0, wrong_alone = 0;
  const auto nearer_truth = [&](const PoseSolution& a, const PoseSolution& b) {
    return rotation_difference_deg(a.rvec, rv) < rotation_difference_deg(b.rvec, rv);
  };
  for (int k = 0; k < 60; ++k) {
    Quad q = exact;
    for (auto& c : q) {
      const float dx = float(rng.gaussian(0.1)), dy = float(rng.gaussian(0.1));
      c += cv::Point2f(dx, dy);
    }
    const auto p = estimate_marker_pose(q, 0.05, cam);
    ASSERT_TRUE(p);
    if (p->ambiguity < 0.3) continue;
    ++ambiguous;
    wrong_alone += !nearer_truth(p->pose, p->alternative);
    // The previous frame's pose (here the truth) chooses the solution nearer it.
    const MarkerPose r = resolve_with_previous(*p, rv);
    resolved += nearer_truth(r.pose, r.alternative);
    EXPECT_EQ(r.chosen_by_previous, !nearer_truth(p->pose, p->alternative));
    EXPECT_LT(rotation_difference_deg(r.pose.rvec, rv), 6);
  }
  EXPECT_GT(ambiguous, 10);
  EXPECT_GT(wrong_alone, 0) << "no flips: the case does not show the ambiguity";
  EXPECT_EQ(resolved, ambiguous);
}

TEST(MarkerPose, AClearViewIsNotOverruledByThePreviousPose) {
  const Calibration cam = camera_of(kCamera);
  const cv::Vec3d rv(2.6, 0.6, 0.1), tv(0.0, 0.02, 0.3);
  const auto p = estimate_marker_pose(projected(rv, tv, 0.05, cam), 0.05, cam);
  ASSERT_TRUE(p);
  ASSERT_LT(p->ambiguity, 0.3);
  const MarkerPose r = resolve_with_previous(*p, p->alternative.rvec);
  EXPECT_FALSE(r.chosen_by_previous);
  EXPECT_LT(rotation_difference_deg(r.pose.rvec, rv), 0.01);
}

TEST(PoseAngles, UprightFacingIsZeroAndTurnsReadAsTheyAre) {
  const auto at = [](cv::Vec3d turn) {   // the upright facing marker turned by `turn` in the viewer's frame
    cv::Matx33d T;
    cv::Rodrigues(turn, T);
    cv::Vec3d rv;
    cv::Rodrigues(cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1) * T, rv);
    return pose_angles({rv, cv::Vec3d(0, 0, 2), 0});
  };
  const PoseAngles a = at({0, 0, 0});
  EXPECT_NEAR(a.distance, 2, 1e-12);
  EXPECT_NEAR(a.tilt_deg, 0, 1e-6);
  EXPECT_NEAR(a.yaw_deg, 0, 1e-6);
  EXPECT_NEAR(a.pitch_deg, 0, 1e-6);
  EXPECT_NEAR(a.roll_deg, 0, 1e-6);
  const PoseAngles yaw = at({0, 30 * CV_PI / 180, 0});
  EXPECT_NEAR(yaw.yaw_deg, 30, 1e-6);
  EXPECT_NEAR(yaw.tilt_deg, 30, 1e-6);
  EXPECT_NEAR(at({-20 * CV_PI / 180, 0, 0}).pitch_deg, -20, 1e-6);
  EXPECT_NEAR(at({0, 0, 45 * CV_PI / 180}).roll_deg, 45, 1e-6);
}

TEST(MarkerPose, BadInputGivesNoPose) {
  const Calibration cam = camera_of(kCamera);
  const Quad good = projected(cv::Vec3d(CV_PI, 0, 0), cv::Vec3d(0, 0, 0.5), 0.05, cam);
  EXPECT_FALSE(estimate_marker_pose(good, 0, cam));
  EXPECT_FALSE(estimate_marker_pose(good, -1, cam));
  EXPECT_FALSE(estimate_marker_pose(good, std::nan(""), cam));
  Quad flat{cv::Point2f(10, 10), cv::Point2f(20, 10), cv::Point2f(30, 10), cv::Point2f(40, 10)};
  EXPECT_FALSE(estimate_marker_pose(flat, 0.05, cam));
  Quad nan = good;
  nan[2].x = std::nanf("");
  EXPECT_FALSE(estimate_marker_pose(nan, 0.05, cam));
}

}  // namespace
}  // namespace arwb
