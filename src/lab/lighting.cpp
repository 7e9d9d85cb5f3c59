#include "lab/lighting.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace arwb::lab {

double direct_share(const SceneLight& light, double lux) {
  return lux >= 1000 ? light.direct_outdoor : lux >= 850 ? light.direct_indoor : light.direct_evening;
}

std::string LightEvents::text() const {
  if (shadow && glare) return "a shadow edge and a glint across the marker";
  if (shadow) return "a shadow edge across the marker";
  if (glare) return "a glint on the marker";
  return {};
}

double shadow_edge_chance(const SceneLight& light, double side_m, double distance_m) {
  if (light.shadow_chance >= 0) return light.shadow_chance;
  const double d = std::max(distance_m, 1e-3), w = light.body_width_m;
  return std::min(1.0, 2 * side_m * d / (CV_PI * (d * d + w * w / 4)));
}

double glint_chance(const SceneLight& light) {
  if (light.glare_chance >= 0) return light.glare_chance;
  return 1 - std::cos(light.glare_lobe_deg * CV_PI / 180);
}

LightEvents apply_scene_light(cv::Mat1f& levels, const SceneLight& light, double distance_m, double lux,
                              double focal_px, const Quad& corners, std::mt19937& rng) {
  LightEvents ev;
  const double direct = std::clamp(direct_share(light, lux), 0.0, 1.0);
  std::uniform_real_distribution<double> u(0, 1);
  // The draws are made whatever happens, so a frame's events do not depend on the constants' values.
  const double shadow_draw = u(rng), glare_draw = u(rng);
  const double edge_angle = u(rng) * 2 * CV_PI, edge_at = u(rng), glint_x = u(rng), glint_y = u(rng);
  if (direct <= 0 || distance_m <= 0) return ev;
  cv::Point2f lo = corners[0], hi = corners[0];
  for (const cv::Point2f& c : corners) {
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y)};
    hi = {std::max(hi.x, c.x), std::max(hi.y, c.y)};
  }
  const cv::Point2d centre((lo.x + hi.x) / 2, (lo.y + hi.y) / 2);
  const double half = std::max(hi.x - lo.x, hi.y - lo.y) / 2;

  // The marker's side in metres from its image: 2 x half x distance / f.
  ev.shadow = shadow_draw < shadow_edge_chance(light, 2 * half * distance_m / focal_px, distance_m);
  if (ev.shadow) {
    // A straight edge through the marker's middle half, the side beyond it in shadow, a linear penumbra.
    const cv::Point2d n(std::cos(edge_angle), std::sin(edge_angle));
    const double offset = (edge_at - 0.5) * half;   // the edge's signed distance from the centre
    const double penumbra = std::max(1.0, focal_px * light.sun_diameter_rad);
    const float dark = float(1 - direct);
    for (int y = 0; y < levels.rows; ++y) {
      float* row = levels.ptr<float>(y);
      for (int x = 0; x < levels.cols; ++x) {
        const double s = (x - centre.x) * n.x + (y - centre.y) * n.y - offset;   // > 0: in the shadow
        const double t = std::clamp(s / penumbra + 0.5, 0.0, 1.0);
        row[x] *= float(1 - t) + dark * float(t);
      }
    }
  }
  ev.glare = glare_draw < glint_chance(light);
  if (ev.glare) {
    // A Gaussian lobe centred somewhere on the marker; its radius in pixels is f tan(lobe) at any distance.
    const cv::Point2d at(lo.x + glint_x * (hi.x - lo.x), lo.y + glint_y * (hi.y - lo.y));
    const double sigma = std::max(1.0, focal_px * std::tan(light.glare_lobe_deg * CV_PI / 180) / 2);
    const double peak = light.glare_peak * 255 * direct;
    const int r = int(std::ceil(3 * sigma));
    const int x0 = std::max(0, int(at.x) - r), x1 = std::min(levels.cols - 1, int(at.x) + r);
    const int y0 = std::max(0, int(at.y) - r), y1 = std::min(levels.rows - 1, int(at.y) + r);
    for (int y = y0; y <= y1; ++y) {
      float* row = levels.ptr<float>(y);
      for (int x = x0; x <= x1; ++x) {
        const double d2 = (x - at.x) * (x - at.x) + (y - at.y) * (y - at.y);
        row[x] += float(peak * std::exp(-d2 / (2 * sigma * sigma)));
      }
    }
  }
  return ev;
}

}  // namespace arwb::lab
