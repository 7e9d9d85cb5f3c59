// The detectors a lab compares, each behind one call (detectors.hpp).
#include "lab/detectors.hpp"

#include "lab/run.hpp"
#include "detect/detector.hpp"
#include "detect/dictionary.hpp"
#include "detect/video_search.hpp"
#include "peers/peers.hpp"

#include <memory>

namespace arwb::lab {

Result<DetectFn> make_detector(const std::string& name, const std::string& dict, const DetectorParams& params,
                               bool video) {
  if (name == "arwb") {
    auto d = dictionary_by_name(dict);
    if (!d) return fail("unknown dictionary " + dict);
    auto det = std::make_shared<Detector>(std::vector<Dictionary>{*d}, params);
    if (video) {
      auto search = std::make_shared<VideoSearch>();
      return DetectFn([det, search](const cv::Mat& img) { return search->detect(*det, img); });
    }
    return DetectFn([det](const cv::Mat& img) { return det->detect(img); });
  }
  if (name == "opencv" || name == "opencv-aruco3") {
    try {
      auto peer = std::make_shared<OpenCvArucoPeer>(dict, name == "opencv-aruco3");
      return DetectFn([peer](const cv::Mat& img) { return peer->detect(img).markers; });
    } catch (const std::exception& e) {
      return fail(name + ": " + e.what());
    }
  }
  if (name == "apriltag") {
    if (!AprilTagPeer::supports(dict)) return fail("apriltag reads the AprilTag families, not " + dict);
    auto peer = std::make_shared<AprilTagPeer>(dict);
    return DetectFn([peer](const cv::Mat& img) { return peer->detect(img).markers; });
  }
  std::string known;
  for (const auto& k : kLabDetectors) known += (known.empty() ? "" : ", ") + k;
  return fail("unknown detector '" + name + "' (" + known + ")");
}

}  // namespace arwb::lab
