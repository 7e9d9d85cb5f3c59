#include "pose/marker_pose.hpp"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace arwb {

namespace {

constexpr double kDeg = 180.0 / CV_PI;

std::vector<cv::Point3d> object_vector(double side) {
  const auto a = marker_object_points(side);
  return {a.begin(), a.end()};
}

double rms_error(const std::vector<cv::Point3d>& obj, const std::vector<cv::Point2d>& img, const PoseSolution& s,
                 const Calibration& cam) {
  std::vector<cv::Point2d> proj;
  cv::projectPoints(obj, s.rvec, s.tvec, cv::Mat(cam.camera_matrix), cam.distortion, proj);
  double sum = 0;
  for (size_t i = 0; i < img.size(); ++i) sum += (proj[i].x - img[i].x) * (proj[i].x - img[i].x) +
                                                 (proj[i].y - img[i].y) * (proj[i].y - img[i].y);
  return std::sqrt(sum / double(img.size()));
}

bool finite(const PoseSolution& s) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(s.rvec[i]) || !std::isfinite(s.tvec[i])) return false;
  return std::isfinite(s.error_px);
}

}  // namespace

Calibration default_calibration(cv::Size image_size) {
  Calibration c;
  const double w = image_size.width, h = image_size.height;
  const double f = (w / 2) / std::tan(kDefaultHorizontalFovDeg / 2 / kDeg);
  c.camera_matrix = cv::Matx33d(f, 0, (w - 1) / 2, 0, f, (h - 1) / 2, 0, 0, 1);
  c.distortion.assign(5, 0.0);
  c.image_size = image_size;
  c.source = "default camera (60 degrees across, no distortion)";
  c.assumed = true;
  return c;
}

std::array<cv::Point3d, 4> marker_object_points(double side) {
  const double h = side / 2;
  return {cv::Point3d(-h, h, 0), cv::Point3d(h, h, 0), cv::Point3d(h, -h, 0), cv::Point3d(-h, -h, 0)};
}

std::optional<MarkerPose> estimate_marker_pose(const Quad& corners, double side, const Calibration& camera) {
  if (!(side > 0) || !std::isfinite(side)) return std::nullopt;
  std::vector<cv::Point2d> img;
  for (const cv::Point2f& c : corners) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y)) return std::nullopt;
    img.emplace_back(c.x, c.y);
  }
  // A quad of (nearly) no area has no pose.
  double area2 = 0;
  for (size_t i = 0; i < 4; ++i) area2 += img[i].x * img[(i + 1) % 4].y - img[(i + 1) % 4].x * img[i].y;
  if (std::abs(area2) < 1e-6) return std::nullopt;
  const std::vector<cv::Point3d> obj = object_vector(side);
  const cv::Mat K(camera.camera_matrix);
  std::vector<cv::Mat> rvecs, tvecs;
  try {
    cv::solvePnPGeneric(obj, img, K, camera.distortion, rvecs, tvecs, false, cv::SOLVEPNP_IPPE_SQUARE);
  } catch (const cv::Exception&) {
    return std::nullopt;
  }
  // OpenCV 4.6's IPPE fails near a marker seen exactly from the front, where its two solutions coincide: it
  // gives the identity or NaN. SQPnP's global minimum is then that one pose.
  const auto usable = [](const cv::Mat& m) { return cv::checkRange(m) && cv::norm(m) > 1e-12; };
  bool ippe_ok = !rvecs.empty();
  for (size_t i = 0; i < rvecs.size(); ++i) ippe_ok = ippe_ok && usable(rvecs[i]) && cv::checkRange(tvecs[i]);
  if (!ippe_ok) {
    try {
      cv::Mat rv, tv;
      cv::solvePnP(obj, img, K, camera.distortion, rv, tv, false, cv::SOLVEPNP_SQPNP);
      rvecs = {rv.clone(), rv.clone()};
      tvecs = {tv.clone(), tv.clone()};
    } catch (const cv::Exception&) {
      return std::nullopt;
    }
  }
  std::vector<PoseSolution> sols;
  for (size_t i = 0; i < rvecs.size() && i < 2; ++i) {
    PoseSolution s;
    s.rvec = cv::Vec3d(rvecs[i].reshape(1, 3));
    s.tvec = cv::Vec3d(tvecs[i].reshape(1, 3));
    s.error_px = rms_error(obj, img, s, camera);
    // Refined on the four corners through the lens model; kept only when it lowers the error and stays in its
    // own basin (LM from one solution can slide to the other when they are close, and the pair would be one).
    PoseSolution r = s;
    try {
      cv::Mat rv(r.rvec), tv(r.tvec);
      cv::solvePnPRefineLM(obj, img, K, camera.distortion, rv, tv,
                           cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 1e-12));
      r.rvec = cv::Vec3d(rv.reshape(1, 3));
      r.tvec = cv::Vec3d(tv.reshape(1, 3));
      r.error_px = rms_error(obj, img, r, camera);
    } catch (const cv::Exception&) {
      r = s;
    }
    if (finite(r) && r.error_px <= s.error_px && r.tvec[2] > 0) s = r;
    if (finite(s)) sols.push_back(s);
  }
  if (sols.empty()) return std::nullopt;
  if (sols.size() == 2 && rotation_difference_deg(sols[0].rvec, sols[1].rvec) < 0.5) {
    // The refinement joined them: the unrefined second solution is the alternative.
    PoseSolution s;
    s.rvec = cv::Vec3d(rvecs[1].reshape(1, 3));
    s.tvec = cv::Vec3d(tvecs[1].reshape(1, 3));
    s.error_px = rms_error(obj, img, s, camera);
    if (finite(s)) sols[1] = s;
  }
  std::sort(sols.begin(), sols.end(), [](const PoseSolution& a, const PoseSolution& b) { return a.error_px < b.error_px; });
  MarkerPose p;
  p.pose = sols[0];
  p.alternative = sols.size() > 1 ? sols[1] : sols[0];
  p.ambiguity = p.alternative.error_px > 0 ? std::clamp(p.pose.error_px / p.alternative.error_px, 0.0, 1.0) : 1.0;
  p.assumed_camera = camera.assumed;
  return p;
}

