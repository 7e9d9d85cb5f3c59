// [SECTION] Index
//   Dispatch     carry_out: every request the window can be given, and what carries it out
//   Sources      opening sources, snapshots, web cards
//   Detector     presets, sweeps
//   Files        the script editor's save, the file browser's pick, marker sheets, the calibration saved
// When: the window's menus and keys, a dropped file and a due --actions step are carried out at once; what panels
// and dialogs ask for waits in App::requests until the frame has been shown (handle_requests).
#include "ui/app.hpp"
#include "ui/gl_window.hpp"

#include "capture/opencv_error.hpp"

#include "base/decimals.hpp"
#include "base/files.hpp"
#include "calibration/calibration_file.hpp"
#include "inspect/trace_view.hpp"
#include "lab/plan.hpp"
#include "media/open_url.hpp"
#include "synth/marker_sheet.hpp"
#include "workbench/snapshot.hpp"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <system_error>

namespace arwb {

namespace {

namespace fs = std::filesystem;

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

}  // namespace

// [SECTION] Dispatch
void App::carry_out(const ui::Request& request) {
  using namespace ui;
  std::visit(
      ui::Overloaded{
          // Panels, workspaces and what the live view shows (ui/view_requests.cpp).
          [&](const SetPanelOpen& r) { set_panel_open(r); },
          [&](const SwitchWorkspace& r) { switch_workspace(r.name); },
          [&](const SaveWorkspace& r) {
            if (std::string why; !workspaces.save_as(r.name, &why)) warn("--actions save_workspace: " + why);
          },
          [&](const MovePanel& r) { move_panel(r); },
          [&](const SetSplitter& r) { set_splitter(r); },
          [&](const TogglePresentation&) { set_presentation(!view.presentation); },
          [&](const SetFullscreen& r) {
            const bool on = r.on.value_or(!ui::is_fullscreen(glfw_window));
            if (const std::string problem = ui::set_fullscreen(glfw_window, on, opt.window); !problem.empty())
              warn("full screen: " + problem);
          },
          [&](const ShowHelp& r) {
            (r.page == HelpPage::shortcuts ? dialogs.show_shortcuts
             : r.page == HelpPage::first_steps ? dialogs.show_first_steps : dialogs.show_about) = r.on;
          },
          [&](const StartTour& r) { start_tour(r.step); },
          [&](const ShowStage& r) { view.pipeline_stage = r.stage ? static_cast<int>(*r.stage) : -1; },
          [&](const SelectCandidate& r) { select_candidate(r.index); },
          [&](const SetRegion& r) {
            view.region = r.region;
            view.has_region = true;
            view.show(Panel::why);
          },
          [&](const ShowMedia& r) { view.show_media = r.on; },
          [&](const SetLabels& r) { set_labels(r); },
          [&](const SetPoseDrawing& r) { set_pose_drawing(r); },
          [&](const ClickLiveView& r) { click_live_view(r.at); },
          // Sources and frames.
          [&](const OpenSource& r) { open_source(r); },
          [&](const StepFrames& r) {
            settings.playback.playing = false;   // a step pauses the video (FrameSource::step): the button says Play
            engine->step(r.by);
          },
          [&](const Seek& r) { engine->seek(r.position); },
          [&](const SetSpeed& r) { settings.playback.speed = r.speed; },
          [&](const NextFrame& r) { r.wait ? next_frame_shown() : void(engine->next_frame()); },
          [&](const Freeze& r) { settings.frozen = r.on; },
          [&](const Snapshot&) { snapshot(); },
          [&](const Drop& r) { drop(r.path); },
          [&](const OpenRecent& r) { open_path(r.kind, r.path); },
          [&](const OpenUrl& r) { open_url(r.url); },
          // Files.
          [&](const LoadPreset& r) { load_preset(r.path); },
          [&](const SavePreset& r) { save_preset(r.path); },
          [&](const ListPresets&) { list_presets(); },
          [&](const LoadScene& r) {
            if (!ask_before(r)) engine->load_scene(r.path);
          },
          [&](const ListExamples&) { list_examples(); },
          [&](const SaveScript& r) { save_script(r); },
          [&](const WatchFile& r) { watch_file(r.path, r.reread); },
          [&](const Browse& r) { dialogs.browse = r.kind; },
          [&](const ListDir& r) { list_dir(r.path); },
          [&](const OpenFile& r) { open_file(r); },
          [&](const ToggleFavourite& r) {
            status.recent.toggle_favourite(r.folder);
            save_recent();
          },
          // The detector.
          [&](const SetParam& r) {
            if (std::string err; !set_param(settings.params, *r.param, r.value, &err)) warn("--actions: " + err);
          },
          [&](const AddDictionary& r) { add_dictionary(r.name); },
          [&](const ComputeDictionaryStats& r) { compute_dictionary_stats(r.dictionary); },
          [&](const EnablePeers&) { settings.peer_opencv = settings.peer_apriltag = true; },
          [&](const Undo&) { undo(); },
          [&](const Redo&) { redo(); },
          [&](const Sweep&) { sweep(); },
          // Dialogs and input (ui/dialogs.cpp).
          [&](const OpenSheetDialog& r) { open_sheet_dialog(r); },
          [&](const WriteMarkerSheet& r) { write_marker_sheet(r); },
          [&](const PressButton& r) { dialogs.answer = r.button; },
          [&](const Focus& r) { focus(r.field); },
          [&](const TypeText& r) { type_text(r.text); },
          [&](const Quit&) {
            if (glfw_window) glfwSetWindowShouldClose(glfw_window, 1);
          },
          // The Calibrate workspace.
          [&](const SetCalibrationBoard& r) { settings.calibration.board = r.board; },
          [&](const SetCalibrationCapture& r) { settings.calibration.capture = r.on; },
          [&](const SetUndistort& r) { settings.calibration.undistort = r.on; },
          [&](const SetMarkerSize& r) { settings.marker_size = r.size; },
          [&](const DropCalibrationView& r) { drop_calibration_view(r); },
          [&](const ResetCalibration&) { engine->reset_calibration(); },
          [&](const SaveCalibrationAs&) { dialogs.save_calibration = true; },
          [&](const SaveCalibration& r) { save_calibration(r.path, view.calibration_paper_files); },
          [&](const WaitForCalibration& r) { wait_for_calibration(r.views); },
          // The Lab workspace (ui/lab_requests.cpp).
          [&](const UsePaperPlan&) { settings.lab.plan = lab::paper_plan(); },
          [&](const ReadLabPlan& r) { read_lab_plan(r.path); },
          [&](const SetLabFrames& r) { settings.lab.plan.frames_per_cell = r.per_cell; },
          [&](const SetLabAxis& r) {
            settings.lab.plan.*(r.axis->values) = r.values;
            settings.lab.plan.name = "your plan";
          },
          [&](const SetLabDetectors& r) { settings.lab.detectors = r.detectors; },
          [&](const StartLab&) { start_lab(); },
          [&](const StopLab&) {
            if (lab_session.running()) lab_session.stop();
          },
          [&](const WaitForLab& r) { wait_for_lab(r.cells); },
          [&](const OpenLabCell& r) { open_lab_cell(r.cell, r.frame); },
          [&](const WhyLabMarker&) { why_lab_marker(); },
          [&](const MarkClipSpan& r) { mark_clip_span(r.end); },
          [&](const SaveClip& r) { save_clip(r.typed); },
          [&](const RecordClip& r) { record_clip(r.typed); },
          [&](const StopClip&) { stop_clip(); },
          [&](const PrintClipMarker&) { print_clip_marker(); },
          [&](const SaveLabReport& r) { save_lab_report(r.dir); },
          // Export and play (ui/export_requests.cpp).
          [&](const OpenExportDialog& r) { open_export_dialog(r.out); },
          [&](const CheckExport&) { start_export(false); },
          [&](const WriteExport& r) { write_export(r.out); },
          [&](const SetExportTitle& r) {
            std::snprintf(export_dialog.title, sizeof export_dialog.title, "%s", r.title.c_str());
          },
          [&](const SetExportSize& r) { export_dialog.size_mm = r.mm; },
          [&](const SetExportCalibration& r) { export_dialog.use_calibration = r.on; },
          [&](const SetExportForce& r) { export_dialog.force = r.on; },
          [&](const SetExportWeb& r) { export_dialog.web = r.on; },
          [&](const SetExportConvert& r) { export_dialog.convert_for_phones = r.on; },
          [&](const ServeBundle& r) { serve_bundle(r.on); },
          [&](const WaitForExport& r) { wait_export(r.seconds); },
          [&](const PlayBundle& r) { play_bundle(r.path); },
          [&](const SetPlayArgs& r) { play_args = r.args; },
          [&](const WaitForPlayers& r) { wait_players(r.seconds); },
          [&](const WaitForSource& r) { wait_source(r.seconds); },
      },
      request);
}

void App::handle_requests() {
  // Carrying one out may ask for more (a deferred source once the unsaved edits are saved): those wait for the
  // next frame.
  for (const ui::Request& r : std::exchange(requests, {})) carry_out(r);
}

// [SECTION] Sources
void App::open_source(const ui::OpenSource& r) {
  if (ask_before(r)) return;
  SourceSpec spec;
  std::string err;
  if (!parse_source_spec(r.spec, &spec, &err)) return error(err);
  engine->open_source(spec);
  asked_source = spec.text();
  std::error_code ec;
  if (fs::exists(r.spec, ec)) {   // a file or folder, not synthetic or a camera: remembered
    status.recent.add(ui::FileKind::source, fs::absolute(r.spec).lexically_normal().string());
    save_recent();
  }
}

void App::snapshot() {
  if (!frame) return warn("snapshot: no frame yet");
  // A projector's pictures lack their text (the window draws it): a snapshot's are drawn as in normal mode.
  std::array<cv::Mat, kStageCount> plain;
  const auto* views = &frame->views;
  if (!frame->view_style.text) {
    render_stage_views(frame->image, frame->trace, plain);
    views = &plain;
  }
  const SnapshotResult s = write_snapshot(opt.snapshot_dir, frame->image, frame->trace, views);
  if (!s.ok) return error("snapshot: " + s.error);
  status.last_snapshot = s.dir;
  info("snapshot: " + std::to_string(s.files.size()) + " files in " + s.dir);
}

void App::open_url(const std::string& url) {
  const std::string err = media::open_url(url);
  if (err.empty()) info("opening " + url + " in the browser");
  else error("cannot open " + url + ": " + err);
}

// [SECTION] Detector
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

void App::load_preset(const std::string& text) {
  std::vector<std::string> errors;
  DetectorParams p = settings.params;
  std::vector<std::string> notes;
  const std::string path = preset_path(text, false);
  const bool ok = load_params_yaml(path, p, &errors, &notes);
  for (const auto& n : notes) warn("preset: " + n);
  if (ok) {
    settings.params = p;
    change_name = "preset " + fs::path(path).filename().string();   // names the undo entry
    info("preset: loaded " + path);
  } else {
    for (const auto& e : errors) error("preset: " + e);
    if (errors.empty()) error("preset: cannot load " + text);
  }
}

void App::save_preset(const std::string& text) {
  // A bare name goes to the user's presets folder; the folder is made first, so the first save works.
  const std::string path = preset_path(text, true);
  std::error_code ec;
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);
  std::string err;
  if (!save_params_yaml(path, settings.params, &err)) return error("preset: " + err);
  note_status("preset: saved " + fs::absolute(path).lexically_normal().string());
  list_presets();
  status.recent.add(ui::FileKind::preset, fs::absolute(path).lexically_normal().string());
  save_recent();
}

