#include "detect/yaml_file.hpp"

#include "base/yaml_depth.hpp"

#include <algorithm>
#include <cctype>
#include <string_view>

namespace arwb {

namespace {

// OpenCV's parse errors end in "'(LINE): Reason'" (the rest is its source file and function): our message
// keeps the line, moved back by the lines we added, and the reason.
std::string parse_error(const std::string& path, const std::string& what, int added_lines) {
  const size_t open = what.rfind("'(");
  const size_t close = open == std::string::npos ? std::string::npos : what.find("): ", open);
  if (close == std::string::npos) return path + ": malformed YAML";
  const std::string digits = what.substr(open + 2, close - open - 2);
  if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
    return path + ": malformed YAML";
  std::string reason = what.substr(close + 3);
  while (!reason.empty() && std::isspace(static_cast<unsigned char>(reason.back()))) reason.pop_back();
  if (!reason.empty() && reason.back() == '\'') reason.pop_back();
  if (!reason.empty()) reason[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(reason[0])));
  const int line = std::max(1, std::stoi(digits) - added_lines);
  return path + ":" + std::to_string(line) + ": malformed YAML" + (reason.empty() ? "" : " (" + reason + ")");
}

// OpenCV 4.6's YAML reader loops forever on some text where one document could end: once a line is indented less
// than its root node, or holds a '-' at the root's indentation, it takes the next three characters for "---" and,
// when they are not, never advances (found by the yaml_params and dictionary fuzz targets: "%YAML:1.0", "---e:1",
// "-1", "-"; a map indented by 7 followed by "    ?   -"). It cannot be interrupted, so such text is refused
// here: one document only, "---" alone on its line and before any content; no line indented less than the first
// line of content; no '-' at that indentation (a top-level list, which our maps never hold: OpenCV indents the
// items of a list by three spaces) and no '?' explicit key. Lines starting with '%' are directives, allowed only
// before the document.
Status check_one_document(std::string_view text, const std::string& path) {
  bool content = false;   // a line of content seen (after which no directive or "---" may come)
  size_t root = 0;        // the first content line's indentation
  int line = 0;
  for (size_t start = 0; start < text.size();) {
    size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view l = text.substr(start, end - start);
    start = end + 1;
    ++line;
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    const size_t first = l.find_first_not_of(" \t");
    if (first == std::string_view::npos || l[first] == '#') continue;   // blank or comment
    const auto where = [&] { return path + ":" + std::to_string(line) + ": "; };
    if (first == 0 && l[0] == '%') {
      if (content) return fail(where() + "a YAML directive after the document started");
      continue;
    }
    if (first == 0 && l.substr(0, 3) == "---") {
      std::string_view rest = l.substr(3);
      const size_t after = rest.find_first_not_of(" \t");
      if (after != std::string_view::npos && rest[after] != '#')
        return fail(where() + "text after the document start '---' (put it on the next line)");
      if (content) return fail(where() + "a second YAML document (one per file)");
      continue;
    }
    if (first == 0 && l.substr(0, 3) == "...") return fail(where() + "a YAML document end marker ('...')");
    if (!content) {
      content = true;
      root = first;
    } else if (first < root) {
      return fail(where() + "indented less than the file's first line of content");
    }
    if (l[first] == '?') return fail(where() + "an explicit YAML key ('?') is not supported");
    if (first == root && l[first] == '-')
      return fail(where() + "a list at the top level (a line starting with '-'; indent list items under their key)");
  }
  return {};
}

}  // namespace

Status open_yaml_file(const std::string& path, const FileLimit& limit, cv::FileStorage* fs) {
  Result<std::string> text = read_text_file(path, limit);
  if (!text) return fail(text.error());
  if (Status depth = check_yaml_depth(*text, path); !depth) return depth;
  if (Status one = check_one_document(*text, path); !one) return one;
  std::string yaml = std::move(*text);
  int added = 0;
  if (yaml.rfind("%YAML", 0) != 0) {
    yaml = "%YAML:1.0\n---\n" + yaml;  // OpenCV's reader wants that first line
    added = 2;
  }
  try {
    fs->open(yaml, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    return fail(parse_error(path, e.what(), added));
  } catch (const std::exception&) {   // std::length_error from an empty flow-map key ("{ : 1}"), found by fuzzing
    return fail(path + ": malformed YAML");
  }
  if (!fs->isOpened()) return fail(path + ": malformed YAML");
  return {};
}

}  // namespace arwb
