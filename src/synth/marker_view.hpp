// Synthetic views of one printed marker with a known 3D pose through a camera with lens distortion, with the
// exact image positions of its four corners: the fixture pose estimation is measured against. Rendered per
// pixel like the calibration boards (chessboard_view.hpp): each sample's ray meets the marker's plane.
#pragma once

#include "detect/quad.hpp"
#include "synth/chessboard_view.hpp"

#include <opencv2/core.hpp>

#include <string>
#include <utility>
#include <vector>

namespace arwb {

struct SynthMarker {
  std::string dictionary = "ARUCO_ORIGINAL";   // as detect's dictionary_by_name knows it
  int id = 0;
  double side_m = 0.05;       // the outer black edge's side, as printed
  double quiet_cells = 1.5;   // white paper around the black border, in cells
};

struct MarkerView {
  cv::Mat image;        // 8-bit grey
  Quad corners{};       // the outer black edge's corners (OpenCV's order: top-left, top-right, bottom-right,
                        // bottom-left of the upright marker), by projectPoints with the lens model
  bool all_inside = false;   // the marker and its quiet zone inside the image, 3 px clear of its edge
};

class MarkerRenderer {
 public:
  MarkerRenderer(SynthCamera camera, SynthMarker marker);
  // The marker in OpenCV's marker frame (pose/marker_pose.hpp: centre at the origin, x right, y up, z towards
  // the camera) placed by rvec and tvec (metres). Paper 220, ink 30, a soft grey background; blur_px > 0 a
  // Gaussian blur, noise a Gaussian noise of that standard deviation (grey levels), seeded.
  MarkerView render(const cv::Vec3d& rvec, const cv::Vec3d& tvec, double blur_px = 0, double noise = 0,
                    unsigned seed = 1) const;
  // The same picture before blur and noise, as grey levels in floats (paper 220, ink 30, the background 90 to
  // 150), with the corners and all_inside in *truth (its image left empty): what a sensor model exposes
  // (lab/sensor.hpp).
  cv::Mat1f render_levels(const cv::Vec3d& rvec, const cv::Vec3d& tvec, MarkerView* truth) const;
  // Another marker (id, size) with the same camera: the rays are kept, only the marker's cells change.
  void set_marker(const SynthMarker& marker);
  const SynthCamera& camera() const { return camera_; }
  const SynthMarker& marker() const { return marker_; }

 private:
  SynthCamera camera_;
  SynthMarker marker_;
  cv::Mat rays_;    // sample_rays(camera_)
  cv::Mat cells_;   // CV_8U, border included, 1 white
};

// `count` poses of a marker of side `side_m` at distances spread over [near_m, far_m], tilted up to
// `max_tilt_deg` about a random axis in its plane, turned in plane at random, its centre spread over the middle
// of the frame and the marker kept inside the image (the same seed, the same poses).
std::vector<std::pair<cv::Vec3d, cv::Vec3d>> marker_poses(const SynthCamera& camera, double side_m, int count,
                                                          double near_m, double far_m, double max_tilt_deg,
                                                          unsigned seed);

}  // namespace arwb
