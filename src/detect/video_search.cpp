#include "detect/video_search.hpp"

#include <string>

namespace arwb {

SearchHint VideoSearch::hint(const DetectorParams& p, cv::Size size) const {
  SearchHint h;
  if (known_.empty()) return h;   // the detector searches the whole frame: no marker known
  h.known = known_;
  if (p.full_search_interval <= 1) h.why_full = "full_search_interval is 1";
  else if (size != size_) h.why_full = "the frame's size changed";
  else if (lost_) h.why_full = "the last frame's regions lost a marker";
  else if (since_whole_ < 0 || since_whole_ + 1 >= p.full_search_interval)
    h.why_full = "every " + std::to_string(p.full_search_interval) + " frames (full_search_interval)";
  return h;
}

void VideoSearch::record(const SearchHint& h, const std::vector<Marker>& found, cv::Size size) {
  const bool whole = h.known.empty() || !h.why_full.empty();
  lost_ = !whole && found.size() < h.known.size();
  since_whole_ = whole ? 0 : since_whole_ + 1;
  size_ = size;
  known_.clear();
  for (const Marker& m : found) known_.push_back(m.corners);
}

std::vector<Marker> VideoSearch::detect(const Detector& detector, const cv::Mat& image, FrameTrace* trace,
                                        TraceLevel level, int threads, cv::Mat* acquired) {
  // Markers come out in the acquired image's pixels when it is asked for, else in the input's: the hint is in the
  // same pixels, which stay the same while the input's size and acquisition's resize do.
  // An input of another size starts again whole; so must a change of acquisition's resize (the caller resets).
  SearchHint h = hint(detector.params(), image.size());
  std::vector<Marker> found = detector.detect(image, trace, level, threads, acquired, &h);
  record(h, found, image.size());
  return found;
}

}  // namespace arwb
