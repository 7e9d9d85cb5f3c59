#include "app/cli_common.hpp"

#include <cstdio>
#include <cstdlib>
#include <sstream>

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
  for (size_t i = 0; i < items_.size(); ++i) {
    if (used_[i]) continue;
    if (items_[i].rfind("-", 0) == 0 && items_[i].size() > 1) continue;  // an option nobody asked for
    used_[i] = true;
    out.push_back(items_[i]);
  }
  return out;
}

bool Args::ok() {
  for (size_t i = 0; i < items_.size(); ++i)
    if (!used_[i] && items_[i].rfind("-", 0) == 0 && items_[i].size() > 1) {
      errors_.push_back("unknown option " + items_[i]);
      used_[i] = true;
    }
  return errors_.empty();
}

int Args::fail(const char* command, const char* usage) {
  for (const auto& e : errors_) std::fprintf(stderr, "%s: %s\n", command, e.c_str());
  std::fprintf(stderr, "%s", usage);
  return 2;
}

std::optional<std::vector<Dictionary>> parse_dictionaries(const std::string& list, std::string* error) {
  std::vector<Dictionary> out;
  std::stringstream ss(list);
  std::string name;
  while (std::getline(ss, name, ',')) {
    if (name.empty()) continue;
    const bool file = name.size() > 4 && (name.ends_with(".yml") || name.ends_with(".yaml"));
    auto d = file ? load_dictionary_yaml(name, error) : dictionary_by_name(name, error);
    if (!d) return std::nullopt;
    out.push_back(std::move(*d));
  }
  if (out.empty()) {
    if (error) *error = "no dictionary named";
    return std::nullopt;
  }
  return out;
}

std::optional<std::vector<int>> parse_id_list(const std::string& list, int limit, std::string* error) {
  std::vector<int> ids;
  std::stringstream ss(list);
  std::string part;
  auto bad = [&](const std::string& why) -> std::optional<std::vector<int>> {
    if (error) *error = why;
    return std::nullopt;
  };
  while (std::getline(ss, part, ',')) {
    if (part.empty()) continue;
    const size_t dash = part.find('-', 1);
    char* end = nullptr;
    const long a = std::strtol(part.c_str(), &end, 10);
    long b = a;
    if (dash != std::string::npos) {
      if (end != part.c_str() + dash) return bad("'" + part + "' is not an id or a range like 0-49");
      b = std::strtol(part.c_str() + dash + 1, &end, 10);
    }
    if (*end || end == part.c_str()) return bad("'" + part + "' is not an id or a range like 0-49");
    if (b < a) return bad("range '" + part + "' runs backwards");
    if (a < 0 || b >= limit)
      return bad("id " + std::to_string(a < 0 ? a : b) + " is outside 0.." + std::to_string(limit - 1));
    for (long id = a; id <= b; ++id) ids.push_back(static_cast<int>(id));
  }
  if (ids.empty()) return bad("no ids in '" + list + "'");
  return ids;
}

}  // namespace arwb
