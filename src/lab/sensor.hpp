// The lab's physical camera: how a marker printed at a size in millimetres, seen at a distance in metres under
// a light in lux, becomes pixels, grey levels and noise. Every constant is in docs/lab.md with where it comes
// from; this header says what each one does.
//
// Light to grey levels (a webcam's small CMOS sensor behind auto-exposure):
//   electrons per pixel = reflectance x lux x exposure_s x sensitivity      (the scene's light on the pixel)
//   auto-exposure aims a mid-grey card (reflectance 0.18) at target_level of full scale, lengthening the
//   exposure up to max_exposure_s (the frame period at the paper's 20 fps), then raising the analogue gain up to
//   max_gain; past both the picture darkens;
//   noise: shot noise (Poisson, sqrt of the electrons), read noise in electrons, both amplified by the gain, then
//   8-bit quantisation and clipping at full well.
// Geometry: a pinhole of the camera's focal length (the calibration's, or a default webcam of 60 degrees across
// at 640x480), lens distortion as calibrated. Optics: defocus from a fixed-focus lens focused at focus_m (a thin
// lens's circle of confusion), hand-held motion blur (the camera turning at shake_deg_s during the exposure).
#pragma once

#include "synth/chessboard_view.hpp"

#include <opencv2/core.hpp>

#include <random>

namespace arwb::lab {

// A pixel's electrons per lux-second at reflectance 1, from its optics and silicon: photons of 555 nm per lux,
// second and um^2 (1 lx = 1/683 W/m^2, 3.58e-19 J a photon: 4090); a Lambertian wall's illuminance reaches the
// sensor through an f/N lens as 1 / (4 N^2) of it, times the lens's transmission; the pixel's area; the share of
// the visible light its colour filter passes; its quantum efficiency. docs/lab.md gives each value's source.
struct PixelSilicon {
  double pixel_um = 1.4;              // pitch of 1080p laptop camera modules' sensors (OmniVision OV2740's)
  double lens_transmission = 0.9;     // a few coated plastic elements
  double filter_share = 0.33;         // one of a Bayer filter's three bands
  double quantum_efficiency = 0.5;    // a small back-illuminated pixel's, averaged over its band
};
constexpr double kPhotonsPerLuxSecondUm2 = 4090;
constexpr double sensitivity_from(const PixelSilicon& p, double f_number) {
  return kPhotonsPerLuxSecondUm2 * p.pixel_um * p.pixel_um / (4 * f_number * f_number) * p.lens_transmission *
         p.filter_share * p.quantum_efficiency;
}

struct SensorModel {
  double sensitivity = sensitivity_from(PixelSilicon{}, 2.0);   // electrons per lux-second at reflectance 1 (74)
  double full_well = 6000;         // electrons at which a pixel clips
  double read_noise = 4;           // electrons RMS
  double target_level = 0.18;      // auto-exposure's aim for a reflectance-0.18 card, fraction of full scale
  double max_exposure_s = 0.05;    // the frame period at 20 fps
  double max_gain = 8;             // analogue gain at most
  double focal_length_mm = 3.7;    // the lens, for defocus
  double f_number = 2.0;
  double focus_m = 1.0;            // a fixed-focus webcam's focus distance
  double shake_deg_s = 6.0;        // hand-held: how fast the camera turns, degrees per second (RMS)
};

// What auto-exposure chose for a light level.
struct Exposure {
  double exposure_s = 0;
  double gain = 1;
  double electrons_white = 0;   // electrons a reflectance-1 surface gives (before clipping)
};
Exposure auto_exposure(const SensorModel& s, double lux);

// The signal-to-noise ratio of a surface of reflectance `r` (mean grey level over its noise) under `lux`.
double snr(const SensorModel& s, double lux, double reflectance);

// Grey levels 0..255 as rendered (synth/marker_view.hpp: level / 255 is the reflectance) to the sensor's 8-bit
// picture under `lux`, with shot and read noise drawn from `rng`.
cv::Mat expose(const cv::Mat1f& levels, const SensorModel& s, double lux, std::mt19937& rng);

// Blur radii in pixels (Gaussian sigma) of defocus at `distance_m` (the pixel pitch is the focal length over
// focal_px), and the length in pixels of the motion
// streak a hand-held camera draws during `exposure_s` for a focal length of `focal_px` pixels (its RMS).
double defocus_sigma_px(const SensorModel& s, double distance_m, double focal_px);
double shake_length_px(const SensorModel& s, double exposure_s, double focal_px);

// A marker's side in pixels at the image's centre: size_mm at distance_m through focal length focal_px.
double marker_side_px(double size_mm, double distance_m, double focal_px);

// The default webcam when there is no calibration: 640x480, 60 degrees across, no distortion (the paper's
// default values, pose/marker_pose.hpp's default_calibration).
SynthCamera default_lab_camera();

}  // namespace arwb::lab
