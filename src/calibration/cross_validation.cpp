#include "calibration/cross_validation.hpp"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace arwb {

namespace {

// Unit rays of `pixels` through calibration `c`; a ray whose reprojection misses its pixel by more than a tenth of
// a pixel (the iterative undistortion did not converge: the model folds over there) is left as (0, 0, 0).
std::vector<cv::Vec3d> unproject(const Calibration& c, const std::vector<cv::Point2d>& pixels) {
  const cv::Mat K(c.camera_matrix), D(c.distortion);
  std::vector<cv::Point2d> normal;
  cv::undistortPoints(pixels, normal, K, D, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-10));
  std::vector<cv::Point3d> points;
  for (const cv::Point2d& n : normal) points.emplace_back(n.x, n.y, 1.0);
  std::vector<cv::Point2d> back;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, back);
  std::vector<cv::Vec3d> rays(pixels.size(), cv::Vec3d(0, 0, 0));
  for (size_t i = 0; i < pixels.size(); ++i)
    if (cv::norm(back[i] - pixels[i]) < 0.1 && std::isfinite(normal[i].x) && std::isfinite(normal[i].y))
      rays[i] = cv::normalize(cv::Vec3d(normal[i].x, normal[i].y, 1.0));
  return rays;
}

// The rotation R that best turns the rays `from` onto `to` (least squares, Kabsch): the relative orientation of
// two cameras that are the same camera.
cv::Matx33d fit_rotation(const std::vector<cv::Vec3d>& from, const std::vector<cv::Vec3d>& to) {
  cv::Matx33d H = cv::Matx33d::zeros();
  for (size_t i = 0; i < from.size(); ++i) H += from[i] * to[i].t();
  cv::Mat w, u, vt;
  cv::SVDecomp(cv::Mat(H), w, u, vt);
  cv::Matx33d V = cv::Matx33d(cv::Mat(vt.t())), U = cv::Matx33d(u);
  const double d = cv::determinant(V * U.t()) < 0 ? -1 : 1;
  return V * cv::Matx33d(1, 0, 0, 0, 1, 0, 0, 0, d) * U.t();
}

}  // namespace

ProjectionDiff projection_diff(const Calibration& a, const Calibration& b, cv::Size size, int cols, int rows) {
  ProjectionDiff out;
  cols = std::max(cols, 1), rows = std::max(rows, 1);
  out.diff = cv::Mat1f(rows, cols, std::numeric_limits<float>::quiet_NaN());
  std::vector<cv::Point2d> pixels;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      pixels.emplace_back((c + 0.5) * size.width / cols - 0.5, (r + 0.5) * size.height / rows - 0.5);
  const std::vector<cv::Vec3d> ra = unproject(a, pixels), rb = unproject(b, pixels);

  const cv::Point2d centre((size.width - 1) / 2.0, (size.height - 1) / 2.0);
  const double focus = std::min(size.width, size.height) / 6.0;
  std::vector<cv::Vec3d> from, to, all_from, all_to;
  for (size_t i = 0; i < pixels.size(); ++i) {
    if (ra[i] == cv::Vec3d() || rb[i] == cv::Vec3d()) continue;
    all_from.push_back(ra[i]), all_to.push_back(rb[i]);
    if (cv::norm(pixels[i] - centre) <= focus) from.push_back(ra[i]), to.push_back(rb[i]);
  }
  if (from.size() < 8) from = all_from, to = all_to;
  if (from.size() < 3) return out;   // nothing either calibration can unproject: every cell stays NaN
  const cv::Matx33d R = fit_rotation(from, to);

  std::vector<cv::Point3d> turned;
  std::vector<size_t> cell;
  for (size_t i = 0; i < pixels.size(); ++i) {
    if (ra[i] == cv::Vec3d()) continue;
    const cv::Vec3d t = R * ra[i];
    if (t[2] <= 1e-6) continue;   // turned behind b's camera: no projection
    turned.emplace_back(t[0], t[1], t[2]);
    cell.push_back(i);
  }
  if (turned.empty()) return out;
  std::vector<cv::Point2d> projected;
  cv::projectPoints(turned, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cv::Mat(b.camera_matrix), cv::Mat(b.distortion),
                    projected);
  std::vector<double> values;
  for (size_t k = 0; k < cell.size(); ++k) {
    const double d = cv::norm(projected[k] - pixels[cell[k]]);
    if (!std::isfinite(d)) continue;
    out.diff(int(cell[k]) / cols, int(cell[k]) % cols) = float(d);
    values.push_back(d);
  }
  if (values.empty()) return out;
  out.max_px = *std::max_element(values.begin(), values.end());
  std::nth_element(values.begin(), values.begin() + long(values.size() / 2), values.end());
  out.median_px = values[values.size() / 2];
  return out;
}

}  // namespace arwb
