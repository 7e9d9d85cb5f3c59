// Other detectors run on the same frames, for the benchmark and the workbench's Peers overlay: OpenCV 4.6's
// aruco module with its default parameters, and AprilTag 3 for the AprilTag families. Both report markers in
// arwb's convention (corner 0 the marker's top-left, clockwise, pixel centres at integers).
#pragma once

#include "detect/trace.hpp"

#include <memory>
#include <string>
#include <vector>

namespace arwb {

struct PeerResult {
  std::vector<Marker> markers;
  double ms = 0;  // detection alone, grey conversion included (every detector is handed the same BGR frame)
};

class OpenCvArucoPeer {
 public:
  // arwb's names; throws on unknown. `aruco3` turns on OpenCV's ArUco3 mode (useAruco3Detection), its other
  // parameters left at their defaults.
  explicit OpenCvArucoPeer(const std::string& dict_name, bool aruco3 = false);
  PeerResult detect(const cv::Mat& bgr) const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

class AprilTagPeer {
 public:
  // For APRILTAG_16h5, APRILTAG_25h9, APRILTAG_36h10 and APRILTAG_36h11; supports() tells.
  explicit AprilTagPeer(const std::string& dict_name);
  static bool supports(const std::string& dict_name);
  PeerResult detect(const cv::Mat& bgr) const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace arwb
