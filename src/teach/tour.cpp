#include "teach/tour.hpp"

#include "base/files.hpp"
#include "base/text.hpp"
#include "detect/params.hpp"

#include <algorithm>
#include <sstream>
#include <string_view>

namespace arwb {
namespace {

// ASCII blanks only: bytes of UTF-8 sequences are never whitespace and must survive untouched.
bool blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

// " (did you mean 'otsu'?)" when one known name is a typo away, so the teacher sees the fix, not just the fault.
std::string suggestion(std::string_view word, const std::vector<std::string>& known) {
  const std::string name = nearest_name(word, known);
  return name.empty() ? "" : " (did you mean '" + name + "'?)";
}

const std::vector<std::string>& step_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k{"overview"};
    for (int i = 0; i < kStageCount; ++i) k.emplace_back(stage_name(static_cast<Stage>(i)));
    k.emplace_back("pose");
    k.emplace_back("summary");
    return k;
  }();
  return keys;
}

const std::vector<std::string>& param_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& info : param_table()) n.emplace_back(info.name);
    return n;
  }();
  return names;
}

// The value of "name: value" when the line starts with that field name, else false.
bool field(std::string_view line, std::string_view name, std::string_view* value) {
  if (line.size() <= name.size() || line.substr(0, name.size()) != name || line[name.size()] != ':') return false;
  *value = trim(line.substr(name.size() + 1));
  return true;
}

}  // namespace

// A tour is a few pages of text; anything much larger is not one.
constexpr FileLimit kTourFile{"a tour", 4u << 20};

bool load_tour(const std::string& path, std::vector<TourStep>* steps, std::vector<std::string>* errors) {
  auto report = [&](int line, const std::string& msg) {
    if (errors) errors->push_back(path + ":" + std::to_string(line) + ": " + msg);
  };
  std::vector<TourStep> out;
  Result<std::string> text = read_text_file(path, kTourFile);
  if (!text) {
    if (errors) errors->push_back(text.error());
    if (steps) steps->clear();
    return false;
  }
  std::string all = std::move(*text);
  if (all.rfind("\xEF\xBB\xBF", 0) == 0) all.erase(0, 3);  // editors on Windows save translations with a BOM

  bool in_step = false;         // lines belong to `cur`
  bool skipping = false;        // lines belong to a step that was refused
  bool reported_stray = false;  // text before the first step is reported once, not per line
  TourStep cur;
  std::string paragraph;
  bool has_title = false, has_look = false;

  auto end_paragraph = [&] {
    if (paragraph.empty()) return;
    if (!cur.text.empty()) cur.text += "\n\n";
    cur.text += paragraph;
    paragraph.clear();
  };
  auto finish = [&] {
    if (!in_step) return;
    end_paragraph();
    if (!has_title) {
      report(cur.line, "step '" + cur.key + "' has no title line");
      cur.title = cur.key;
    }
    if (cur.text.empty()) report(cur.line, "step '" + cur.key + "' has no text");
    out.push_back(std::move(cur));
    cur = TourStep{};
    in_step = false;
  };

  std::istringstream lines(all);
  std::string raw;
  int n = 0;
  while (std::getline(lines, raw)) {
    ++n;
    const std::string_view line = trim(raw);
    if (!line.empty() && line.front() == '#') continue;
    if (line.size() >= 2 && line.front() == '[' && line.back() == ']') {
      finish();
      const std::string key(trim(line.substr(1, line.size() - 2)));
      Stage stage = Stage::accepted;
      const bool is_stage = stage_from_name(key, &stage) && stage != Stage::accepted;
      if (!is_stage && key != "overview" && key != "pose" && key != "summary") {
        report(n, "unknown stage '" + key + "'" + suggestion(key, step_keys()) + "; the step is skipped");
        skipping = true;
        continue;
      }
      const auto same = std::find_if(out.begin(), out.end(), [&](const TourStep& s) { return s.key == key; });
      if (same != out.end()) {
        report(n, "step '" + key + "' already given at line " + std::to_string(same->line) + "; this one is skipped");
        skipping = true;
        continue;
      }
      skipping = false;
      in_step = true;
      has_title = has_look = false;
      cur.key = key;
      cur.is_stage = is_stage;
      cur.stage = stage;
      cur.line = n;
      continue;
    }
    if (skipping) continue;
    if (!in_step) {
      if (!line.empty() && !reported_stray) {
        report(n, "text before the first step (a step starts with a line such as [overview])");
        reported_stray = true;
      }
      continue;
    }
    std::string_view value;
    if (field(line, "title", &value)) {
      if (value.empty()) continue;  // reported as a missing title when the step ends
      if (has_title) report(n, "second title in step '" + cur.key + "'; the first is kept");
      else cur.title = std::string(value);
      has_title = true;
    } else if (field(line, "look", &value)) {
      if (has_look) report(n, "second look line in step '" + cur.key + "'; the first is kept");
      else cur.look = std::string(value);
      has_look = true;
    } else if (field(line, "params", &value)) {
      std::string names(value);
      std::replace(names.begin(), names.end(), ',', ' ');
      std::istringstream words(names);
      std::string name;
      while (words >> name) {
        if (!find_param(name)) {
          report(n, "unknown parameter '" + name + "'" + suggestion(name, param_names()));
          continue;
        }
        if (std::find(cur.params.begin(), cur.params.end(), name) == cur.params.end()) cur.params.push_back(name);
      }
    } else if (line.empty()) {
      end_paragraph();
    } else {
      if (!paragraph.empty()) paragraph += ' ';
      paragraph += line;
    }
  }
  finish();
  const bool ok = !out.empty();
  if (!ok && errors) errors->push_back(path + ": no step could be read");
  if (steps) *steps = std::move(out);
  return ok;
}

}  // namespace arwb
