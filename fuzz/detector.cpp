// Fuzz target: the detector (src/detect) on small random images, the whole pipeline with the full trace, then what
// the workbench and snapshots make of a trace (its JSON, the stage pictures). Input layout:
//   byte 0, 1  width - 1, height - 1 (1..64 each: small frames keep each input fast)
//   byte 2     bit 0: BGR (else grey); bits 1-2: acquisition's resize (off, to twice the width, to half the
//              height keeping the aspect, to 17x9); bits 3-7: the dictionary (dictionary_names(), in turn)
//   byte 3     k = byte % 8 parameter settings follow, each 2 bytes: the parameter (param_table(), in turn) and
//              its value from its minimum (0) to its maximum (255)
//   the rest   the pixels, row by row, repeated when short (black when none)
// Markers are in image pixels, inside the (acquired) image, with ids inside their dictionary.
#include "detect/detector.hpp"
#include "inspect/trace_json.hpp"
#include "inspect/trace_view.hpp"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::vector<arwb::Dictionary> dictionaries = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    std::vector<arwb::Dictionary> all;
    for (const std::string& name : arwb::dictionary_names()) all.push_back(*arwb::dictionary_by_name(name));
    return all;
  }();
  if (size < 4) return -1;
  const int width = 1 + data[0] % 64, height = 1 + data[1] % 64;
  const bool bgr = data[2] & 1;
  const int resize = data[2] >> 1 & 3;
  const arwb::Dictionary& dict = dictionaries[(data[2] >> 3) % dictionaries.size()];
  const auto table = arwb::param_table();
  arwb::DetectorParams params;
  size_t pos = 4;
  for (int k = data[3] % 8; k > 0 && pos + 1 < size; --k, pos += 2) {
    const arwb::ParamInfo& info = table[data[pos] % table.size()];
    double v = info.min_value + (info.max_value - info.min_value) * data[pos + 1] / 255.0;
    if (info.integer) v = std::round(v);
    if (!arwb::set_param(params, info, v)) std::abort();   // inside its range: always accepted
  }

  cv::Mat image(height, width, bgr ? CV_8UC3 : CV_8UC1, cv::Scalar::all(0));
  const size_t n = image.total() * image.elemSize();
  if (pos < size)
    for (size_t i = 0; i < n; ++i) image.data[i] = data[pos + i % (size - pos)];

  arwb::Detector detector({dict}, params);
  if (resize != 0) {
    const cv::Size to = resize == 1 ? cv::Size(2 * width, 0) : resize == 2 ? cv::Size(0, (height + 1) / 2) : cv::Size(17, 9);
    detector.set_acquisition({.fps_cap = 0, .resize = true, .size = to});
  }
  arwb::FrameTrace trace;
  cv::Mat acquired;
  const std::vector<arwb::Marker> markers = detector.detect(image, &trace, arwb::TraceLevel::full, 1, &acquired);
  if (acquired.empty()) std::abort();
  const auto cols = static_cast<float>(acquired.cols), rows = static_cast<float>(acquired.rows);
  for (const arwb::Marker& m : markers) {
    if (m.id < 0 || m.id >= dict.size()) std::abort();
    for (const cv::Point2f& c : m.corners)
      if (!(c.x >= -1 && c.y >= -1 && c.x <= cols && c.y <= rows)) std::abort();
  }
  const std::string json = arwb::trace_to_json(trace);
  if (json.empty() || json.front() != '{') std::abort();
  cv::Mat working;
  if (acquired.channels() == 1) cv::cvtColor(acquired, working, cv::COLOR_GRAY2BGR);
  else working = acquired;
  std::array<cv::Mat, arwb::kStageCount> views;
  arwb::render_stage_views(working, trace, views);
  return 0;
}
