#include "synth/marker_view.hpp"

#include "detect/dictionary.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

namespace arwb {

MarkerRenderer::MarkerRenderer(SynthCamera camera, SynthMarker marker)
    : camera_(std::move(camera)), rays_(sample_rays(camera_)) {
  set_marker(marker);
}

void MarkerRenderer::set_marker(const SynthMarker& marker) {
  marker_ = marker;
  cells_.release();
  const std::optional<Dictionary> dict = dictionary_by_name(marker_.dictionary);
  if (!dict || marker_.id < 0 || marker_.id >= dict->size()) return;   // an unknown marker renders as paper
  const int n = dict->marker_size();
  cells_ = cv::Mat::zeros(n + 2, n + 2, CV_8U);
  dict->bits(marker_.id).copyTo(cells_(cv::Rect(1, 1, n, n)));
}

MarkerView MarkerRenderer::render(const cv::Vec3d& rvec, const cv::Vec3d& tvec, double blur_px, double noise,
                                  unsigned seed) const {
  MarkerView v;
  cv::Mat1f acc = render_levels(rvec, tvec, &v);
  if (blur_px > 0) cv::GaussianBlur(acc, acc, cv::Size(), blur_px);
  if (noise > 0) {
    cv::Mat1f nz(acc.size());
    cv::RNG rng(seed);
    rng.fill(nz, cv::RNG::NORMAL, 0, noise);
    acc += nz;
  }
  acc.convertTo(v.image, CV_8U);
  return v;
}

cv::Mat1f MarkerRenderer::render_levels(const cv::Vec3d& rvec, const cv::Vec3d& tvec, MarkerView* truth) const {
  const int w = camera_.size.width, h = camera_.size.height;
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  // The plane z = 0 maps to normalised image coordinates by H = [r1 r2 t]; its inverse takes a ray back.
  const cv::Matx33d Hi =
      cv::Matx33d(R(0, 0), R(0, 1), tvec[0], R(1, 0), R(1, 1), tvec[1], R(2, 0), R(2, 1), tvec[2]).inv();
  const double L = marker_.side_m, half = L / 2;
  const int n = cells_.empty() ? 1 : cells_.rows;
  const double cell = L / n, paper = half + marker_.quiet_cells * cell;
  cv::Mat1f acc(camera_.size, 0.f);
  for (int sy = 0; sy < rays_.rows; ++sy) {
    const auto* ray = rays_.ptr<cv::Vec2f>(sy);
    float* row = acc.ptr<float>(sy / kRaySamples);
    for (int sx = 0; sx < rays_.cols; ++sx) {
      const double px = ray[sx][0], py = ray[sx][1];
      const double bw = Hi(2, 0) * px + Hi(2, 1) * py + Hi(2, 2);
      const double X = (Hi(0, 0) * px + Hi(0, 1) * py + Hi(0, 2)) / bw;
      const double Y = (Hi(1, 0) * px + Hi(1, 1) * py + Hi(1, 2)) / bw;
      float value;
      // Written so that NaN falls to the background: a ray or pose that is not a number (a camera model that
      // cannot be undone there) shows no marker instead of indexing a cell at INT_MIN.
      if (!(bw > 0) || !(std::abs(X) < paper) || !(std::abs(Y) < paper)) {
        value = float(90 + 60.0 * sx / rays_.cols);   // background (bw <= 0: the plane is behind the camera)
      } else if (std::abs(X) >= half || std::abs(Y) >= half || cells_.empty()) {
        value = 220;   // paper
      } else {
        // Columns from corner 0's side (x = -L/2), rows from the top (y = +L/2).
        const int c = std::min(n - 1, int((X + half) / cell)), r = std::min(n - 1, int((half - Y) / cell));
        value = cells_.at<uchar>(r, c) ? 220.f : 30.f;
      }
      row[sx / kRaySamples] += value;
    }
  }
  acc *= 1.0 / (kRaySamples * kRaySamples);
  MarkerView& v = *truth;
  const std::vector<cv::Point3d> obj{{-half, half, 0}, {half, half, 0}, {half, -half, 0}, {-half, -half, 0},
                                     {-paper, paper, 0}, {paper, paper, 0}, {paper, -paper, 0}, {-paper, -paper, 0}};
  std::vector<cv::Point2d> img;
  cv::projectPoints(obj, rvec, tvec, cv::Mat(camera_.camera_matrix), camera_.distortion, img);
  for (int i = 0; i < 4; ++i) v.corners[size_t(i)] = cv::Point2f(float(img[size_t(i)].x), float(img[size_t(i)].y));
  v.all_inside = true;
  for (const cv::Point2d& p : img)
    if (!(p.x >= 3 && p.y >= 3 && p.x <= w - 4 && p.y <= h - 4)) v.all_inside = false;
  for (int i = 0; i < 8; ++i) {   // and in front of the camera
    const cv::Vec3d q = R * cv::Vec3d(obj[size_t(i)].x, obj[size_t(i)].y, 0) + tvec;
    if (q[2] <= 0) v.all_inside = false;
  }
  return acc;
}

std::vector<std::pair<cv::Vec3d, cv::Vec3d>> marker_poses(const SynthCamera& camera, double side_m, int count,
                                                          double near_m, double far_m, double max_tilt_deg,
                                                          unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const double f = camera.camera_matrix(0, 0);
  std::vector<std::pair<cv::Vec3d, cv::Vec3d>> poses;
  for (int tries = 0; int(poses.size()) < count && tries < count * 200; ++tries) {
    // One draw per statement: the order of a call's arguments differs between compilers.
    const double d = near_m + (far_m - near_m) * u(rng);
    const double axis = 2 * CV_PI * u(rng);
    const double tilt = max_tilt_deg * std::sqrt(u(rng)) * CV_PI / 180;   // more poses near the limit
    const double roll = 2 * CV_PI * u(rng);
    const double sx = u(rng) - 0.5, sy = u(rng) - 0.5;
    // Facing the camera upright (x right, y up, z towards the camera) is R0 = diag(1, -1, -1); then turned by
    // `roll` about its normal and tilted by `tilt` about an axis in its plane.
    cv::Matx33d Rroll, Rtilt;
    cv::Rodrigues(cv::Vec3d(0, 0, roll), Rroll);
    cv::Rodrigues(cv::Vec3d(std::cos(axis), std::sin(axis), 0) * tilt, Rtilt);
    const cv::Matx33d R = cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1) * Rtilt * Rroll;
    cv::Vec3d rvec;
    cv::Rodrigues(R, rvec);
    const double x = sx * 0.6 * camera.size.width / f * d, y = sy * 0.6 * camera.size.height / f * d;
    const cv::Vec3d t(x, y, std::sqrt(std::max(d * d - x * x - y * y, 1e-6)));
    std::vector<cv::Point3d> obj{{-side_m * 0.7, side_m * 0.7, 0}, {side_m * 0.7, side_m * 0.7, 0},
                                 {side_m * 0.7, -side_m * 0.7, 0}, {-side_m * 0.7, -side_m * 0.7, 0}};
    std::vector<cv::Point2d> img;
    cv::projectPoints(obj, rvec, t, cv::Mat(camera.camera_matrix), camera.distortion, img);
    bool inside = true;
    for (const cv::Point2d& p : img)
      if (!(p.x >= 4 && p.y >= 4 && p.x <= camera.size.width - 5 && p.y <= camera.size.height - 5)) inside = false;
    if (inside) poses.emplace_back(rvec, t);
  }
  return poses;
}

}  // namespace arwb
