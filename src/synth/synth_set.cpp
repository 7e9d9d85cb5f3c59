#include "synth/synth_set.hpp"

#include "base/files.hpp"
#include "base/json.hpp"
#include "capture/image_io.hpp"

#include <cstdio>
#include <regex>
#include <sstream>

namespace arwb {

const std::vector<cv::Size>& mixed_sizes() {
  static const std::vector<cv::Size> sizes = {{640, 480}, {1280, 720}, {1920, 1080}};
  return sizes;
}

SetItem make_set_item(const std::vector<Dictionary>& dicts, const std::vector<cv::Size>& sizes, uint64_t seed, int i) {
  SynthOptions opt;
  opt.size = sizes[size_t(i) % sizes.size()];
  opt.dictionaries = dicts;
  SynthImage s = synth_photo(opt, seed, i);
  char name[32];
  std::snprintf(name, sizeof name, "img_%05d.png", i);
  return SetItem{name, std::move(s.image), std::move(s.markers), std::move(s.notes)};
}

std::string truth_line(const SetItem& item) {
  std::string line = "{\"file\":" + json::quote(item.file) + ",\"width\":" + std::to_string(item.image.cols) +
                     ",\"height\":" + std::to_string(item.image.rows) + ",\"markers\":[";
  for (size_t i = 0; i < item.truth.size(); ++i) {
    const TruthMarker& m = item.truth[i];
    line += (i ? ",{" : "{");
    line += "\"id\":" + std::to_string(m.id) + ",\"dict\":" + json::quote(m.dict) + ",\"corners\":[";
    for (int k = 0; k < 4; ++k)
      line += std::string(k ? "," : "") + "[" + json::number(m.corners[size_t(k)].x, 4) + "," +
              json::number(m.corners[size_t(k)].y, 4) + "]";
    line += "]}";
  }
  return line + "],\"notes\":" + json::quote(item.notes) + "}";
}

// One line per photograph: a million photographs stay far below this.
constexpr std::uintmax_t kMaxTruthBytes = 256u << 20;

std::optional<std::vector<SetItem>> read_set(const std::string& dir, std::vector<std::string>* errors) {
  const std::string path = dir + "/truth.jsonl";
  Result<std::string> text = read_text_file(path, kMaxTruthBytes);
  if (!text) {
    if (errors) errors->push_back(text.error());
    return std::nullopt;
  }
  std::istringstream in(std::move(*text));
  // The set's own format, written by truth_line: a small pattern reader is enough and rejects anything else.
  static const std::regex file_re("\"file\"\\s*:\\s*\"([^\"]+)\"");
  static const std::regex marker_re(
      "\\{\\s*\"id\"\\s*:\\s*(-?\\d+)\\s*,\\s*\"dict\"\\s*:\\s*\"([^\"]+)\"\\s*,\\s*\"corners\"\\s*:\\s*\\[\\s*"
      "\\[([^\\]]+)\\]\\s*,\\s*\\[([^\\]]+)\\]\\s*,\\s*\\[([^\\]]+)\\]\\s*,\\s*\\[([^\\]]+)\\]\\s*\\]\\s*\\}");
  std::vector<SetItem> items;
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    auto fail = [&](const std::string& why) {
      if (errors) errors->push_back(path + ":" + std::to_string(n) + ": " + why);
    };
    std::smatch fm;
    if (!std::regex_search(line, fm, file_re)) {
      fail("no \"file\"");
      continue;
    }
    SetItem item;
    item.file = fm[1];
    if (item.file.find('/') != std::string::npos) {
      fail("file '" + item.file + "' must be a name inside the set's folder");
      continue;
    }
    LoadedImage img = load_image(dir + "/" + item.file);
    if (!img.ok()) {
      fail(img.error);
      continue;
    }
    item.image = img.image;
    bool ok = true;
    for (std::sregex_iterator it(line.begin(), line.end(), marker_re), end; it != end; ++it) {
      TruthMarker m;
      m.id = std::stoi((*it)[1]);
      m.dict = (*it)[2];
      for (int k = 0; k < 4; ++k) {
        float x = 0, y = 0;
        if (std::sscanf((*it)[size_t(3 + k)].str().c_str(), "%f , %f", &x, &y) != 2) ok = false;
        m.corners[size_t(k)] = {x, y};
      }
      item.truth.push_back(m);
    }
    if (!ok) {
      fail("a marker's corners are not [x,y] pairs");
      continue;
    }
    items.push_back(std::move(item));
  }
  return items;
}

}  // namespace arwb
