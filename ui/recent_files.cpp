#include "ui/recent_files.hpp"

#include <algorithm>
#include <cctype>
#include <initializer_list>
#include <sstream>

namespace arwb::ui {

namespace {

std::string extension_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  std::string e = path.substr(dot);
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

bool one_of(const std::string& e, std::initializer_list<const char*> list) {
  return std::any_of(list.begin(), list.end(), [&](const char* x) { return e == x; });
}

}  // namespace

const char* file_kind_name(FileKind k) {
  switch (k) {
    case FileKind::source: return "source";
    case FileKind::scene: return "scene";
    case FileKind::preset: return "preset";
    case FileKind::calibration: return "calibration";
    case FileKind::bundle: return "bundle";
    case FileKind::count: break;
  }
  return "?";
}

DropKind drop_kind(const std::string& path, bool is_folder, bool is_media) {
  if (is_folder) return DropKind::source;
  const std::string e = extension_of(path);
  if (one_of(e, {".lua", ".xml"})) return DropKind::scene;
  if (one_of(e, {".yml", ".yaml"})) return DropKind::preset;
  return is_media ? DropKind::source : DropKind::none;
}

bool listed_for(FileKind kind, const std::string& name) {
  const std::string e = extension_of(name);
  switch (kind) {
    case FileKind::source:
      return one_of(e, {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp", ".pbm", ".pgm", ".ppm", ".mp4",
                        ".mov", ".m4v", ".avi", ".mkv", ".webm", ".ts", ".mpg", ".mpeg"});
    case FileKind::scene: return one_of(e, {".lua", ".xml"});
    case FileKind::preset: return one_of(e, {".yml", ".yaml"});
    case FileKind::calibration: return one_of(e, {".yml", ".yaml", ".xml", ".json"});
    case FileKind::bundle: return one_of(e, {".arwb", ".zip"});
    case FileKind::count: break;
  }
  return false;
}

void RecentFiles::add(FileKind kind, const std::string& path) {
  if (path.empty()) return;
  auto& list = recent[static_cast<size_t>(kind)];
  list.erase(std::remove(list.begin(), list.end(), path), list.end());
  list.insert(list.begin(), path);
  if (list.size() > kMax) list.resize(kMax);
}

bool RecentFiles::is_favourite(const std::string& folder) const {
  return std::find(favourites.begin(), favourites.end(), folder) != favourites.end();
}

void RecentFiles::toggle_favourite(const std::string& folder) {
  const auto it = std::find(favourites.begin(), favourites.end(), folder);
  if (it != favourites.end()) favourites.erase(it);
  else if (!folder.empty()) favourites.push_back(folder);
}

std::string recent_text(const RecentFiles& r) {
  std::string s = "# arwb: recent files and favourite folders (kind<TAB>path); rewritten by the workbench\n";
  for (int k = 0; k < kFileKindCount; ++k) {
    for (const auto& p : r.recent[static_cast<size_t>(k)]) s += std::string(file_kind_name(FileKind(k))) + "\t" + p + "\n";
  }
  for (const auto& f : r.favourites) s += "favourite\t" + f + "\n";
  for (const auto& l : r.kept) s += l + "\n";
  return s;
}

RecentFiles parse_recent(const std::string& text, std::vector<std::string>* problems) {
  RecentFiles r;
  std::istringstream in(text);
  std::string line;
  int n = 0;
  auto problem = [&](const std::string& m) {
    if (problems) problems->push_back("line " + std::to_string(n) + ": " + m);
  };
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const size_t tab = line.find('\t');
    if (tab == std::string::npos || tab + 1 >= line.size()) {
      problem("expected kind<TAB>path");
      r.kept.push_back(line);
      continue;
    }
    const std::string kind = line.substr(0, tab), path = line.substr(tab + 1);
    if (kind == "favourite") {
      if (!r.is_favourite(path)) r.favourites.push_back(path);
      continue;
    }
    int k = 0;
    while (k < kFileKindCount && kind != file_kind_name(FileKind(k))) ++k;
    if (k == kFileKindCount) {
      problem("unknown kind '" + kind + "'");
      r.kept.push_back(line);
      continue;
    }
    auto& list = r.recent[static_cast<size_t>(k)];
    // The file is newest first: keep that order, each path once, at most kMax.
    if (list.size() < RecentFiles::kMax && std::find(list.begin(), list.end(), path) == list.end()) list.push_back(path);
  }
  return r;
}

}  // namespace arwb::ui
