#include "cli/cli_common.hpp"

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace arwb {

Args::Args(int argc, char** argv) {
  bool rest = false;
  for (int i = 0; i < argc; ++i) {
    std::string a = argv[i];
    if (!rest && a == "--") {
      rest = true;
      continue;
    }
    if (rest && a.rfind("-", 0) == 0) a = "./" + a;  // after "--", a leading dash is a file name
    if (!rest && a.rfind("--", 0) == 0 && a.find('=') != std::string::npos) {
      items_.push_back(a.substr(0, a.find('=')));
      items_.push_back(a.substr(a.find('=') + 1));
    } else {
      items_.push_back(a);
    }
  }
  used_.assign(items_.size(), false);
}

int Args::find(const std::string& name) {
  known_.insert(name);
  for (size_t i = 0; i < items_.size(); ++i)
    if (!used_[i] && items_[i] == name) return static_cast<int>(i);
  return -1;
}

bool Args::flag(const std::string& name) {
  const int i = find(name);
  if (i < 0) return false;
  used_[size_t(i)] = true;
  return true;
}

std::string Args::value(const std::string& name, const std::string& fallback) {
  const int i = find(name);
  if (i < 0) return fallback;
  used_[size_t(i)] = true;
  if (size_t(i) + 1 >= items_.size()) {
    errors_.push_back(name + " needs a value");
    return fallback;
  }
  used_[size_t(i) + 1] = true;
  return items_[size_t(i) + 1];
}

int Args::int_value(const std::string& name, int fallback, int lo, int hi) {
  const std::string v = value(name, "");
  if (v.empty()) return fallback;
  char* end = nullptr;
  const long n = std::strtol(v.c_str(), &end, 10);
  if (*end || n < lo || n > hi) {
    errors_.push_back(name + " " + v + ": expected a whole number in " + std::to_string(lo) + ".." + std::to_string(hi));
    return fallback;
  }
  return static_cast<int>(n);
}

double Args::double_value(const std::string& name, double fallback, double lo, double hi) {
  const std::string v = value(name, "");
  if (v.empty()) return fallback;
  char* end = nullptr;
  const double n = std::strtod(v.c_str(), &end);
  if (*end || !(n >= lo && n <= hi)) {
    std::ostringstream os;
    os << name << " " << v << ": expected a number in " << lo << ".." << hi;
    errors_.push_back(os.str());
    return fallback;
  }
  return n;
}

std::vector<std::string> Args::positional() {
  std::vector<std::string> out;
  ok();  // unknown options are errors, not file names
  for (size_t i = 0; i < items_.size(); ++i) {
    if (used_[i]) continue;
    if (items_[i].rfind("-", 0) == 0 && items_[i].size() > 1) continue;  // an option nobody asked for
    used_[i] = true;
    out.push_back(items_[i]);
  }
  return out;
}

bool Args::no_positional() {
  for (const auto& p : positional()) errors_.push_back("unexpected argument '" + p + "'");
  return errors_.empty();
}

bool Args::ok() {
  for (size_t i = 0; i < items_.size(); ++i)
    if (!used_[i] && items_[i].rfind("-", 0) == 0 && items_[i].size() > 1) {
      errors_.push_back("unknown option " + items_[i]);
      used_[i] = true;
    }
  return errors_.empty();
}

int Args::fail(const char* command) {
  // One line: the first problem, and where to read more.
  std::fprintf(stderr, "%s: %s (see %s --help)\n", command, errors_.empty() ? "bad arguments" : errors_[0].c_str(),
               command);
  return 2;
}

std::optional<std::vector<Dictionary>> dictionaries_option(const std::string& list, const char* command) {
  std::string err;
  auto dicts = parse_dictionaries(list, &err);
  if (!dicts) std::fprintf(stderr, "%s: --dict %s\n", command, err.c_str());
  return dicts;
}

bool load_params_option(const std::string& path, const char* command, DetectorParams& p) {
  if (path.empty()) return true;
  std::vector<std::string> errors, notes;
  const bool ok = load_params_yaml(path, p, &errors, &notes);
  for (const auto& n : notes) std::fprintf(stderr, "%s: --params %s\n", command, n.c_str());
  if (ok) return true;
  for (const auto& e : errors) std::fprintf(stderr, "%s: --params %s\n", command, e.c_str());
  return false;
}

namespace {

// A whole string as a number of type T, or nullopt.
template <typename T>
std::optional<T> parse_number(std::string_view s) {
  T v{};
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

}  // namespace

std::optional<std::vector<int>> parse_id_list(std::string_view spec, const Dictionary& dict, std::string* error) {
  const long long size = dict.size();
  const std::string range = dict.name() + " has ids 0-" + std::to_string(size - 1);
  std::vector<int> ids;
  std::vector<bool> seen(static_cast<size_t>(size), false);
  size_t pos = 0;
  while (true) {
    const size_t comma = std::min(spec.find(',', pos), spec.size());
    const std::string_view item = spec.substr(pos, comma - pos);
    // Unsigned parsing rejects signs, so "-3" or "3--5" cannot slip through as a range.
    const size_t dash = item.find('-');
    const auto first = parse_number<unsigned long long>(item.substr(0, dash));
    const auto last = dash == std::string_view::npos ? first : parse_number<unsigned long long>(item.substr(dash + 1));
    if (!first || !last) {
      *error = "bad id list '" + std::string(spec) + "' at '" + std::string(item) + "' (expected e.g. 0-49 or 3,7,10-12)";
      return std::nullopt;
    }
    if (*first > *last) {
      *error = "bad id range '" + std::string(item) + "' in --ids (the first id is larger than the last)";
      return std::nullopt;
    }
    for (const unsigned long long id : {*first, *last})
      if (id >= static_cast<unsigned long long>(size)) {
        *error = "id " + std::to_string(id) + " is outside the dictionary: " + range;
        return std::nullopt;
      }
    for (auto id = *first; id <= *last; ++id)
      if (!seen[id]) {
        seen[id] = true;
        ids.push_back(static_cast<int>(id));
      }
    if (comma == spec.size()) break;
    pos = comma + 1;
  }
  return ids;
}


bool open_video_writer(cv::VideoWriter& writer, const std::string& path, double fps, cv::Size size,
                       std::string* codec) {
  const std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  const bool avi = ext == ".avi" || ext == ".AVI";
  for (const char* cc : avi ? std::vector<const char*>{"MJPG"} : std::vector<const char*>{"avc1", "mp4v"}) {
    if (writer.open(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc(cc[0], cc[1], cc[2], cc[3]), fps, size, true)) {
      if (codec) *codec = cc;
      return true;
    }
  }
  return false;
}

}  // namespace arwb
