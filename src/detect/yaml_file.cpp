#include "detect/yaml_file.hpp"

#include "base/yaml_depth.hpp"

#include <algorithm>
#include <cctype>

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

}  // namespace

Status open_yaml_file(const std::string& path, const FileLimit& limit, cv::FileStorage* fs) {
  Result<std::string> text = read_text_file(path, limit);
  if (!text) return fail(text.error());
  if (Status depth = check_yaml_depth(*text, path); !depth) return depth;
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
  }
  if (!fs->isOpened()) return fail(path + ": malformed YAML");
  return {};
}

}  // namespace arwb
