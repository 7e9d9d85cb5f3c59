// cells.jsonl (cells_file.hpp): a run's key, a finished cell as one line and back, the file read into a run's
// finished cells, and how two runs' keys differ.
#include "lab/cells_file.hpp"

#include "base/files.hpp"
#include "base/json_depth.hpp"
#include "base/json_text.hpp"
#include "base/text.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <iterator>
#include <utility>

namespace arwb::lab {
namespace {

// The key's arrays' fields, in the key's order: key_difference names them.
const char* const kPlanFields[] = {"name",         "dictionary",      "markers",     "sizes_mm", "distances_m",
                                   "lux",          "max_tilt_deg",    "frames_per_cell", "empty_share", "sides_px",
                                   "tilts_deg",    "blurs_px",        "noises",      "occlusions",  "curve_at",
                                   "curve_blurs_px", "curve_noises"};
const char* const kCameraFields[] = {"width", "height", "camera matrix", "distortion"};
const char* const kSensorFields[] = {"sensitivity", "full_well", "read_noise", "target_level", "max_exposure_s",
                                     "max_gain", "focal_length_mm", "f_number", "focus_m", "shake_deg_s"};
const char* const kLightFields[] = {"direct_outdoor",   "direct_indoor", "direct_evening", "body_width_m",
                                    "shadow_chance",    "sun_diameter_rad", "glare_chance", "glare_lobe_deg",
                                    "glare_peak"};

}  // namespace

std::string lab_run_key(const LabPlan& plan, const LabOptions& options) {
  nlohmann::ordered_json j;
  j["plan"] = {plan.name,        plan.dictionary,   plan.markers,         plan.sizes_mm, plan.distances_m,
               plan.lux,         plan.max_tilt_deg, plan.frames_per_cell, plan.empty_share,  plan.sides_px,
               plan.tilts_deg,   plan.blurs_px,     plan.noises,          plan.occlusions,   plan.curve_at,
               plan.curve_blurs_px, plan.curve_noises};
  j["seed"] = options.seed;
  j["detectors"] = options.detectors;
  nlohmann::ordered_json params = nlohmann::ordered_json::object();
  for (const ParamInfo& info : param_table()) params[info.name] = get_param(options.params, info);
  j["params"] = params;
  const SynthCamera& c = options.camera;
  j["camera"] = {c.size.width, c.size.height, std::vector<double>(c.camera_matrix.val, c.camera_matrix.val + 9),
                 c.distortion};
  const SensorModel& m = options.sensor;
  j["sensor"] = {m.sensitivity, m.full_well,    m.read_noise, m.target_level, m.max_exposure_s,
                 m.max_gain,    m.focal_length_mm, m.f_number, m.focus_m,  m.shake_deg_s};
  const SceneLight& l = options.light;
  j["light"] = {l.direct_outdoor,   l.direct_indoor, l.direct_evening, l.body_width_m,  l.shadow_chance,
                l.sun_diameter_rad, l.glare_chance,  l.glare_lobe_deg, l.glare_peak};
  return json_text(j);
}

std::string cell_to_line(const std::string& key, size_t index, const CellResult& c) {
  nlohmann::json j;
  j["key"] = key;
  j["index"] = index;
  j["cell"] = {c.cell.size_mm, c.cell.distance_m, c.cell.lux,      c.cell.side_px,
               c.cell.tilt_deg, c.cell.blur_px,    c.cell.noise, c.cell.occlusion};
  j["side_px"] = c.side_px;
  j["tilts"] = c.tilts_deg;
  j["exposure_ms"] = c.exposure_ms;
  j["gain"] = c.gain;
  j["snr"] = c.snr_black_white;
  j["blur_px"] = c.blur_px;
  j["seconds"] = c.seconds;
  nlohmann::json ds = nlohmann::json::array();
  for (const DetectorTally& t : c.detectors)
    ds.push_back({t.frames, t.detected, t.wrong_id, t.ms, t.empty_frames, t.false_positives, t.marks});
  j["detectors"] = ds;
  return json_text(j) + "\n";
}

namespace {

// Why the tally of a saved cell cannot be (empty when it can): a negative count, more found than frames.
std::string impossible_tally(const DetectorTally& t) {
  const std::pair<const char*, int> counts[] = {{"frames", t.frames},
                                                {"detected", t.detected},
                                                {"wrong_id", t.wrong_id},
                                                {"empty_frames", t.empty_frames},
                                                {"false_positives", t.false_positives}};
  for (const auto& [name, v] : counts)
    if (v < 0) return std::string(name) + " " + std::to_string(v) + " is negative";
  // A frame counts once as detected and once as wrong_id at most (another id may be reported beside the right one).
  for (const auto& [name, v] : {std::pair{"detected", t.detected}, std::pair{"wrong_id", t.wrong_id}})
    if (v > t.frames) return std::string(name) + " " + std::to_string(v) + " is more than its " +
                             std::to_string(t.frames) + " frames";
  for (double ms : t.ms)
    if (!(ms >= 0) || !std::isfinite(ms)) return "a time of " + std::to_string(ms) + " ms";
  return {};
}

}  // namespace

std::optional<std::pair<size_t, CellResult>> cell_from_line(const std::string& key, const std::string& line,
                                                            size_t detectors, std::string* problem) {
  if (!check_json_depth(line, "")) return std::nullopt;
  const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
  try {
    if (!j.is_object() || j.value("key", std::string()) != key) return std::nullopt;
    CellResult c;
    const auto& cell = j.at("cell");
    double* fields[] = {&c.cell.size_mm, &c.cell.distance_m, &c.cell.lux,      &c.cell.side_px,
                        &c.cell.tilt_deg, &c.cell.blur_px,    &c.cell.noise, &c.cell.occlusion};
    for (size_t i = 0; i < std::size(fields); ++i) *fields[i] = cell.at(i).get<double>();
    c.side_px = j.at("side_px").get<double>();
    c.tilts_deg = j.at("tilts").get<std::vector<float>>();
    c.exposure_ms = j.at("exposure_ms").get<double>();
    c.gain = j.at("gain").get<double>();
    c.snr_black_white = j.at("snr").get<double>();
    c.blur_px = j.at("blur_px").get<double>();
    c.seconds = j.value("seconds", -1.0);   // absent from cells saved by an older arwb
    if (!(c.seconds >= 0) || !std::isfinite(c.seconds)) c.seconds = -1;
    const auto& ds = j.at("detectors");
    if (!ds.is_array() || ds.size() != detectors) return std::nullopt;
    for (const auto& d : ds) {
      DetectorTally t;
      t.frames = d.at(0).get<int>();
      t.detected = d.at(1).get<int>();
      t.wrong_id = d.at(2).get<int>();
      t.ms = d.at(3).get<std::vector<double>>();
      t.empty_frames = d.at(4).get<int>();
      t.false_positives = d.at(5).get<int>();
      if (d.size() > 6) t.marks = d.at(6).get<std::string>();
      if (const std::string why = impossible_tally(t); !why.empty()) {
        if (problem) *problem = why;
        return std::nullopt;
      }
      c.detectors.push_back(std::move(t));
    }
    return std::pair{j.at("index").get<size_t>(), std::move(c)};
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;   // a line cut short by the interruption, or one edited by hand
  }
}

namespace {

// A JSON value in a sentence, cut to a readable length.
std::string value_text(const nlohmann::json& v) {
  std::string s = json_text(v);
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

// "its seed is 7, this run's 1".
std::string differs(const std::string& what, const nlohmann::json& theirs, const nlohmann::json& ours) {
  return "its " + what + " is " + value_text(theirs) + ", this run's " + value_text(ours);
}

// The first differing field of one of the key's arrays, named from `fields` ("its plan's lux is ...").
template <size_t N>
std::string array_difference(const std::string& owner, const char* const (&fields)[N], const nlohmann::json& theirs,
                             const nlohmann::json& ours) {
  if (theirs.is_array() && ours.is_array() && theirs.size() == N && ours.size() == N)
    for (size_t i = 0; i < N; ++i)
      if (theirs[i] != ours[i]) return differs(owner + "'s " + fields[i], theirs[i], ours[i]);
  return "its " + owner + " differs";
}

}  // namespace

std::string key_difference(const std::string& theirs, const std::string& ours) {
  const nlohmann::json a = nlohmann::json::parse(theirs, nullptr, false);
  const nlohmann::json b = nlohmann::json::parse(ours, nullptr, false);
  if (!a.is_object() || !b.is_object()) return theirs == ours ? "" : "its key is not a run's";
  for (const auto& [name, ours_value] : b.items()) {
    const nlohmann::json theirs_value = a.contains(name) ? a[name] : nlohmann::json();
    if (theirs_value == ours_value) continue;
    if (name == "plan") return array_difference("plan", kPlanFields, theirs_value, ours_value);
    if (name == "camera") return array_difference("camera", kCameraFields, theirs_value, ours_value);
    if (name == "sensor") return array_difference("sensor model", kSensorFields, theirs_value, ours_value);
    if (name == "light") return array_difference("light model", kLightFields, theirs_value, ours_value);
    if (name == "params" && theirs_value.is_object())
      for (const auto& [param, v] : ours_value.items())
        if (!theirs_value.contains(param) || theirs_value[param] != v)
          return differs("parameter " + param, theirs_value.value(param, nlohmann::json()), v);
    return differs(name, theirs_value, ours_value);
  }
  return a == b ? "" : "its key has fields this arwb does not know";
}

Result<CellsFile> read_cells_file(const std::string& path, const std::string& key, size_t detectors,
                                  std::vector<std::shared_ptr<const CellResult>>& finished) {
  CellsFile out;
  std::error_code ec;
  if (std::filesystem::symlink_status(path, ec).type() == std::filesystem::file_type::not_found) return out;
  // Through the file check: a FIFO or a device in its place is refused at once instead of blocking or reading
  // without end.
  const Result<std::string> text = read_file_bytes(path, FileLimit{"a lab's cells file", std::uintmax_t(256) << 20});
  if (!text) return fail(printable(text.error()));
  size_t start = 0;
  for (int n = 1; start < text->size(); ++n) {
    const size_t end = text->find('\n', start);
    if (end == std::string::npos) break;   // a last line without its newline: cut short by an interruption
    const std::string line = text->substr(start, end - start);
    start = end + 1;
    std::string problem;
    auto c = cell_from_line(key, line, detectors, &problem);
    if (c && c->first < finished.size()) {
      if (!finished[c->first]) {
        finished[c->first] = std::make_shared<const CellResult>(std::move(c->second));
        ++out.taken;
      }
    } else if (!problem.empty()) {
      out.problems.push_back(printable(path) + ":" + std::to_string(n) + ": " + problem);
    } else if (!check_json_depth(line, "")) {
      continue;
    } else if (const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
               j.is_object() && j.contains("key") && j["key"].is_string() && j["key"] != key) {
      if (out.other_runs++ == 0) out.other_run = key_difference(j["key"].get<std::string>(), key);
    }
  }
  return out;
}

std::string cells_file_text(const std::string& key, const std::vector<CellResult>& cells) {
  std::string s;
  for (size_t i = 0; i < cells.size(); ++i) s += cell_to_line(key, i, cells[i]);
  return s;
}

}  // namespace arwb::lab