double rotation_difference_deg(const cv::Vec3d& rvec_a, const cv::Vec3d& rvec_b) {
  cv::Matx33d A, B;
  cv::Rodrigues(rvec_a, A);
  cv::Rodrigues(rvec_b, B);
  const cv::Matx33d D = A.t() * B;
  const double c = std::clamp((cv::trace(D) - 1) / 2, -1.0, 1.0);
  return std::acos(c) * kDeg;
}

MarkerPose resolve_with_previous(const MarkerPose& p, const cv::Vec3d& previous_rvec, double min_ambiguity) {
  MarkerPose out = p;
  if (p.ambiguity < min_ambiguity) return out;
  const PoseSolution& lower = p.chosen_by_previous ? p.alternative : p.pose;
  const PoseSolution& higher = p.chosen_by_previous ? p.pose : p.alternative;
  const bool take_higher =
      rotation_difference_deg(higher.rvec, previous_rvec) < rotation_difference_deg(lower.rvec, previous_rvec);
  out.pose = take_higher ? higher : lower;
  out.alternative = take_higher ? lower : higher;
  out.chosen_by_previous = take_higher;
  return out;
}

PoseAngles pose_angles(const PoseSolution& p) {
  PoseAngles a;
  a.distance = cv::norm(p.tvec);
  cv::Matx33d R;
  cv::Rodrigues(p.rvec, R);
  const cv::Vec3d normal(R(0, 2), R(1, 2), R(2, 2));
  if (a.distance > 0) a.tilt_deg = std::acos(std::clamp(-normal.dot(p.tvec) / a.distance, -1.0, 1.0)) * kDeg;
  // F = R0^T R, R0 the upright marker facing the camera (x, -y, -z); F = Ry(yaw) Rx(pitch) Rz(roll).
  const cv::Matx33d F = cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1) * R;
  a.pitch_deg = std::asin(std::clamp(-F(1, 2), -1.0, 1.0)) * kDeg;
  a.yaw_deg = std::atan2(F(0, 2), F(2, 2)) * kDeg;
  a.roll_deg = std::atan2(F(1, 0), F(1, 1)) * kDeg;
  return a;
}

std::vector<cv::Point2d> project_marker_points(const std::vector<cv::Point3d>& points, const PoseSolution& p,
                                               const Calibration& camera) {
  std::vector<cv::Point2d> out;
  if (points.empty()) return out;
  cv::projectPoints(points, p.rvec, p.tvec, cv::Mat(camera.camera_matrix), camera.distortion, out);
  return out;
}

}  // namespace arwb
