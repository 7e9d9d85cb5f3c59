// The WebAssembly core's detector (web_detector.hpp).
#include "web_detector.hpp"

#include "detect/dictionary.hpp"
#include "detect/params.hpp"

#include <nlohmann/json.hpp>

#include <chrono>

namespace arwb::web {

WebDetector::WebDetector() : detector_(std::make_unique<Detector>(std::vector<Dictionary>{make_aruco_original()})) {
  // The page's pixels are RGBA: the detector's acquisition makes them grey with cvtColor's levels, where it looks.
  AcquisitionSettings a = detector_->acquisition();
  a.rgb = true;
  detector_->set_acquisition(a);
}

std::string WebDetector::set_dictionaries(const std::string& list) {
  std::string error;
  auto dicts = parse_dictionaries(list, &error);
  if (!dicts) return error;
  auto next = std::make_unique<Detector>(std::move(*dicts), detector_->params());
  next->set_acquisition(detector_->acquisition());
  detector_ = std::move(next);
  return "";
}

std::string WebDetector::set_param(const std::string& name, double value) {
  const ParamInfo* info = find_param(name);
  if (!info || !is_detector_param(*info)) return "no detector parameter is called \"" + name + "\"";
  DetectorParams p = detector_->params();
  std::string error;
  if (!arwb::set_param(p, *info, value, &error)) return error;
  detector_->set_params(p);
  return "";
}

uint8_t* WebDetector::frame(int width, int height) {
  if (width <= 0 || height <= 0 || width > 8192 || height > 8192) return nullptr;
  width_ = width;
  height_ = height;
  // Grown once and then reused, not cleared: the page writes every byte of every frame.
  rgba_.resize(size_t(width) * size_t(height) * 4);
  return rgba_.data();
}

const std::string& WebDetector::detect() {
  using Json = nlohmann::ordered_json;
  if (rgba_.empty()) {
    result_ = Json{{"error", "no frame: call frame(width, height) and write its pixels first"}}.dump();
    return result_;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const cv::Mat rgba(height_, width_, CV_8UC4, rgba_.data());
  FrameTrace trace;
  const std::vector<Marker> markers = detector_->detect(rgba, &trace, TraceLevel::summary);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  Json stages = Json::object();
  for (const StageRecord& r : trace.stages) stages[std::string(stage_name(r.stage))] = r.ms;
  Json out = {{"width", width_}, {"height", height_}, {"ms", ms}, {"markers", Json::array()},
              {"stages", std::move(stages)}};
  for (const Marker& m : markers) {
    Json corners = Json::array();
    for (const auto& c : m.corners) corners.push_back({c.x, c.y});
    out["markers"].push_back({{"id", m.id}, {"dict", m.dict}, {"corners", std::move(corners)}, {"hamming", m.hamming}});
  }
  result_ = out.dump();
  return result_;
}

}  // namespace arwb::web
