// Video mode (the idea of ArUco 3's, Romero-Ramirez, Munoz-Salinas and Medina-Carnicer, 2018): a frame of a video
// is searched only around the markers the frame before it found, at the scale they had (search_regions), which
// costs a fraction of a whole search. The whole frame is searched again
//   - when no marker is known,
//   - every full_search_interval frames, so that a marker coming into view is found within that many frames,
//   - after a frame whose regions lost a marker (it moved further than the margin, or left),
//   - when the frame's size changes.
// VideoSearch keeps what one video's frames tell each other; the Detector itself stays stateless. Each source of
// frames (the workbench's stream, a video file, a lab clip) has its own.
#pragma once

#include "detect/detector.hpp"

#include <opencv2/core.hpp>

#include <vector>

namespace arwb {

class VideoSearch {
 public:
  // The next frame of the video through `detector`, as Detector::detect with the hint this video gives; the
  // markers are remembered for the frame after.
  std::vector<Marker> detect(const Detector& detector, const cv::Mat& image, FrameTrace* trace = nullptr,
                             TraceLevel level = TraceLevel::summary, int threads = 1, cv::Mat* acquired = nullptr);

  // The hint an input frame of `size` gets now (see the rules above).
  SearchHint hint(const DetectorParams& p, cv::Size size) const;
  // What the input frame of `size` searched with `h` found.
  void record(const SearchHint& h, const std::vector<Marker>& found, cv::Size size);
  // Forget everything: the next frame is searched whole (a seek, another source, another acquisition resize).
  void reset() { *this = VideoSearch{}; }

  // Frames searched since the last whole search (0: the last one was whole), -1 before any.
  int frames_since_whole() const { return since_whole_; }

 private:
  std::vector<Quad> known_;
  cv::Size size_;   // the input's size known_ was found on
  int since_whole_ = -1;
  bool lost_ = false;
};

}  // namespace arwb
