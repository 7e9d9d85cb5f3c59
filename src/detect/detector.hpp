// The marker detector: the pipeline of pipeline.hpp run on a frame, recording what each stage did in a trace.
#pragma once

#include "capture/acquisition.hpp"
#include "detect/dictionary.hpp"
#include "detect/params.hpp"
#include "detect/trace.hpp"

#include <string>
#include <vector>

namespace arwb {

// What earlier frames of a video tell the search (detect/video_search.hpp keeps it from frame to frame): the
// markers they found, in the input's pixels. The search looks around them only, at their scale (search_regions).
struct SearchHint {
  std::vector<Quad> known;
  std::string why_full;   // not empty: search the whole frame anyway, for this reason (shown in the trace)
};

class Detector {
 public:
  // One or more dictionaries are searched in one pass; a grid is read once per distinct marker size.
  explicit Detector(std::vector<Dictionary> dictionaries, DetectorParams params = {});

  // Markers in the image (grey or BGR, 8 bit), sorted by dictionary order then id, their corners in the image's
  // pixels. `trace`, when given, is overwritten with a record at `level`. `threads` > 1 spreads the candidates
  // over threads; the result does not depend on it.
  //
  // `acquired`, when given, receives the frame after acquisition's resize (its channels kept), and the markers
  // and the trace are then in that image's pixels (the trace's width and height are its size, scale 1): the
  // workbench and `arwb render` show that image and draw over it.
  //
  // `hint`, when given, is what earlier frames of a video found (see SearchHint); without it the whole frame is
  // searched.
  std::vector<Marker> detect(const cv::Mat& image, FrameTrace* trace = nullptr,
                             TraceLevel level = TraceLevel::summary, int threads = 1,
                             cv::Mat* acquired = nullptr, const SearchHint* hint = nullptr) const;

  const DetectorParams& params() const { return params_; }
  void set_params(const DetectorParams& p) { params_ = p; }
  const std::vector<Dictionary>& dictionaries() const { return dictionaries_; }
  // The acquisition step's resize (its fps cap is for whoever pulls frames). Off until set: the frame is
  // detected at its own size, as `arwb bench` does and `arwb detect` unless given --resize.
  const AcquisitionSettings& acquisition() const { return acquisition_; }
  void set_acquisition(const AcquisitionSettings& a) { acquisition_ = a; }

 private:
  std::vector<Dictionary> dictionaries_;
  DetectorParams params_;
  AcquisitionSettings acquisition_{.fps_cap = 0, .resize = false};
};

}  // namespace arwb