void App::sweep() {
  if (!view.has_region || !frame || sweep_future.valid()) return;
  std::string err;
  std::string list;
  for (const auto& n : settings.dictionaries) list += (list.empty() ? "" : ",") + n;
  auto dicts = parse_dictionaries(list, &err);
  if (!dicts) return error("sweep: " + err);
  status.sweep = {};
  status.sweep.running = true;
  status.sweep.region = view.region;
  sweep_progress = 0;
  sweep_cancel = false;
  std::shared_ptr<const Frame> f = frame;
  Detector det(std::move(*dicts), settings.params);
  sweep_future = std::async(std::launch::async, [this, f, det, region = view.region] {
    return sweep_region(f->image, det, region, [this](double p) { sweep_progress = p; }, &sweep_cancel);
  });
  info("sweep: trying the parameter table on frame " + std::to_string(f->index));
}

// [SECTION] Files
void App::save_script(const ui::SaveScript& r) {
  std::string err;
  const bool saved = write_file_atomically(r.path, r.text, &err);
  if (saved) info("saved " + r.path + " (the scene reloads by itself)");
  else error("cannot save " + r.path + ": " + err + "; your text is still in the editor");
  if (r.path == status.script_file.path) watch_file(r.path, true);   // the editor sees its save land now
  // The unsaved-edits question was answered "Save": what waited goes on once the save landed, not before.
  Dialogs::Unsaved& u = dialogs.unsaved;
  if (u.save_wait < 0) return;
  if (saved) return proceed();
  u.save_wait = -1;
  u.quit_waiting = false;
  u.deferred.reset();
}

