// Calibration files: the one reader used everywhere (detection, the workbench, rendering) and the writer.
//
// The reader accepts the key names in use: OpenCV's samples (camera_matrix, distortion_coefficients), its
// interactive-calibration app (cameraMatrix, dist_coeffs), the paper (cameraMatrix, distCoeffs; also as its two
// files cameraMatrix.xml and distCoeffs.xml) and ROS's ost.yaml (camera_matrix: {rows, cols, data},
// distortion_coefficients, distortion_model plumb_bob). XML or YAML, told from the text. A file is read through
// base/files' checks (regular file, 1 MiB, UTF-8); YAML goes through detect/yaml_file's guards and XML through a
// nesting check of ours, as OpenCV's parser recurses without limit and cannot be interrupted.
#pragma once

#include "base/files.hpp"
#include "base/result.hpp"
#include "calibration/camera_rule.hpp"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace arwb {

inline constexpr FileLimit kCalibrationFile{"a calibration file", std::uintmax_t{1} << 20};

struct Calibration {
  cv::Matx33d camera_matrix = cv::Matx33d::eye();
  std::vector<double> distortion;   // k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tx ty]]]]: 4, 5, 8, 12 or 14 values
  cv::Size image_size;              // 0x0 when the file does not say
  std::string source;               // the file (or files) read, for messages
  bool assumed = false;             // not measured: default values (pose/marker_pose.hpp's default_calibration)
};

// Reads a calibration. Every failure is one line naming the file and, where it is about a value, the key:
// "cam.yml: camera_matrix: expected 3x3 values, found 2x3", "cam.yml: distortion_coefficients: value 3 is not a
// finite number", "cam.yml: camera_matrix: focal length fy -500 is not 1 to 1e+07 pixels", "cam.yml: no camera matrix
// (looked for camera_matrix, cameraMatrix)". The paper's cameraMatrix.xml, which has no distortion, is completed
// from the distCoeffs.xml beside it.
Result<Calibration> read_calibration(const std::string& path);
// The paper's two files named separately.
Result<Calibration> read_calibration_pair(const std::string& camera_matrix_path, const std::string& dist_coeffs_path);

// The calibration for a source of `size`: unchanged when the file gives no size or the same one; scaled when the
// aspect ratio is the same (a 1280x720 calibration used at 640x360); refused otherwise ("cam.yml: made for
// 640x480 (4:3), the source is 1280x720 (16:9); calibrate at this size"). The result keeps to camera_rule.hpp's
// rule at that size, or is refused with its reason ("cam.yml: its distortion cannot be undone at pixel ...").
Result<Calibration> calibration_for_size(const Calibration& c, cv::Size size);

// What is written beside the camera and its distortion.
struct CalibrationFileExtras {
  double avg_reprojection_error = 0;
  std::vector<double> per_view_reprojection_errors;
  std::vector<double> std_intrinsics;   // fx fy cx cy (one standard deviation)
  std::vector<double> std_distortion;   // as many as distortion
  std::string board;                    // "chessboard 9x6 inner corners, 25 mm squares"
  int view_count = 0;
  std::string date;                     // ISO 8601, UTC; now when empty
  std::vector<std::string> notes;       // fixed parameters, dropped views
};

// Writes the calibration as OpenCV FileStorage (XML for .xml, YAML for .yml/.yaml; anything else is refused)
// with camera_matrix, distortion_coefficients, image_width, image_height, the extras, and the paper's names
// cameraMatrix and distCoeffs; with `paper_dir` (which must exist), the paper's two files there too. The texts go
// to temporary files that replace the files in one rename each once all are written: a failure ("out/cam.xml:
// cannot write (Permission denied)") leaves none of them written, or the old ones, never half of one and never
// a calibration file without the paper's files asked for (or a cameraMatrix.xml beside an older distCoeffs.xml).
Status write_calibration(const std::string& path, const Calibration& c, const CalibrationFileExtras& extras,
                         const std::string& paper_dir = "");
// The paper's two files in `dir` (which must exist): cameraMatrix.xml and distCoeffs.xml, both or neither.
Status write_paper_files(const std::string& dir, const Calibration& c);

}  // namespace arwb
