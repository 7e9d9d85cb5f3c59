// Cameras at the edges of what read_calibration accepts (calibration/camera_rule.hpp), each a 640x480 calibration
// file's text: the cameras every consumer must take without crashing or printing a figure that is not a number.
#pragma once

#include "support/support.hpp"

#include <string>
#include <vector>

namespace arwb::test {

struct ExtremeCamera {
  const char* name;
  const char* matrix;       // the 9 values
  const char* distortion;   // 4, 5, 8, 12 or 14 values
};

inline const std::vector<ExtremeCamera>& extreme_cameras() {
  static const std::vector<ExtremeCamera> cameras = {
      {"focal_1px", "1, 0, 320, 0, 1, 240, 0, 0, 1", "0, 0, 0, 0, 0"},
      {"focal_1e7px", "1e7, 0, 320, 0, 1e7, 240, 0, 0, 1", "0, 0, 0, 0, 0"},
      {"pixels_1_by_1e7", "1, 0, 320, 0, 1e7, 240, 0, 0, 1", "0, 0, 0, 0"},
      {"centre_and_skew_1e7_away", "500, 1e7, 1e7, 0, 500, -1e7, 0, 0, 1", "0, 0, 0, 0, 0"},
      {"denormal_distortion", "560, 0, 322, 0, 555, 236, 0, 0, 1", "4e-320, -4e-320, 1e-310, 0, 0"},
      {"strong_14_coefficients", "560, 0, 322, 0, 555, 236, 0, 0, 1",
       "-0.3, 0.1, 0.001, -0.001, -0.02, 0.05, 0.02, -0.01, 0.001, 0, 0.001, 0, 0.01, 0.02"},
  };
  return cameras;
}

// Writes the camera as DIR/NAME.yml and returns the path.
inline std::string write_extreme_camera(const TempDir& dir, const ExtremeCamera& c) {
  // Built by appending: GCC 12 warns wrongly (-Warray-bounds) on a chain of + here.
  std::string text = "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n";
  text.append("camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ ").append(c.matrix);
  text.append(" ]\ndistortion_coefficients: [ ").append(c.distortion).append(" ]\n");
  const std::string path = dir.str(std::string(c.name) + ".yml");
  write_file(path, text);
  return path;
}

}  // namespace arwb::test
