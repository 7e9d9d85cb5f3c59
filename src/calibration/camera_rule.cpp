#include "calibration/camera_rule.hpp"

#include "base/decimals.hpp"

#include <opencv2/calib3d.hpp>

#include <cmath>
#include <cstdio>

namespace arwb {

namespace {

constexpr double kMaxPixels = 1e7;

}  // namespace

std::string camera_matrix_problem(const cv::Matx33d& k) {
  for (const auto& [name, v] : {std::pair{"fx", k(0, 0)}, std::pair{"fy", k(1, 1)}})
    if (!(v >= 1 && v <= kMaxPixels))
      return std::string("focal length ") + name + " " + general_text(v) + " is not 1 to " + general_text(kMaxPixels) + " pixels";
  for (const auto& [name, v] : {std::pair{"cx", k(0, 2)}, std::pair{"cy", k(1, 2)}, std::pair{"skew", k(0, 1)}})
    if (!(std::abs(v) <= kMaxPixels))
      return std::string(name) + " " + general_text(v) + " is not within " + general_text(kMaxPixels) + " pixels";
  return {};
}

std::string camera_picture_problem(const cv::Matx33d& k, const std::vector<double>& distortion, cv::Size size) {
  if (distortion.empty() || size.empty()) return {};
  std::vector<cv::Point2d> pixels;
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 9; ++i) pixels.emplace_back((size.width - 1) * i / 8.0, (size.height - 1) * j / 6.0);
  std::vector<cv::Point2d> undone, again;
  const cv::TermCriteria until(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-6);
  cv::undistortPoints(pixels, undone, k, distortion, cv::noArray(), cv::noArray(), until);
  std::vector<cv::Point3d> rays;
  for (const cv::Point2d& u : undone)
    rays.emplace_back(std::isfinite(u.x) && std::isfinite(u.y) ? cv::Point3d(u.x, u.y, 1.0) : cv::Point3d(0, 0, 1));
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), k, distortion, again);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const bool finite = std::isfinite(undone[i].x) && std::isfinite(undone[i].y);
    const double off = finite ? cv::norm(again[i] - pixels[i]) : NAN;
    if (off <= 1.0) continue;
    char where[64];
    std::snprintf(where, sizeof where, "(%.0f, %.0f)", pixels[i].x, pixels[i].y);
    return std::string("its distortion cannot be undone at pixel ") + where + " of a " + std::to_string(size.width) +
           "x" + std::to_string(size.height) + " picture (" +
           (std::isfinite(off) ? "undone and applied again, it lands " + general_text(off) + " px away" : "not a finite number") +
           "); calibrate again with views that reach the corners";
  }
  return {};
}

}  // namespace arwb
