// [SECTION] Index
//   Requests     what panels asked for: sources, snapshots, presets, sweeps, sheets, scenes, URLs
//   Background   the sweep and dictionary distances on their own threads, polled each UI frame
//   Files        the shipped presets and example scenes listed, the script editor's file read and watched
#include "ui/app.hpp"

#include "capture/opencv_error.hpp"

#include "base/files.hpp"
#include "media/open_url.hpp"
#include "synth/marker_sheet.hpp"
#include "workbench/snapshot.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iterator>
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

// [SECTION] Requests
void App::handle_requests() {
  std::vector<ui::Request> todo;
  todo.swap(requests);
  for (const ui::Request& r : todo) {
    switch (r.kind) {
      case ui::RequestKind::open_source: {
        SourceSpec spec;
        std::string err;
        if (parse_source_spec(r.text, &spec, &err)) engine->open_source(spec);
        else error(err);
        break;
      }
      case ui::RequestKind::step: engine->step(r.value); break;
      case ui::RequestKind::seek: engine->seek(r.value); break;
      case ui::RequestKind::next_frame: engine->next_frame(); break;
      case ui::RequestKind::snapshot: {
        if (!frame) {
          warn("snapshot: no frame yet");
          break;
        }
        const SnapshotResult s = write_snapshot(opt.snapshot_dir, frame->image, frame->trace, &frame->views);
        if (s.ok) {
          status.last_snapshot = s.dir;
          info("snapshot: " + std::to_string(s.files.size()) + " files in " + s.dir);
        } else {
          error("snapshot: " + s.error);
        }
        break;
      }
      case ui::RequestKind::sweep: {
        if (!frame || sweep_future.valid()) break;
        std::string err;
        std::string list;
        for (const auto& n : settings.dictionaries) list += (list.empty() ? "" : ",") + n;
        auto dicts = parse_dictionaries(list, &err);
        if (!dicts) {
          error("sweep: " + err);
          break;
        }
        status.sweep = {};
        status.sweep.running = true;
        status.sweep.region = r.region;
        sweep_progress = 0;
        sweep_cancel = false;
        std::shared_ptr<const Frame> f = frame;
        Detector det(std::move(*dicts), settings.params);
        sweep_future = std::async(std::launch::async, [this, f, det, region = r.region] {
          return sweep_region(f->image, det, region, [this](double p) { sweep_progress = p; }, &sweep_cancel);
        });
        info("sweep: trying the parameter table on frame " + std::to_string(f->index));
        break;
      }
      case ui::RequestKind::load_preset: {
        std::vector<std::string> errors;
        DetectorParams p = settings.params;
        std::vector<std::string> notes;
        const bool ok = load_params_yaml(r.text, p, &errors, &notes);
        for (const auto& n : notes) warn("preset: " + n);
        if (ok) {
          settings.params = p;
          info("preset: loaded " + r.text);
        } else {
          for (const auto& e : errors) error("preset: " + e);
          if (errors.empty()) error("preset: cannot load " + r.text);
        }
        break;
      }
      case ui::RequestKind::load_scene: engine->load_scene(r.text); break;
      case ui::RequestKind::save_script: {
        std::string err;
        if (write_file_atomically(r.text, r.payload, &err)) info("saved " + r.text + " (the scene reloads by itself)");
        else error("cannot save " + r.text + ": " + err + "; your text is still in the editor");
        if (r.text == status.script_file.path) watch_file(r.text, true);   // the editor sees its save land now
        break;
      }
      case ui::RequestKind::open_url: {
        const std::string err = media::open_url(r.text);
        if (err.empty()) info("opening " + r.text + " in the browser");
        else error("cannot open " + r.text + ": " + err);
        break;
      }
      case ui::RequestKind::save_preset: {
        // The folder it goes into is made first, so "presets/..." works on the first save.
        std::error_code ec;
        const fs::path parent = fs::path(r.text).parent_path();
        if (!parent.empty()) fs::create_directories(parent, ec);
        std::string err;
        if (save_params_yaml(r.text, settings.params, &err)) info("preset: saved " + r.text);
        else error("preset: " + err);
        break;
      }
      case ui::RequestKind::dictionary_stats: {
        if (status.dictionary_stats.count(r.text) || dictionary_futures.count(r.text)) break;   // done or under way
        std::string err;
        auto d = dictionary_by_name(r.text, &err);
        if (!d) {
          error("dictionary: " + err);
          break;
        }
        // Every pair (500 000 for 1000 ids): off the UI thread.
        dictionary_futures[r.text] = std::async(std::launch::async, [d = std::move(*d)] {
          const auto start = Clock::now();
          ui::DictionaryStats s;
          s.min_distance = d.min_distance();
          s.pairs = closest_pairs(d, 50);
          s.histogram = distance_histogram(d);
          s.ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
          return s;
        });
        break;
      }
      case ui::RequestKind::list_presets: list_presets(); break;
      case ui::RequestKind::list_examples: list_examples(); break;
      case ui::RequestKind::watch_file: watch_file(r.text, r.value != 0); break;
      case ui::RequestKind::marker_sheet: {
        const std::string dict_name = settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : settings.dictionaries[0];
        std::string err;
        auto dict = dictionary_by_name(dict_name, &err);
        if (!dict) {
          error("marker sheet: " + err);
          break;
        }
        std::vector<int> ids;
        for (int i = std::max(0, r.value); i < std::min(dict->size(), std::max(0, r.value) + 12); ++i) ids.push_back(i);
        try {
          const SheetResult s = write_marker_sheet(*dict, ids, 50.0, SheetFormat::pdf, r.text);
          info("marker sheet: " + r.text + " (" + std::to_string(s.pages) + " page(s), 50 mm markers of " + dict_name +
               "); print at 100% and check the 100 mm bar");
        } catch (const std::exception& e) {
          error("marker sheet: " + one_line_reason(e));
        }
        break;
      }
    }
  }
}

// [SECTION] Background
void App::poll_background() {
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

// [SECTION] Files
// *.yml in assets/presets: default first, then by name.
void App::list_presets() {
  status.presets.clear();
  std::error_code ec;
  status.presets_dir = (fs::path(status.assets_dir) / "presets").lexically_normal().string();
  if (!fs::is_directory(status.presets_dir, ec)) {
    status.presets_dir.clear();
    return;
  }
  for (const auto& entry : fs::directory_iterator(status.presets_dir, ec)) {
    if (!entry.is_regular_file(ec) || entry.path().extension() != ".yml") continue;
    status.presets.push_back({entry.path().string(), entry.path().stem().string(), first_comment(entry.path())});
  }
  std::sort(status.presets.begin(), status.presets.end(), [](const ui::PresetFile& a, const ui::PresetFile& b) {
    if ((a.name == "default") != (b.name == "default")) return a.name == "default";
    return a.name < b.name;
  });
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

}  // namespace arwb
