#include "render/mesh_uniforms.hpp"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>

namespace arwb::render {

namespace {

double radial_factor(const std::vector<double>& d, double r2) {
  auto k = [&](size_t i) { return i < d.size() ? d[i] : 0.0; };
  const double r4 = r2 * r2, r6 = r4 * r2;
  return (1 + k(0) * r2 + k(1) * r4 + k(4) * r6) / (1 + k(5) * r2 + k(6) * r4 + k(7) * r6);
}

}  // namespace

double distortion_r2_limit(const cv::Matx33d& K, const std::vector<double>& dist, cv::Size frame) {
  // The image's farthest corner in normalised coordinates, without distortion.
  double rmax = 0;
  const double fx = K(0, 0) > 0 ? K(0, 0) : 1, fy = K(1, 1) > 0 ? K(1, 1) : 1;
  for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(frame.width, 0), cv::Point2d(frame.width, frame.height),
                              cv::Point2d(0, frame.height)})
    rmax = std::max(rmax, std::hypot((p.x - K(0, 2)) / fx, (p.y - K(1, 2)) / fy));
  bool any = false;
  for (const double v : dist) any = any || v != 0;
  if (any && dist.size() >= 4) {
    try {
      std::vector<cv::Point2d> in, out;
      for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(frame.width, 0),
                                  cv::Point2d(frame.width, frame.height), cv::Point2d(0, frame.height)})
        in.push_back(p);
      cv::undistortPoints(in, out, K, dist);
      for (const cv::Point2d& p : out)
        if (std::isfinite(p.x) && std::isfinite(p.y)) rmax = std::max(rmax, std::hypot(p.x, p.y));
    } catch (const cv::Exception&) {
      // The pinhole's corners stand.
    }
  }
  const double cap = 2 * std::max(rmax, 0.1);
  if (!any) return cap * cap;
  // r * radial(r^2) must keep growing: stop before it turns.
  constexpr int kSteps = 4000;
  double prev = 0;
  for (int i = 1; i <= kSteps; ++i) {
    const double r = cap * i / kSteps, v = r * radial_factor(dist, r * r);
    if (!(v > prev) || !std::isfinite(v)) {
      const double rr = cap * (i - 1) / kSteps;
      return std::max(rr * rr, 1e-6);
    }
    prev = v;
  }
  return cap * cap;
}

MeshUniforms mesh_uniforms(const SolidDraw& s, cv::Size frame) {
  cv::Matx33d R;
  cv::Rodrigues(s.rvec, R);
  const cv::Matx44d pose(R(0, 0), R(0, 1), R(0, 2), s.tvec[0], R(1, 0), R(1, 1), R(1, 2), s.tvec[1], R(2, 0),
                         R(2, 1), R(2, 2), s.tvec[2], 0, 0, 0, 1);
  const cv::Matx44d mv = pose * s.mesh_to_marker;
  const cv::Matx33d nm = mv.get_minor<3, 3>(0, 0).inv().t();
  MeshUniforms u;
  for (int i = 0; i < 16; ++i) u.model_view[size_t(i)] = static_cast<float>(mv.val[i]);
  for (int i = 0; i < 9; ++i) u.normal_matrix[size_t(i)] = static_cast<float>(nm.val[i]);
  auto k = [&](size_t i) { return static_cast<float>(i < s.distortion.size() ? s.distortion[i] : 0.0); };
  const cv::Matx33d& K = s.camera_matrix;
  u.intrinsics = {float(K(0, 0)), float(K(1, 1)), float(K(0, 2)), float(K(1, 2))};
  u.skew = float(K(0, 1));
  u.knum = {k(0), k(1), k(4)};
  u.kden = {k(5), k(6), k(7)};
  u.tangential = {k(2), k(3)};
  u.r2_max = float(distortion_r2_limit(K, s.distortion, frame));
  u.size = {float(frame.width), float(frame.height)};
  const double n = kMeshNear, f = kMeshFar;
  u.depth = {float((f + n) / (f - n)), float(-2 * f * n / (f - n))};
  return u;
}

std::array<float, 4> part_colour(const MeshPart& part, double opacity) {
  const cv::Scalar& c = part.colour;
  return {float(c[2] / 255), float(c[1] / 255), float(c[0] / 255), float(c[3] / 255 * opacity)};
}

std::vector<float> interleaved_vertices(const MeshPart& part) {
  const size_t n = part.positions.size();
  const bool normals = part.normals.size() == n, uvs = part.uvs.size() == n;
  std::vector<float> v;
  v.reserve(n * 8);
  for (size_t i = 0; i < n; ++i) {
    const cv::Vec3f& p = part.positions[i];
    const cv::Vec3f nr = normals ? part.normals[i] : cv::Vec3f(0, 0, 0);
    const cv::Vec2f t = uvs ? part.uvs[i] : cv::Vec2f(0, 0);
    v.insert(v.end(), {p[0], p[1], p[2], nr[0], nr[1], nr[2], t[0], t[1]});
  }
  return v;
}

}  // namespace arwb::render
