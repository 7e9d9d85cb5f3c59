// The detectors a lab run compares, each behind one call (internal to src/lab: rendered runs and videos).
#pragma once

#include "detect/params.hpp"
#include "detect/trace.hpp"
#include "base/result.hpp"

#include <opencv2/core.hpp>

#include <functional>
#include <string>
#include <vector>

namespace arwb::lab {

// Markers found on a BGR frame.
using DetectFn = std::function<std::vector<Marker>(const cv::Mat&)>;

// A detector of kLabDetectors (run.hpp) for `dict`; an error naming it when unknown or when it cannot read
// that dictionary ("apriltag reads the AprilTag families, not ARUCO_ORIGINAL"). `video`: the frames it is given are
// one video's, in order; arwb then searches as video (detect/video_search.hpp), the peers as they always do.
Result<DetectFn> make_detector(const std::string& name, const std::string& dict, const DetectorParams& params,
                               bool video = false);

}  // namespace arwb::lab
