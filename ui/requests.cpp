// [SECTION] Index
//   Requests     what panels asked for: sources, snapshots, presets, sweeps, sheets, scenes, URLs
//   Background   the sweep and dictionary distances on their own threads, polled each UI frame
//   Files        the shipped presets and example scenes listed, the script editor's file read and watched
#include "ui/app.hpp"

#include "capture/opencv_error.hpp"

#include "base/decimals.hpp"
#include "base/files.hpp"
#include "calibration/calibration_file.hpp"
#include "media/open_url.hpp"
#include "synth/marker_sheet.hpp"
#include "workbench/snapshot.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
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

// "0-11", "3,7,9" or "0-3,8": ids below `count`, each once, in the order given.
bool parse_id_ranges(const std::string& text, int count, std::vector<int>* ids, std::string* error) {
  std::istringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    int a = 0, b = 0;
    char dash = 0;
    std::istringstream p(part);
    if (!(p >> a)) return *error = "'" + part + "' is not an id or a range such as 0-11", false;
    b = a;
    if (p >> dash) {
      if (dash != '-' || !(p >> b)) return *error = "'" + part + "' is not an id or a range such as 0-11", false;
    }
    if (a < 0 || b >= count || a > b) {
      return *error = "'" + part + "' is outside 0-" + std::to_string(count - 1) + ", the dictionary's ids", false;
    }
    for (int i = a; i <= b; ++i)
      if (std::find(ids->begin(), ids->end(), i) == ids->end()) ids->push_back(i);
    if (ids->size() > 1000) return *error = "more than 1000 markers", false;
  }
  if (ids->empty()) return *error = "no id given", false;
  return true;
}

bool scene_extension(const fs::path& p) {
  const std::string ext = p.extension().string();
  return ext == ".lua" || ext == ".xml";
}

}  // namespace

// A preset named without a folder ("fast", "fast.yml") is the user's, in config_dir/presets; a path is used as it
// is. Loading a bare name that is not there looks in the working folder, as before.
std::string App::preset_path(const std::string& text, bool saving) const {
  if (text.find('/') != std::string::npos || status.config_dir.empty()) return text;
  const std::string name = fs::path(text).extension() == ".yml" || fs::path(text).extension() == ".yaml" ? text : text + ".yml";
  const std::string mine = status.config_dir + "/presets/" + name;
  std::error_code ec;
  if (saving || fs::exists(mine, ec) || !fs::exists(text, ec)) return mine;
  return text;
}

