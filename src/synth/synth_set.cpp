#include "synth/synth_set.hpp"

#include "base/decimals.hpp"
#include "base/files.hpp"
#include "base/json_depth.hpp"
#include "capture/image_io.hpp"
#include "base/json_text.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

namespace arwb {

using Json = nlohmann::ordered_json;

const std::vector<cv::Size>& mixed_sizes() {
  static const std::vector<cv::Size> sizes = {{640, 480}, {1280, 720}, {1920, 1080}};
  return sizes;
}

const std::vector<cv::Size>& hard_sizes() {
  static const std::vector<cv::Size> sizes = {{640, 480}, {1280, 720}, {1920, 1080}, {3840, 2160}};
  return sizes;
}

SetItem make_set_item(const std::vector<Dictionary>& dicts, const std::vector<cv::Size>& sizes, uint64_t seed, int i,
                      SetKind kind) {
  SynthOptions opt;
  opt.size = sizes[size_t(i) % sizes.size()];
  opt.dictionaries = dicts;
  int index = i;
  if (kind == SetKind::hard) {
    opt.hardship = kHardships[(size_t(i) / sizes.size()) % std::size(kHardships)];
    index += 1000000;  // not the standard set's draws
  }
  SynthImage s = synth_photo(opt, seed, index);
  char name[32];
  std::snprintf(name, sizeof name, "img_%05d.png", i);
  return SetItem{name, std::move(s.image), std::move(s.markers), std::move(s.notes),
                 kind == SetKind::hard ? std::string(hardship_name(opt.hardship)) : std::string()};
}

std::string truth_line(const SetItem& item) {
  Json markers = Json::array();
  for (const TruthMarker& m : item.truth) {
    Json corners = Json::array();
    for (const auto& c : m.corners) corners.push_back({round_decimals(c.x, 4), round_decimals(c.y, 4)});
    markers.push_back({{"id", m.id}, {"dict", m.dict}, {"corners", std::move(corners)}});
  }
  Json line = {{"file", item.file},        {"width", item.image.cols}, {"height", item.image.rows},
               {"markers", std::move(markers)}, {"notes", item.notes}};
  if (!item.condition.empty()) line["condition"] = item.condition;
  return json_text(line);
}

namespace {

// One truth.jsonl line's markers, or why they cannot be used. A marker without its own "dict" takes the line's.
Result<std::vector<TruthMarker>> read_markers(const Json& line) {
  std::vector<TruthMarker> out;
  const auto it = line.find("markers");
  if (it == line.end()) return out;
  if (!it->is_array()) return fail("\"markers\" is not a list");
  const auto line_dict = line.find("dict");
  if (line_dict != line.end() && !line_dict->is_string()) return fail("\"dict\" is not a dictionary's name");
  for (const Json& m : *it) {
    const std::string which = "marker " + std::to_string(out.size() + 1);
    if (!m.is_object()) return fail(which + " is not an object");
    const auto id = m.find("id"), own_dict = m.find("dict"), corners = m.find("corners");
    if (id == m.end()) return fail(which + ": \"id\" is missing");
    if (!id->is_number_integer() || *id < 0 || *id > 1000000)
      return fail(which + ": \"id\" is not a whole number from 0 to 1000000");
    const Json* dict = own_dict != m.end() ? &*own_dict : line_dict != line.end() ? &*line_dict : nullptr;
    if (!dict) return fail(which + ": \"dict\" is missing (give it per marker, or once for the line)");
    if (!dict->is_string()) return fail(which + ": \"dict\" is not a dictionary's name");
    if (corners == m.end()) return fail(which + ": \"corners\" is missing");
    TruthMarker t;
    t.id = id->get<int>();
    t.dict = dict->get<std::string>();
    bool pairs = corners->is_array() && corners->size() == 4;
    for (size_t k = 0; pairs && k < 4; ++k) {
      const Json& c = (*corners)[k];
      pairs = c.is_array() && c.size() == 2 && c[0].is_number() && c[1].is_number();
      if (pairs) t.corners[k] = {c[0].get<float>(), c[1].get<float>()};
    }
    if (!pairs) return fail(which + ": \"corners\" are not four [x,y] pairs");
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace

Result<std::vector<SetItem>> read_set(const std::string& dir, std::vector<std::string>* skipped) {
  const std::string path = dir + "/truth.jsonl";
  // A truth set of a million markers is about 100 MB.
  const Result<std::string> all = read_text_file(path, FileLimit{"a truth set", std::uintmax_t(256) << 20});
  if (!all) return fail(all.error());
  std::istringstream in(*all);
  std::vector<SetItem> items;
  std::string text;
  for (int n = 1; std::getline(in, text); ++n) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    auto skip = [&](const std::string& why) {
      if (skipped) skipped->push_back(path + ":" + std::to_string(n) + ": " + why);
    };
    if (Status depth = check_json_depth(text, ""); !depth) {
      skip("nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
      continue;
    }
    const Json line = Json::parse(text, nullptr, false);
    if (line.is_discarded() || !line.is_object()) {
      skip("not a JSON object");
      continue;
    }
    const auto file = line.find("file");
    if (file == line.end() || !file->is_string() || file->get_ref<const std::string&>().empty()) {
      skip("no \"file\"");
      continue;
    }
    SetItem item;
    item.file = file->get<std::string>();
    if (item.file.find('/') != std::string::npos || item.file == "." || item.file == "..") {
      skip("file '" + item.file + "' must be a name inside the set's folder");
      continue;
    }
    Result<std::vector<TruthMarker>> truth = read_markers(line);
    if (!truth) {
      skip(truth.error());
      continue;
    }
    LoadedImage img = load_image(dir + "/" + item.file);
    if (!img.ok()) {
      skip(img.error);
      continue;
    }
    item.image = img.image;
    item.truth = std::move(*truth);
    if (const auto notes = line.find("notes"); notes != line.end() && notes->is_string())
      item.notes = notes->get<std::string>();
    if (const auto c = line.find("condition"); c != line.end()) {
      // Only the hard set's names: the bench prints a row for each.
      const bool known = c->is_string() && std::any_of(std::begin(kHardships), std::end(kHardships), [&](Hardship h) {
                           return hardship_name(h) == c->get_ref<const std::string&>();
                         });
      if (!known) {
        skip("\"condition\" is not one of low_contrast, tiny, low_light, crossed");
        continue;
      }
      item.condition = c->get<std::string>();
    }
    items.push_back(std::move(item));
  }
  return items;
}

}  // namespace arwb
