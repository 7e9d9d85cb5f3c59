// Apart from the sources (capture/source.hpp): the detector includes only this, so its programs link none of
// OpenCV's image and video file readers, whose 240 libraries take a quarter of a second to load.
#pragma once

#include <opencv2/core.hpp>

namespace arwb {

// The paper's acquisition step: an fps cap and a resize (20 fps, and the paper's 640 pixels across by default, the
// height following the source's aspect: a 16:9 picture squashed into 640x480 shows its markers squashed, and
// loses some). It is the only resize before detection: whoever pulls frames applies the cap, and the detector
// applies the resize as its `acquisition` stage (detect/detector.hpp), so the trace times it.
struct AcquisitionSettings {
  double fps_cap = 20;           // frames per second taken from the source; 0 = as fast as it gives them
  bool resize = true;
  cv::Size size{640, 0};         // the working size when resize is on; a side of 0 follows the frame's aspect,
                                 // both 0 keep the frame's size; two sides are exact (aspect not kept)
  bool rgb = false;              // colour frames are R, G, B(, A) (a browser's), not OpenCV's B, G, R(, A)
  bool operator==(const AcquisitionSettings&) const = default;
};

// The size `in` is resized to under `s`: `in` itself when resize is off or nothing is to change.
cv::Size acquisition_size(cv::Size in, const AcquisitionSettings& s);

// Resizes `in` to the acquisition size (or copies when resize is off or the size already matches).
void acquire(const cv::Mat& in, const AcquisitionSettings& s, cv::Mat& out);

}  // namespace arwb