// [SECTION] Requests
void App::handle_requests() {
  std::vector<ui::Request> todo;
  todo.swap(requests);
  for (const ui::Request& r : todo) {
    switch (r.kind) {
      case ui::RequestKind::open_source: {
        if (ask_before(r)) break;
        SourceSpec spec;
        std::string err;
        if (parse_source_spec(r.text, &spec, &err)) {
          engine->open_source(spec);
          std::error_code ec;
          if (fs::exists(r.text, ec)) {   // a file or folder, not synthetic or a camera: remembered
            status.recent.add(ui::FileKind::source, fs::absolute(r.text).lexically_normal().string());
            save_recent();
          }
        } else {
          error(err);
        }
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
        const std::string path = preset_path(r.text, false);
        const bool ok = load_params_yaml(path, p, &errors, &notes);
        for (const auto& n : notes) warn("preset: " + n);
        if (ok) {
          settings.params = p;
          change_name = "preset " + fs::path(path).filename().string();   // names the undo entry
          info("preset: loaded " + path);
        } else {
          for (const auto& e : errors) error("preset: " + e);
          if (errors.empty()) error("preset: cannot load " + r.text);
        }
        break;
      }
      case ui::RequestKind::load_scene:
        if (!ask_before(r)) engine->load_scene(r.text);
        break;
      case ui::RequestKind::save_script: {
        std::string err;
        const bool saved = write_file_atomically(r.text, r.payload, &err);
        if (saved) info("saved " + r.text + " (the scene reloads by itself)");
        else error("cannot save " + r.text + ": " + err + "; your text is still in the editor");
        if (r.text == status.script_file.path) watch_file(r.text, true);   // the editor sees its save land now
        // The unsaved-edits question was answered "Save": what waited goes on once the save landed, not before.
        if (save_wait >= 0) {
          if (saved) proceed();
          else {
            save_wait = -1;
            quit_waiting = false;
            deferred.reset();
          }
        }
        break;
      }
      case ui::RequestKind::open_url: {
        const std::string err = media::open_url(r.text);
        if (err.empty()) info("opening " + r.text + " in the browser");
        else error("cannot open " + r.text + ": " + err);
        break;
      }
      case ui::RequestKind::save_preset: {
        // A bare name goes to the user's presets folder; the folder is made first, so the first save works.
        const std::string path = preset_path(r.text, true);
        std::error_code ec;
        const fs::path parent = fs::path(path).parent_path();
        if (!parent.empty()) fs::create_directories(parent, ec);
        std::string err;
        if (save_params_yaml(path, settings.params, &err)) {
          note_status("preset: saved " + fs::absolute(path).lexically_normal().string());
          list_presets();
          status.recent.add(ui::FileKind::preset, fs::absolute(path).lexically_normal().string());
          save_recent();
        } else {
          error("preset: " + err);
        }
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
        // payload: dictionary, ids, size in mm, one a line (the marker sheet dialog).
        std::istringstream in(r.payload);
        std::string dict_name, id_text, size_text;
        std::getline(in, dict_name);
        std::getline(in, id_text);
        std::getline(in, size_text);
        if (dict_name.empty()) dict_name = settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : settings.dictionaries[0];
        std::string err;
        auto dict = dictionary_by_name(dict_name, &err);
        if (!dict) {
          error("marker sheet: " + err);
          break;
        }
        std::vector<int> ids;
        if (!parse_id_ranges(id_text.empty() ? "0-11" : id_text, dict->size(), &ids, &err)) {
          error("marker sheet: ids '" + id_text + "': " + err);
          break;
        }
        const double mm = size_text.empty() ? 50.0 : std::atof(size_text.c_str());
        const std::string path = fs::absolute(r.text).lexically_normal().string();
        std::error_code ec;
        fs::create_directories(fs::path(path).parent_path(), ec);
        try {
          const SheetResult s = write_marker_sheet(*dict, ids, mm, SheetFormat::pdf, path);
          note_status("marker sheet: wrote " + path + " (" + std::to_string(s.pages) + " page(s), " +
                      std::to_string(ids.size()) + " markers of " + dict_name + " at " + decimals_text(mm, 1) +
                      " mm); print at 100% and check the 100 mm bar");
        } catch (const std::exception& e) {
          error("marker sheet: " + path + ": " + one_line_reason(e));
        }
        break;
      }
      case ui::RequestKind::list_dir: list_dir(r.text); break;
      case ui::RequestKind::open_file: {
        const auto kind = static_cast<ui::FileKind>(std::clamp(r.value, 0, ui::kFileKindCount - 1));
        if (kind == ui::FileKind::source && (r.text == "synthetic" || r.text.rfind("camera:", 0) == 0)) {
          open_path(kind, r.text);
          ++status.opened;
          break;
        }
        std::string path = r.text;
        if (path.rfind("~/", 0) == 0) {
          if (const char* home = std::getenv("HOME")) path = home + path.substr(1);
        }
        std::error_code ec;
        if (fs::is_directory(path, ec) && r.payload != "folder") {   // "folder": the browser's "Use this folder"
          list_dir(path);
          break;
        }
        if (!fs::exists(path, ec)) {
          status.listing.error = r.text + ": no such file or folder";
          warn("open: " + status.listing.error);
          break;
        }
        open_path(kind, fs::absolute(path).lexically_normal().string());
        ++status.opened;
        break;
      }
      case ui::RequestKind::toggle_favourite:
        status.recent.toggle_favourite(r.text);
        save_recent();
        break;
      case ui::RequestKind::calibration_drop: engine->drop_calibration_view(r.text); break;
      case ui::RequestKind::calibration_reset: engine->reset_calibration(); break;
      case ui::RequestKind::calibration_save: save_calibration(r.text, r.value != 0); break;
      case ui::RequestKind::lab_start:
      case ui::RequestKind::lab_stop:
      case ui::RequestKind::lab_open_cell:
      case ui::RequestKind::lab_read_plan:
      case ui::RequestKind::lab_save:
      case ui::RequestKind::lab_save_clip: lab_request(r); break;
      case ui::RequestKind::export_check:
      case ui::RequestKind::export_write:
      case ui::RequestKind::play_bundle: export_request(r); break;
    }
  }
}

// The newest solve, as `arwb calibrate` writes it (write_calibration: whole or not at all), and the paper's two
// files beside it when asked (all three, or none).
void App::save_calibration(const std::string& text, bool paper_files) {
  const std::shared_ptr<const CalibrationSnapshot> snap = frame ? frame->calibration : nullptr;
  if (!snap || !snap->solution) {
    error("calibration: nothing solved yet to save (keep at least 6 views in the Calibrate workspace)");
    return;
  }
  const Solution& s = *snap->solution;
  CalibrationFileExtras x;
  x.avg_reprojection_error = s.rms;
  x.per_view_reprojection_errors = s.per_view_errors;
  x.std_intrinsics = s.std_intrinsics;
  x.std_distortion = s.std_distortion;
  x.board = snap->board.describe();
  x.view_count = int(s.view_names.size());
  x.notes = s.notes;
  const std::string path = fs::absolute(text).lexically_normal().string();
  // With the paper's files, all three or none (write_calibration writes them together).
  const std::string paper_dir = paper_files ? fs::path(path).parent_path().string() : std::string();
  if (Status st = write_calibration(path, s.calibration, x, paper_dir); !st) {
    error("calibration: " + st.error());
    return;
  }
  const std::string also = paper_files ? " and the paper's cameraMatrix.xml, distCoeffs.xml beside it" : "";
  status.recent.add(ui::FileKind::calibration, path);
  save_recent();
  note_status("calibration: wrote " + path + also + " (" + std::to_string(s.view_names.size()) + " views, RMS " +
              decimals_text(s.rms, 3) + " px)");
}

// [SECTION] Background
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

}  // namespace arwb
