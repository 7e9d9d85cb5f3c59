// The bundle's self-test in the page (web_self_test.hpp).
#include "web_self_test.hpp"

#include "detect/detector.hpp"
#include "detect/dictionary.hpp"
#include "script/scene_step.hpp"
#include "script/self_test_verdict.hpp"

#include <nlohmann/json.hpp>

#include <opencv2/core.hpp>

#include <algorithm>

namespace arwb::web {

namespace {

// Export's frame: one marker of about 120 pixels, upright and frontal, with a quiet zone of a cell and a half, in
// the middle of a grey 320x240 frame. Drawn here cell by cell (synth, which export draws with, is not in the core).
cv::Mat test_frame(const Dictionary& dict, int id) {
  cv::Mat frame(240, 320, CV_8UC1, cv::Scalar(200));
  const int cells = dict.marker_size() + 2;
  const int cell = std::max(2, 120 / cells);
  const int quiet = cell * 3 / 2;
  const int side = cells * cell, outer = side + 2 * quiet;
  const cv::Rect box((frame.cols - outer) / 2, (frame.rows - outer) / 2, outer, outer);
  frame(box).setTo(cv::Scalar(255));
  dict.render(id, cell).copyTo(frame(cv::Rect(box.x + quiet, box.y + quiet, side, side)));
  return frame;
}

}  // namespace

std::string self_test_json(const std::string& scene_path, media::MediaProvider& media) {
  using Json = nlohmann::ordered_json;
  script::SceneStep step(media);
  if (!step.load(scene_path))
    return Json{{"passed", false}, {"error", step.status().error}, {"rows", Json::array()}}.dump();
  std::string error;
  const std::string name = step.dictionary().empty() ? "ARUCO_ORIGINAL" : step.dictionary();
  std::optional<std::vector<Dictionary>> dicts = parse_dictionaries(name, &error);
  if (!dicts || dicts->empty())
    return Json{{"passed", false}, {"error", "dictionary " + name + ": " + error}, {"rows", Json::array()}}.dump();
  const Dictionary& dict = dicts->front();
  const Detector detector(*dicts);
  Json rows = Json::array();
  bool passed = true;
  double t = 0;
  uint64_t frame_index = 0;
  for (const auto& [mapped, mappings] : script::mapped_ids(step.runtime())) {
    const int id = mapped;   // a plain variable: clang 14's lambdas cannot capture a structured binding
    const cv::Mat frame = test_frame(dict, id);
    const std::vector<Marker> markers = detector.detect(frame);
    script::SceneStepInput in;
    in.markers = &markers;
    in.image = frame.size();
    in.t_s = t;
    in.frame_index = ++frame_index;
    t += 1.0;   // one second apart, so each id enters alone
    const script::SceneStepOutput out = step.run(in);
    const std::vector<std::string> errors = step.take_errors();
    const bool detected = std::any_of(markers.begin(), markers.end(), [&](const Marker& m) { return m.id == id; });
    for (const size_t mi : mappings) {
      const script::MappingVerdict v = script::judge_mapping(id, mi, detected, step.status(), out.overlays, errors);
      passed = passed && v.fired;
      rows.push_back({{"id", id}, {"line", v.line}, {"media", v.media}, {"detected", detected}, {"fired", v.fired},
                      {"detail", v.detail}});
    }
  }
  return Json{{"passed", passed}, {"error", ""}, {"rows", std::move(rows)}}.dump();
}

}  // namespace arwb::web
