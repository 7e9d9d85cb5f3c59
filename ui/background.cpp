// [SECTION] Index
//   Threads      the sweep and dictionary distances on their own threads, polled each UI frame
//   Files        the shipped presets and example scenes listed, the script editor's file read and watched, a
//                folder listed for the file browser
#include "ui/app.hpp"

#include "base/files.hpp"
#include "capture/opencv_error.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>
#include <system_error>

namespace arwb {

namespace {

namespace fs = std::filesystem;

constexpr FileLimit kScriptFile{"the script editor", 1u << 20};
constexpr double kScriptCheckS = 0.5;             // how often the script editor's file is looked at

// The first comment line of a YAML preset, shown beside its name.
std::string first_comment(const fs::path& p) {
  // The shared reader, as for loading: a FIFO or device named *.yml in the folder must not block the listing.
  const Result<std::string> read = read_text_file(p.string(), FileLimit{"a preset", 1u << 20});
  if (!read) return {};
  std::istringstream in(*read);
  std::string line;
  while (std::getline(in, line)) {
    const size_t at = line.find_first_not_of(" \t");
    if (at == std::string::npos) continue;
    if (line[at] == '%' || line.compare(at, 3, "---") == 0) continue;  // %YAML:1.0 and the document start
    if (line[at] != '#') break;
    std::string text = line.substr(at + 1);
    const size_t s = text.find_first_not_of(" \t");
    return s == std::string::npos ? std::string() : text.substr(s);
  }
  return {};
}

// The script editor's reading: the shared reader, with the editor's own limit.
bool read_script(const std::string& path, std::string* text, std::string* error) {
  Result<std::string> read = read_text_file(path, kScriptFile);
  if (!read) {
    *error = read.error();
    return false;
  }
  *text = std::move(*read);
  return true;
}

bool scene_extension(const fs::path& p) {
  const std::string ext = p.extension().string();
  return ext == ".lua" || ext == ".xml";
}

}  // namespace

// [SECTION] Threads
void App::poll_background() {
  poll_lab();
  poll_export();
  for (auto it = dictionary_futures.begin(); it != dictionary_futures.end();) {
    if (it->second.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
      ++it;
      continue;
    }
    status.dictionary_stats[it->first] = it->second.get();
    it = dictionary_futures.erase(it);
  }
  // The script editor's file: looked at twice a second.
  const double now = std::chrono::duration<double>(Clock::now() - t0).count();
  if (!status.script_file.path.empty() && now >= script_next_check) watch_file(status.script_file.path, false);
  status.sweep.progress = sweep_progress;
  if (!sweep_future.valid()) return;
  if (sweep_future.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  status.sweep.running = false;
  status.sweep.has_result = true;
  try {
    status.sweep.result = sweep_future.get();
    info("sweep: " + status.sweep.result.message);
  } catch (const std::exception& e) {
    sweep_future = {};
    error("sweep: " + one_line_reason(e));
  }
}

void App::compute_dictionary_stats(const std::string& name) {
  if (status.dictionary_stats.count(name) || dictionary_futures.count(name)) return;   // done or under way
  std::string err;
  auto d = dictionary_by_name(name, &err);
  if (!d) return error("dictionary: " + err);
  // Every pair (500 000 for 1000 ids): off the UI thread.
  dictionary_futures[name] = std::async(std::launch::async, [d = std::move(*d)] {
    const auto start = Clock::now();
    ui::DictionaryStats s;
    s.min_distance = d.min_distance();
    s.pairs = closest_pairs(d, 50);
    s.histogram = distance_histogram(d);
    s.ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    return s;
  });
}

// [SECTION] Files
// *.yml in assets/presets: default first, then by name; then the user's own (config_dir/presets), by name.
void App::list_presets() {
  status.presets.clear();
  status.user_presets.clear();
  auto list = [](const std::string& dir, std::vector<ui::PresetFile>* out) {
    std::error_code ec;
    if (dir.empty() || !fs::is_directory(dir, ec)) return false;
    for (const auto& entry : fs::directory_iterator(dir, ec)) {
      if (!entry.is_regular_file(ec) || entry.path().extension() != ".yml") continue;
      out->push_back({entry.path().string(), entry.path().stem().string(), first_comment(entry.path())});
    }
    std::sort(out->begin(), out->end(), [](const ui::PresetFile& a, const ui::PresetFile& b) {
      if ((a.name == "default") != (b.name == "default")) return a.name == "default";
      return a.name < b.name;
    });
    return true;
  };
  status.presets_dir = (fs::path(status.assets_dir) / "presets").lexically_normal().string();
  if (!list(status.presets_dir, &status.presets)) status.presets_dir.clear();
  if (!status.config_dir.empty()) list(status.config_dir + "/presets", &status.user_presets);
}

// *.lua and *.xml in the scripts folder and one folder below it (scripts/museum/museum.lua).
void App::list_examples() {
  status.examples.clear();
  status.examples_error.clear();
  const std::string& dir = status.scripts_dir;
  if (dir.empty()) {
    status.examples_error = "no scripts folder";
    return;
  }
  std::error_code ec;
  const fs::path root(dir);
  if (!fs::is_directory(root, ec)) {
    status.examples_error = dir + " is not a folder";
    return;
  }
  auto add = [&](const fs::path& p) {
    std::error_code e;
    if (!fs::is_regular_file(p, e) || !scene_extension(p)) return;
    status.examples.push_back({p.lexically_normal().string(), p.lexically_relative(root).generic_string()});
  };
  for (const auto& entry : fs::directory_iterator(root, ec)) {
    std::error_code e;
    if (entry.is_directory(e)) {
      for (const auto& inner : fs::directory_iterator(entry.path(), e)) add(inner.path());
    } else {
      add(entry.path());
    }
  }
  std::sort(status.examples.begin(), status.examples.end(),
            [](const ui::ExampleScene& a, const ui::ExampleScene& b) { return a.label < b.label; });
  if (status.examples.empty()) status.examples_error = "no .lua or .xml file in " + dir;
}

// Reads `path` into Status::script_file when it is a new path, `reread`, or its time or size changed on disk.
void App::watch_file(const std::string& path, bool reread) {
  ui::WatchedFile& f = status.script_file;
  script_next_check = std::chrono::duration<double>(Clock::now() - t0).count() + kScriptCheckS;
  std::error_code ec;
  const bool exists = !path.empty() && fs::is_regular_file(path, ec);
  fs::file_time_type mtime{};
  uintmax_t size = 0;
  if (exists) {
    mtime = fs::last_write_time(path, ec);
    size = fs::file_size(path, ec);
    if (ec) size = 0;
  }
  if (!reread && path == f.path && exists == f.exists && mtime == script_mtime && size == script_size) return;
  f.path = path;
  f.exists = exists;
  script_mtime = mtime;
  script_size = size;
  f.text.clear();
  f.error.clear();
  f.read = !path.empty() && read_script(path, &f.text, &f.error);
  ++f.version;
}

void App::list_dir(const std::string& path) {
  ui::DirListing& l = status.listing;
  std::error_code ec;
  fs::path p = fs::absolute(path.empty() ? "." : path, ec).lexically_normal();
  if (p.has_relative_path() && !p.has_filename()) p = p.parent_path();   // "a/b/" -> "a/b"
  if (!fs::is_directory(p, ec)) {
    l.error = path + ": " + (fs::exists(p, ec) ? "not a folder" : "no such folder");
    ++l.version;
    return;
  }
  std::vector<ui::DirEntry> entries;
  for (auto it = fs::directory_iterator(p, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name[0] == '.') continue;   // hidden, as in a desktop's file dialog
    std::error_code e;
    entries.push_back({name, it->is_directory(e)});
    if (entries.size() >= 20000) break;
  }
  if (ec) {
    l.error = p.string() + ": " + ec.message();
    ++l.version;
    return;
  }
  auto lower = [](std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
  };
  std::sort(entries.begin(), entries.end(), [&](const ui::DirEntry& a, const ui::DirEntry& b) {
    if (a.folder != b.folder) return a.folder;
    return lower(a.name) < lower(b.name);
  });
  l.dir = p.string();
  l.parent = p == p.root_path() ? std::string() : p.parent_path().string();
  l.entries = std::move(entries);
  l.error.clear();
  ++l.version;
}

}  // namespace arwb
