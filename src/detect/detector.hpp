// The marker detector: the pipeline of pipeline.hpp run on a frame, recording what each stage did in a trace.
#pragma once

#include "detect/dictionary.hpp"
#include "detect/params.hpp"
#include "detect/trace.hpp"

#include <vector>

namespace arwb {

class Detector {
 public:
  // One or more dictionaries are searched in one pass; a grid is read once per distinct marker size.
  explicit Detector(std::vector<Dictionary> dictionaries, DetectorParams params = {});

  // Markers in the image (grey or BGR, 8 bit), sorted by dictionary order then id. `trace`, when given, is
  // overwritten with a record at `level`. `threads` > 1 spreads the candidates over threads; the result does not
  // depend on it.
  std::vector<Marker> detect(const cv::Mat& image, FrameTrace* trace = nullptr,
                             TraceLevel level = TraceLevel::summary, int threads = 1) const;

  const DetectorParams& params() const { return params_; }
  void set_params(const DetectorParams& p) { params_ = p; }
  const std::vector<Dictionary>& dictionaries() const { return dictionaries_; }

 private:
  std::vector<Dictionary> dictionaries_;
  DetectorParams params_;
};

}  // namespace arwb