void App::open_file(const ui::OpenFile& r) {
  if (r.kind == ui::FileKind::source && (r.path == "synthetic" || r.path.rfind("camera:", 0) == 0)) {
    open_path(r.kind, r.path);
    ++status.opened;
    return;
  }
  std::string path = r.path;
  if (path.rfind("~/", 0) == 0) {
    if (const char* home = std::getenv("HOME")) path = home + path.substr(1);
  }
  std::error_code ec;
  if (fs::is_directory(path, ec) && !r.folder_itself) return list_dir(path);   // else the browser's "Use this folder"
  if (!fs::exists(path, ec)) {
    status.listing.error = r.path + ": no such file or folder";
    return warn("open: " + status.listing.error);
  }
  open_path(r.kind, fs::absolute(path).lexically_normal().string());
  ++status.opened;
}

void App::write_marker_sheet(const ui::WriteMarkerSheet& r) {
  const std::string dict_name = !r.dictionary.empty() ? r.dictionary
                                : settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : settings.dictionaries[0];
  std::string err;
  auto dict = dictionary_by_name(dict_name, &err);
  if (!dict) return error("marker sheet: " + err);
  std::vector<int> ids;
  if (!parse_id_ranges(r.ids.empty() ? "0-11" : r.ids, dict->size(), &ids, &err))
    return error("marker sheet: ids '" + r.ids + "': " + err);
  const std::string path = fs::absolute(r.path).lexically_normal().string();
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  try {
    const SheetResult s = arwb::write_marker_sheet(*dict, ids, r.size_mm, SheetFormat::pdf, path);
    note_status("marker sheet: wrote " + path + " (" + std::to_string(s.pages) + " page(s), " +
                std::to_string(ids.size()) + " markers of " + dict_name + " at " + decimals_text(r.size_mm, 1) +
                " mm); print at 100% and check the 100 mm bar");
  } catch (const std::exception& e) {
    error("marker sheet: " + path + ": " + one_line_reason(e));
  }
}

void App::drop_calibration_view(const ui::DropCalibrationView& r) {
  if (!r.name.empty()) return engine->drop_calibration_view(r.name);
  // The number-th view kept (from 1), as clicking its bar does.
  const CalibrationSnapshot* c = frame ? frame->calibration.get() : nullptr;
  if (!c || r.number < 1 || r.number > static_cast<int>(c->views.size()))
    return warn("--actions calib_drop=" + std::to_string(r.number) + ": no such view (" +
                std::to_string(c ? c->views.size() : 0) + " kept)");
  engine->drop_calibration_view(c->views[static_cast<size_t>(r.number - 1)].name);
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

}  // namespace arwb
