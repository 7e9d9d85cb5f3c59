#include "lab/sensor.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace arwb::lab {

Exposure auto_exposure(const SensorModel& s, double lux) {
  Exposure e;
  const double want = s.target_level * s.full_well;           // electrons for the mid-grey card
  const double per_second = 0.18 * std::max(lux, 1e-6) * s.sensitivity;
  e.exposure_s = std::min(s.max_exposure_s, want / per_second);
  e.gain = std::clamp(want / (per_second * e.exposure_s), 1.0, s.max_gain);
  e.electrons_white = std::max(lux, 0.0) * s.sensitivity * e.exposure_s;
  return e;
}

double snr(const SensorModel& s, double lux, double reflectance) {
  const Exposure e = auto_exposure(s, lux);
  const double signal = std::min(reflectance * e.electrons_white, s.full_well);
  const double noise = std::sqrt(signal + s.read_noise * s.read_noise);
  return noise > 0 ? signal / noise : 0;
}

cv::Mat expose(const cv::Mat1f& levels, const SensorModel& s, double lux, std::mt19937& rng) {
  const Exposure e = auto_exposure(s, lux);
  // Grey levels per electron after the gain: full well at gain 1 is 255.
  const double scale = 255.0 / s.full_well * e.gain;
  cv::Mat out(levels.size(), CV_8U);
  std::normal_distribution<double> normal(0, 1);
  for (int y = 0; y < levels.rows; ++y) {
    const float* in = levels.ptr<float>(y);
    uchar* o = out.ptr<uchar>(y);
    for (int x = 0; x < levels.cols; ++x) {
      // Above 255: a glint (lighting.hpp), brighter than the paper's diffuse white; the well clips it below.
      const double electrons = std::clamp(double(in[x]) / 255.0, 0.0, 8.0) * e.electrons_white;
      // Poisson shot noise by its normal approximation (electrons in the hundreds and more), then read noise.
      const double noisy = electrons + std::sqrt(std::max(electrons, 0.0)) * normal(rng) + s.read_noise * normal(rng);
      const double clipped = std::clamp(noisy, 0.0, s.full_well);
      o[x] = cv::saturate_cast<uchar>(std::lround(clipped * scale));
    }
  }
  return out;
}

double defocus_sigma_px(const SensorModel& s, double distance_m, double focal_px) {
  // A thin lens focused at focus_m: the circle of confusion's diameter on the sensor for a point at distance_m,
  // c = A f |d - d_f| / (d (d_f - f)), A the aperture's diameter f / N. A disc of diameter c is close to a
  // Gaussian of sigma c / 2.5 for blur purposes.
  const double f = s.focal_length_mm, A = f / s.f_number;
  const double d = distance_m * 1000, df = s.focus_m * 1000;
  if (d <= f || df <= f) return 0;
  const double c_mm = A * f * std::abs(d - df) / (d * (df - f));
  const double pixel_mm = focal_px > 0 ? f / focal_px : 0;
  return pixel_mm > 0 ? c_mm / pixel_mm / 2.5 : 0;
}

double shake_length_px(const SensorModel& s, double exposure_s, double focal_px) {
  return focal_px * std::tan(s.shake_deg_s * CV_PI / 180 * exposure_s);
}

double marker_side_px(double size_mm, double distance_m, double focal_px) {
  return distance_m > 0 ? focal_px * (size_mm / 1000) / distance_m : 0;
}

SynthCamera default_lab_camera() {
  SynthCamera c;
  c.size = {640, 480};
  const double f = 320.0 / std::tan(CV_PI / 6);
  c.camera_matrix = cv::Matx33d(f, 0, 319.5, 0, f, 239.5, 0, 0, 1);
  c.distortion = {0, 0, 0, 0, 0};
  return c;
}

}  // namespace arwb::lab
