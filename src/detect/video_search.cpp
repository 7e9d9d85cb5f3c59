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
  // same pixels. The acquired size is known only after the frame, so a changed input size is checked on the input.
  const cv::Size in_size = image.size();
  const bool same_input = in_size == input_size_;
  SearchHint h = hint(detector.params(), same_input ? size_ : cv::Size());
  std::vector<Marker> found = detector.detect(image, trace, level, threads, acquired, &h);
  input_size_ = in_size;
  record(h, found, acquired && !acquired->empty() ? acquired->size() : in_size);
  return found;
}

}  // namespace arwb
