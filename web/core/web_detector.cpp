// The WebAssembly core's detector (web_detector.hpp).
#include "web_detector.hpp"

#include "detect/dictionary.hpp"
#include "detect/params.hpp"
#include "pose/marker_pose.hpp"

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
  video_.reset();
  return "";
}

std::string WebDetector::set_param(const std::string& name, double value) {
  const ParamInfo* info = find_param(name);
  if (!info || !is_detector_param(*info)) return "no detector parameter is called \"" + name + "\"";
  DetectorParams p = detector_->params();
  std::string error;
  if (!arwb::set_param(p, *info, value, &error)) return error;
  detector_->set_params(p);
  video_.reset();
  return "";
}

std::string WebDetector::set_camera(const std::string& path, double marker_side) {
  if (!(marker_side >= 0) || marker_side > 1e5)
    return "marker side " + std::to_string(marker_side) + ": not 0 to 100000";
  std::optional<Calibration> c;
  if (!path.empty()) {
    Result<Calibration> read = read_calibration(path);
    if (!read) return read.error();
    c = std::move(*read);
  }
  calibration_ = std::move(c);
  marker_side_ = marker_side;
  sized_.clear();
  return "";
}

const Calibration* WebDetector::camera_for(int width, int height, std::string* error) {
  auto it = sized_.find({width, height});
  if (it == sized_.end()) {
    Result<Calibration> c = calibration_ ? calibration_for_size(*calibration_, {width, height})
                                         : Result<Calibration>(default_calibration({width, height}));
    it = sized_.emplace(std::make_pair(width, height), std::move(c)).first;
  }
  if (!it->second) {
    *error = it->second.error();
    return nullptr;
  }
  return &*it->second;
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
  markers_ = video_.detect(*detector_, rgba, &trace, TraceLevel::summary);
  const std::vector<Marker>& markers = markers_;
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  Json stages = Json::object();
  for (const StageRecord& r : trace.stages) stages[std::string(stage_name(r.stage))] = r.ms;
  Json out = {{"width", width_}, {"height", height_}, {"ms", ms}, {"markers", Json::array()},
              {"stages", std::move(stages)}};
  std::string camera_error;
  const Calibration* camera = marker_side_ > 0 ? camera_for(width_, height_, &camera_error) : nullptr;
  if (!camera_error.empty()) out["camera_error"] = camera_error;
  const auto vec = [](const cv::Vec3d& v) { return Json{v[0], v[1], v[2]}; };
  for (const Marker& m : markers) {
    Json corners = Json::array();
    for (const auto& c : m.corners) corners.push_back({c.x, c.y});
    Json marker = {{"id", m.id}, {"dict", m.dict}, {"corners", std::move(corners)}, {"hamming", m.hamming}};
    if (camera)
      if (const std::optional<MarkerPose> p = estimate_marker_pose(m.corners, marker_side_, *camera)) {
        // The marker's axes as the workbench's live view draws them: through the lens, one side long.
        const double L = marker_side_;
        Json axes = Json::array();
        const std::vector<cv::Point3d> ends = {{0, 0, 0}, {L, 0, 0}, {0, L, 0}, {0, 0, L}};
        for (const cv::Point2d& a : project_marker_points(ends, p->pose, *camera)) axes.push_back({a.x, a.y});
        marker["pose"] = {{"rvec", vec(p->pose.rvec)}, {"tvec", vec(p->pose.tvec)}, {"error_px", p->pose.error_px},
                          {"ambiguity", p->ambiguity},
                          {"alternative", {{"rvec", vec(p->alternative.rvec)}, {"tvec", vec(p->alternative.tvec)},
                                           {"error_px", p->alternative.error_px}}},
                          {"camera", p->assumed_camera ? "assumed" : "calibrated"}, {"axes", std::move(axes)}};
      }
    out["markers"].push_back(std::move(marker));
  }
  result_ = out.dump();
  return result_;
}

}  // namespace arwb::web
