// [SECTION] Index
//   Actions      --actions steps and the scene's dictionary
//   Frame state  forwarding edits to the engine, the region report, stats per frame
//   Frame loop   window, ImGui, menus, panels, status bar, stats at exit
// Requests are carried out in ui/requests.cpp; the layout file and presentation mode are in ui/layout.cpp.
#include "ui/window.hpp"

#include "ui/app.hpp"
#include "ui/gl_window.hpp"
#include "base/decimals.hpp"
#include "base/data_dirs.hpp"
#include "pose/marker_pose.hpp"
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_internal.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <thread>
#include <utility>

namespace arwb {

namespace fs = std::filesystem;

// [SECTION] Actions
void App::run_action(const Action& a) {
  ui::Panel p;
  if (a.verb == "open" || a.verb == "close") {
    if (a.arg == "all") {
      view.open.fill(a.verb == "open");
      return;
    }
    if (!ui::panel_from_key(a.arg, &p)) return warn("--actions: no panel '" + a.arg + "'");
    view.open[static_cast<size_t>(p)] = a.verb == "open";
    if (a.verb == "open") view.front = p;   // the active tab of its region in the current workspace
  } else if (a.verb == "workspace") {
    const int i = workspaces.find(a.arg);
    if (i < 0) return warn("--actions: no workspace '" + a.arg + "'");
    ui::switch_workspace(workspaces, i, view);
  } else if (a.verb == "save_workspace") {
    std::string why;
    if (!workspaces.save_as(a.arg, &why)) warn("--actions save_workspace: " + why);
  } else if (a.verb == "move") {
    // move=PANEL>OTHER: PANEL into the region showing OTHER (what dragging its tab there does).
    const size_t gt = a.arg.find('>');
    ui::Panel q;
    ui::Layout& l = workspaces.now().layout(view.presentation);
    if (gt == std::string::npos || !ui::panel_from_key(a.arg.substr(0, gt), &p) ||
        !ui::panel_from_key(a.arg.substr(gt + 1), &q) || ui::region_of(l, q) < 0) {
      return warn("--actions: move wants PANEL>PANEL_IN_THE_TARGET_REGION, not '" + a.arg + "'");
    }
    ui::move_panel(l, p, ui::region_of(l, q));
    view.open[static_cast<size_t>(p)] = true;   // a panel moved in from nowhere is open now
  } else if (a.verb == "splitter") {
    // splitter=I,RATIO: the I-th split of the current workspace (depth first) at RATIO (what dragging it does).
    int i = -1;
    float r = 0;
    ui::Layout& l = workspaces.now().layout(view.presentation);
    const std::vector<int> s = ui::splits(l);
    if (std::sscanf(a.arg.c_str(), "%d,%f", &i, &r) != 2 || i < 0 || i >= static_cast<int>(s.size()) || !(r >= 0.05f && r <= 0.95f)) {
      return warn("--actions: splitter wants I,RATIO (I < " + std::to_string(s.size()) + ", RATIO in 0.05..0.95), not '" + a.arg + "'");
    }
    l.nodes[static_cast<size_t>(s[static_cast<size_t>(i)])].ratio = r;
  } else if (a.verb == "source") {
    requests.push_back({ui::RequestKind::open_source, a.arg, 0, {}, {}});
  } else if (a.verb == "freeze" || a.verb == "unfreeze") {
    settings.frozen = a.verb == "freeze";
  } else if (a.verb == "next") {
    // next: the source's next frame, and for scripts and tests the window waits (up to 2 s) until the worker has
    // taken it and shows it, whatever the machine's speed (two steps a few frames apart had reached the worker as
    // one). A video or folder steps to the frame after the one shown (Next frame in the window takes what a
    // playing video's clock has reached: possibly none yet); other sources give their next frame, and a still
    // image none.
    forward_settings();   // a freeze of this same frame reaches the worker first
    const bool stepped = frame && (frame->source.kind == SourceKind::video || frame->source.kind == SourceKind::folder);
    const uint64_t ticket = stepped ? engine->step(1) : engine->next_frame();
    const auto end = Clock::now() + std::chrono::seconds(2);
    while (engine->served() < ticket && engine->running() && Clock::now() < end)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    if (engine->served() < ticket) warn("--actions next: the worker did not take the frame within 2 s");
    if (auto f = engine->latest()) frame = f;
  } else if (a.verb == "snapshot") {
    requests.push_back({ui::RequestKind::snapshot, "", 0, {}, {}});
  } else if (a.verb == "stage") {
    Stage s;
    if (a.arg == "input") view.pipeline_stage = -1;
    else if (stage_from_name(a.arg, &s)) view.pipeline_stage = static_cast<int>(s);
    else warn("--actions: no stage '" + a.arg + "'");
  } else if (a.verb == "select") {
    // select=N: candidate N; select=marker: the candidate that became the frame's first marker.
    view.selected_candidate = std::atoi(a.arg.c_str());
    if (a.arg == "marker" && frame) {
      view.selected_candidate = -1;
      for (size_t i = 0; i < frame->trace.candidates.size(); ++i) {
        if (frame->trace.candidates[i].marker == 0) view.selected_candidate = static_cast<int>(i);
      }
    }
    if (view.selected_candidate >= 0) view.show(ui::Panel::inspector);
  } else if (a.verb == "region") {
    float x, y, w, h;
    if (std::sscanf(a.arg.c_str(), "%f,%f,%f,%f", &x, &y, &w, &h) == 4 && w > 0 && h > 0) {
      view.region = {x, y, w, h};
      view.has_region = true;
      view.show(ui::Panel::why);
    } else {
      warn("--actions: region wants X,Y,W,H, not '" + a.arg + "'");
    }
  } else if (a.verb == "add_dictionary") {
    // What the Why panel's "Add ... to the searched dictionaries" button does.
    std::string err;
    if (const auto d = dictionary_by_name(a.arg, &err)) {
      if (std::find(settings.dictionaries.begin(), settings.dictionaries.end(), d->name()) == settings.dictionaries.end())
        settings.dictionaries.push_back(d->name());
    } else {
      warn("--actions add_dictionary: " + err);
    }
  } else if (a.verb == "sweep") {
    if (view.has_region) requests.push_back({ui::RequestKind::sweep, "", 0, view.region, {}});
  } else if (a.verb == "tour") {
    view.tour_active = true;
    settings.frozen = true;
    view.show(ui::Panel::tour);
    if (!a.arg.empty()) view.tour_step = std::atoi(a.arg.c_str());
  } else if (a.verb == "presentation") {
    set_presentation(!view.presentation);
  } else if (a.verb == "preset") {
    requests.push_back({ui::RequestKind::load_preset, a.arg, 0, {}, {}});
  } else if (a.verb == "scene") {
    requests.push_back({ui::RequestKind::load_scene, a.arg, 0, {}, {}});
  } else if (a.verb == "media") {
    view.show_media = a.arg != "off";
  } else if (a.verb == "pose" || a.verb == "labels") {
    // pose=axes,cube,alternative and labels=ids,dict,rejected,truth,peers: those drawn, the others not; all; none.
    const bool pose = a.verb == "pose";
    const std::vector<std::string> names = pose ? std::vector<std::string>{"axes", "cube", "alternative"}
                                                : std::vector<std::string>{"ids", "dict", "rejected", "truth", "peers"};
    std::vector<bool> on(names.size(), false);
    for (size_t at = 0; at <= a.arg.size();) {
      const size_t comma = std::min(a.arg.find(',', at), a.arg.size());
      const std::string kind = a.arg.substr(at, comma - at);
      at = comma + 1;
      const auto it = std::find(names.begin(), names.end(), kind);
      if (kind == "all") on.assign(names.size(), true);
      else if (it != names.end()) on[static_cast<size_t>(it - names.begin())] = true;
      else if (kind != "none" && !kind.empty()) {
        std::string known;
        for (const std::string& n : names) known += n + ", ";
        warn("--actions " + a.verb + "=" + a.arg + ": no kind '" + kind + "' (" + known + "all, none)");
        return;
      }
    }
    if (pose) {
      view.show_axes = on[0];
      view.show_cube = on[1];
      view.show_alternative = on[2];
    } else {
      view.label_ids = on[0];
      view.label_dict = on[1];
      view.show_rejected = on[2];
      view.show_truth = on[3];
      view.show_peer_opencv = view.show_peer_apriltag = on[4];
    }
  } else if (a.verb == "click") {
    // A click on the live view at image pixel X,Y: what a user's click on a web card does.
    double x = 0, y = 0;
    if (std::sscanf(a.arg.c_str(), "%lf,%lf", &x, &y) != 2) {
      error("--actions click=" + a.arg + ": expected X,Y in image pixels");
      return;
    }
    const int hit = frame ? overlay_at(frame->overlays, {x, y}, true) : -1;
    if (hit >= 0) requests.push_back({ui::RequestKind::open_url, frame->overlays[size_t(hit)].media.url, 0, {}, {}});
    else info("click " + a.arg + ": no web card there");
  } else if (a.verb == "peers") {
    settings.peer_opencv = settings.peer_apriltag = true;
  } else if (a.verb == "drop") {
    drop(a.arg);
  } else if (a.verb == "focus") {
    view.focus_field = a.arg;
    if (a.arg == "script") view.show(ui::Panel::script);
    if (a.arg == "source_path") view.show(ui::Panel::source);
    if (a.arg == "preset_path") view.show(ui::Panel::parameters);
  } else if (a.verb == "type") {
    // "\n" is Enter; everything else is typed as it is.
    for (size_t i = 0; i < a.arg.size(); ++i) {
      if (a.arg[i] == '\\' && i + 1 < a.arg.size() && a.arg[i + 1] == 'n') {
        typing.push_back('\n');
        ++i;
      } else {
        typing.push_back(static_cast<unsigned char>(a.arg[i]));
      }
    }
  } else if (a.verb == "undo") {
    undo();
  } else if (a.verb == "redo") {
    redo();
  } else if (a.verb == "set") {
    // set=NAME=VALUE: what letting go of a slider does, one completed edit.
    const size_t eq = a.arg.find('=');
    const ParamInfo* info = find_param(a.arg.substr(0, eq));
    std::string err;
    if (!info || eq == std::string::npos) warn("--actions set=" + a.arg + ": expected PARAM=VALUE");
    else if (!set_param(settings.params, *info, std::atof(a.arg.c_str() + eq + 1), &err)) warn("--actions: " + err);
  } else if (a.verb == "quit") {
    if (glfw_window) glfwSetWindowShouldClose(glfw_window, 1);
  } else if (a.verb == "answer") {
    answer = a.arg;
  } else if (a.verb == "browse") {
    for (int k = 0; k < ui::kFileKindCount; ++k)
      if (a.arg == ui::file_kind_name(static_cast<ui::FileKind>(k))) view.browse_kind = k;
  } else if (a.verb == "save_preset") {
    requests.push_back({ui::RequestKind::save_preset, a.arg, 0, {}, {}});
  } else if (a.verb == "sheet") {
    open_sheet_dialog();
  } else if (a.verb == "calib_board") {
    // calib_board=chessboard|charuco[,COLS,ROWS[,SQUARE_MM[,MARKER_MM]]]: the board the Calibrate workspace looks for.
    const std::string kind = a.arg.substr(0, a.arg.find(','));
    if (kind != "chessboard" && kind != "charuco") return warn("--actions calib_board: chessboard or charuco, not '" + a.arg + "'");
    BoardSpec b = default_board(kind == "charuco" ? BoardKind::charuco : BoardKind::chessboard);
    if (a.arg.size() > kind.size())
      std::sscanf(a.arg.c_str() + kind.size(), ",%d,%d,%lf,%lf", &b.cols, &b.rows, &b.square_mm, &b.marker_mm);
    if (const std::string why = b.problem(); !why.empty()) return warn("--actions calib_board=" + a.arg + ": " + why);
    settings.calibration.board = b;
  } else if (a.verb == "marker_size") {
    // marker_size=L: the printed marker's side (poses in its unit); 0: in marker sides.
    char* end = nullptr;
    const double v = std::strtod(a.arg.c_str(), &end);
    if (a.arg.empty() || *end != '\0' || !std::isfinite(v) || v < 0 || v > 1e6)
      return warn("--actions marker_size: a size from 0 (marker sides) to 1000000, not '" + a.arg + "'");
    settings.marker_size = v;
  } else if (a.verb == "calib_capture" || a.verb == "undistort") {
    if (a.arg != "on" && a.arg != "off") return warn("--actions " + a.verb + ": on or off, not '" + a.arg + "'");
    (a.verb == "undistort" ? settings.calibration.undistort : settings.calibration.capture) = a.arg == "on";
  } else if (a.verb == "calib_drop") {
    // calib_drop=N: the N-th view kept (from 1), as clicking its bar does.
    const int n = std::atoi(a.arg.c_str());
    const CalibrationSnapshot* c = frame ? frame->calibration.get() : nullptr;
    if (!c || n < 1 || n > static_cast<int>(c->views.size()))
      return warn("--actions calib_drop=" + a.arg + ": no such view (" + std::to_string(c ? c->views.size() : 0) + " kept)");
    requests.push_back({ui::RequestKind::calibration_drop, c->views[static_cast<size_t>(n - 1)].name, 0, {}, {}});
  } else if (a.verb == "calib_wait") {
    // calib_wait[=N]: for scripts and tests, the window waits (up to 120 s) until N views are kept and the views
    // are solved, whatever the machine's speed. The worker goes on meanwhile; the window is not drawn.
    const size_t want = static_cast<size_t>(std::max(0, std::atoi(a.arg.c_str())));
    const auto end = Clock::now() + std::chrono::seconds(120);
    // The settings changed this frame (a workspace switched to, capture turned off) reach the worker first.
    forward_settings();
    // Two frames newer than now: the worker may be finishing a frame begun before this frame's requests reached it.
    std::shared_ptr<const Frame> f = engine->latest();
    for (int i = 0; i < 2 && Clock::now() < end; ++i) f = engine->wait_newer(f ? f->index : 0, 60);
    while (Clock::now() < end) {
      const CalibrationSnapshot* c = f ? f->calibration.get() : nullptr;
      const bool settled = c && !c->solving && (c->solved_revision == c->revision || !c->solve_error.empty());
      if (c && c->views.size() >= want && settled && c->capture == settings.calibration.capture) {
        frame = f;
        return;
      }
      f = engine->wait_newer(f ? f->index : 0, 0.5);
    }
    warn("--actions calib_wait=" + a.arg + ": the calibration did not get there within 120 s");
  } else if (a.verb == "lab_plan") {
    // lab_plan=paper|FILE.yml: the Lab panel's plan, as its buttons set it.
    if (a.arg == "paper") settings.lab.plan = lab::paper_plan();
    else requests.push_back({ui::RequestKind::lab_read_plan, a.arg, 0, {}, {}});
  } else if (a.verb == "lab_frames") {
    const int n = std::atoi(a.arg.c_str());
    if (n < 1 || n > 10000) return warn("--actions lab_frames: 1 to 10000 frames per cell, not '" + a.arg + "'");
    settings.lab.plan.frames_per_cell = n;
  } else if (a.verb == "lab_axis") {
    // lab_axis=sizes_mm:65,39 (or distances_m:, lux:, or an added axis, tilts_deg: ...): what typing in the panel's
    // field does, or reading a plan file that gives it.
    const size_t colon = a.arg.find(':');
    const std::string key = a.arg.substr(0, colon);
    for (const lab::PlanAxis& axis : lab::plan_axes()) {
      if (key != axis.key || colon == std::string::npos) continue;
      Result<std::vector<double>> v = lab::parse_axis(axis, a.arg.substr(colon + 1));
      if (!v) return warn("--actions lab_axis: " + v.error());
      settings.lab.plan.*axis.values = *v;
      settings.lab.plan.name = "your plan";
      return;
    }
    std::string keys;
    for (const lab::PlanAxis& axis : lab::plan_axes()) keys += (keys.empty() ? "" : ", ") + std::string(axis.key) + ":";
    warn("--actions lab_axis: one of " + keys + " and values, not '" + a.arg + "'");
  } else if (a.verb == "lab_detectors") {
    std::vector<std::string> list;
    std::stringstream in(a.arg);
    for (std::string d; std::getline(in, d, ',');)
      if (!d.empty()) list.push_back(d);
    settings.lab.detectors = list;
  } else if (a.verb == "lab_run") {
    requests.push_back({ui::RequestKind::lab_start, "", 0, {}, {}});
  } else if (a.verb == "lab_stop") {
    requests.push_back({ui::RequestKind::lab_stop, "", 0, {}, {}});
  } else if (a.verb == "lab_wait") {
    // lab_wait[=CELLS]: for scripts and tests, the window waits (up to 600 s) until the run has finished that many
    // cells (all: when none is given) or ended. The window is not drawn meanwhile.
    handle_requests();   // a lab_run of this same frame starts first
    const int want = a.arg.empty() ? -1 : std::atoi(a.arg.c_str());
    const auto end = Clock::now() + std::chrono::seconds(600);
    while (Clock::now() < end) {
      const auto run = lab_session.snapshot();
      if (!run->running || (want >= 0 && run->cells_done() >= want)) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    poll_lab();
    if (lab_session.running() && want < 0) warn("--actions lab_wait: the run did not end within 600 s");
  } else if (a.verb == "lab_cell") {
    // lab_cell=I[,K]: cell I of the run (from 0, the table's order), at frame K; what clicking it does.
    int cell = -1, k = 0;
    if (std::sscanf(a.arg.c_str(), "%d,%d", &cell, &k) < 1) return warn("--actions lab_cell: CELL[,FRAME], not '" + a.arg + "'");
    requests.push_back({ui::RequestKind::lab_open_cell, std::to_string(k), cell, {}, {}});
  } else if (a.verb == "lab_why") {
    // lab_why: what the Lab panel's "Why not detected?" does on the frame shown (the region on the truth).
    if (!frame || frame->truth.empty()) return warn("--actions lab_why: the frame shown has no marker's truth");
    ui::why_on_marker(view, frame->truth[0].corners);
  } else if (a.verb == "lab_span") {
    // lab_span=start|end|whole: the Lab panel's span buttons on the video frame shown.
    lab::VideoRow& row = settings.lab.clip;
    const int at = frame ? frame->source.position : 0;
    if (a.arg == "start") row.first_frame = at;
    else if (a.arg == "end") row.last_frame = at;
    else if (a.arg == "whole") row.first_frame = row.last_frame = -1;
    else warn("--actions lab_span: start, end or whole, not '" + a.arg + "'");
  } else if (a.verb == "lab_clip") {
    // lab_clip=ID,SIZE_MM,DISTANCE_M,LUX[,DIR]: the clip's row as typed in the panel, then Save to videos.csv.
    lab::VideoRow& row = settings.lab.clip;
    char dir[1024] = "";
    if (std::sscanf(a.arg.c_str(), "%d,%lf,%lf,%lf,%1023[^\n]", &row.id, &row.size_mm, &row.distance_m, &row.lux,
                    dir) < 4)
      return warn("--actions lab_clip: ID,SIZE_MM,DISTANCE_M,LUX[,DIR], not '" + a.arg + "'");
    row.dictionary = settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : settings.dictionaries[0];
    settings.lab.videos_dir = dir;
    requests.push_back({ui::RequestKind::lab_save_clip, "", 0, {}, {}});
  } else if (a.verb == "lab_save") {
    requests.push_back({ui::RequestKind::lab_save, a.arg, 0, {}, {}});
  } else if (a.verb == "calib_reset") {
    requests.push_back({ui::RequestKind::calibration_reset, "", 0, {}, {}});
  } else if (a.verb == "calib_save") {
    requests.push_back({ui::RequestKind::calibration_save, a.arg, view.calibration_paper_files ? 1 : 0, {}, {}});
  } else if (a.verb == "export_dialog") {
    open_export_dialog(a.arg);
  } else if (a.verb == "export") {
    // export=PATH: what File > Export...'s Export button does, with the dialog's values (export_title=, ...).
    open_export_dialog(a.arg);
    export_dialog.opening = false;
    requests.push_back({ui::RequestKind::export_write, "", 0, {}, {}});
  } else if (a.verb == "export_title") {
    std::snprintf(export_dialog.title, sizeof export_dialog.title, "%s", a.arg.c_str());
  } else if (a.verb == "export_size") {
    const double mm = std::atof(a.arg.c_str());
    if (!(mm >= 1 && mm <= 1000)) return warn("--actions export_size: 1 to 1000 mm, not '" + a.arg + "'");
    export_dialog.size_mm = mm;
  } else if (a.verb == "export_calibration" || a.verb == "export_force") {
    if (a.arg != "on" && a.arg != "off") return warn("--actions " + a.verb + ": on or off, not '" + a.arg + "'");
    (a.verb == "export_force" ? export_dialog.force : export_dialog.use_calibration) = a.arg == "on";
  } else if (a.verb == "export_wait") {
    // export_wait[=S]: for scripts and tests, the window waits (up to S seconds, 120 by default) for the check or
    // export running to finish. The window is not drawn meanwhile.
    wait_export(a.arg.empty() ? 120 : std::clamp(std::atof(a.arg.c_str()), 0.0, 600.0));
  } else if (a.verb == "play") {
    requests.push_back({ui::RequestKind::play_bundle, a.arg, 0, {}, {}});
  } else if (a.verb == "play_args") {
    // play_args=ARGS: more arguments for the players File > Play bundle starts, split at spaces ("--frames 30").
    play_args.clear();
    std::istringstream in(a.arg);
    for (std::string w; in >> w;) play_args.push_back(w);
  } else if (a.verb == "play_wait") {
    // play_wait[=S]: waits (up to S seconds, 120 by default) until every player started has ended.
    wait_players(a.arg.empty() ? 120 : std::clamp(std::atof(a.arg.c_str()), 0.0, 600.0));
  } else if (a.verb == "help") {
    show_shortcuts |= a.arg == "shortcuts";
    show_first_steps |= a.arg == "first";
    show_about |= a.arg == "about";
  }
}

void App::open_sheet_dialog() {
  sheet.opening = true;
  sheet.dictionary = settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : settings.dictionaries[0];
  // Into the user's own folder, never the working folder (which may be the source tree or read-only).
  const std::string path = status.config_dir + "/marker-sheets/" + sheet.dictionary + ".pdf";
  std::snprintf(sheet.path, sizeof sheet.path, "%s", path.c_str());
}

// A newly (re)loaded scene that names a dictionary switches the detector to it, as `arwb render` does.
void App::sync_scene() {
  if (!frame || frame->scene.generation == scene_generation) return;
  scene_generation = frame->scene.generation;
  const std::string& d = frame->scene.dictionary;
  if (!d.empty() && (settings.dictionaries.size() != 1 || settings.dictionaries[0] != d)) {
    settings.dictionaries = {d};
    info("scene: detecting " + d + ", the scene's dictionary");
    change_name = "the scene's dictionary " + d;
  }
}

// [SECTION] Frame state
// On the synthetic source, the Calibrate workspace shows the kind of board it looks for (that kind's defaults: the
// paper's chessboard, the CLI's ChArUco board), so that a class sees calibration without a camera; leaving the
// workspace brings the markers back. A board the user chose in the Source panel is left as it is.
void App::follow_calibration_board(bool calibrating) {
  const bool synthetic = frame && frame->source.kind == SourceKind::synthetic;
  std::string& shown = settings.synthetic.board;
  if (calibrating && !calibrating_sent && synthetic && shown.empty()) synthetic_board_auto = "?";
  if (!synthetic_board_auto.empty() && shown != synthetic_board_auto && synthetic_board_auto != "?") {
    synthetic_board_auto.clear();   // the user chose another in the Source panel
    return;
  }
  if (calibrating && !synthetic_board_auto.empty())
    shown = synthetic_board_auto = board_kind_name(settings.calibration.board.kind);
  if (!calibrating && !synthetic_board_auto.empty()) {
    shown.clear();
    synthetic_board_auto.clear();
  }
}

void App::forward_settings() {
  const bool calibrating = view.open[static_cast<size_t>(ui::Panel::calibrate)] ||
                           view.open[static_cast<size_t>(ui::Panel::calibration_views)];
  follow_calibration_board(calibrating);
  if (!(settings.params == sent.params)) engine->set_params(settings.params);
  if (settings.dictionaries != sent.dictionaries) engine->set_dictionaries(settings.dictionaries);
  if (!(settings.acquisition == sent.acquisition)) engine->set_acquisition(settings.acquisition);
  if (!(settings.playback == sent.playback)) engine->set_playback(settings.playback);
  if (!(settings.synthetic == sent.synthetic)) engine->set_synthetic(settings.synthetic);
  if (settings.frozen != sent.frozen) engine->set_frozen(settings.frozen);
  if (settings.peer_opencv != sent.peer_opencv || settings.peer_apriltag != sent.peer_apriltag) {
    engine->set_peers(settings.peer_opencv, settings.peer_apriltag);
  }
  // A board that cannot exist (a ChArUco marker as large as its square, typed half-way) stays unsent.
  const BoardSpec board_sent = sent.calibration.board;
  bool board_ok = true;
  if (!(settings.calibration.board == sent.calibration.board)) {
    board_ok = settings.calibration.board.problem().empty();
    if (board_ok) engine->set_calibration_board(settings.calibration.board);
  }
  if (settings.calibration.capture != sent.calibration.capture) engine->set_calibration_capture(settings.calibration.capture);
  if (settings.calibration.undistort != sent.calibration.undistort) engine->set_undistort(settings.calibration.undistort);
  if (settings.marker_size != sent.marker_size) engine->set_marker_size(settings.marker_size);
  // The board is looked for only while a Calibrate panel is on screen.
  if (calibrating != calibrating_sent) engine->set_calibrating(calibrating_sent = calibrating);
  sent = settings;
  if (!board_ok) sent.calibration.board = board_sent;
}

void App::update_region() {
  if (!view.has_region || !frame) return;
  const cv::Rect2f& r = view.region;
  if (frame->index == region_frame && r == region_done) return;
  // With the dictionaries the frame was detected with: the report names a marker of any other one.
  view.region_report = explain_region(frame->trace, r, frame->params, frame->dictionaries);
  region_frame = frame->index;
  region_done = r;
}

void App::record_stats() {
  if (!frame || frame->index == last_frame_index) return;
  last_frame_index = frame->index;
  ++detected_seen;
  std::array<float, kStageCount + 1> row{};
  for (const StageRecord& s : frame->trace.stages) {
    const auto i = static_cast<size_t>(s.stage);
    row[i] = static_cast<float>(s.ms);
    stage_ms_sum[i] += s.ms;
    ++stage_ms_n[i];
  }
  row[kStageCount] = static_cast<float>(frame->detect_ms);
  detect_ms_sum += frame->detect_ms;
  for (const PeerDetections& p : frame->peers) {
    if (!p.error.empty()) continue;
    peer_ms[p.name].first += p.ms;
    ++peer_ms[p.name].second;
  }
  status.history.push_back(row);
  while (status.history.size() > 300) status.history.pop_front();
  // Each track's pose over the last frames (the Pose panel's plots); tracks gone are forgotten.
  std::map<uint64_t, std::deque<ui::PoseSample>> poses;
  for (const TrackedMarker& t : frame->tracks) {
    if (!t.pose) continue;
    auto& h = poses[t.track_id];
    if (auto it = status.pose_history.find(t.track_id); it != status.pose_history.end()) h = std::move(it->second);
    const PoseAngles a = pose_angles(t.pose->pose);
    h.push_back({static_cast<float>(frame->time_s), static_cast<float>(a.distance),
                 static_cast<float>(t.pose->ambiguity), static_cast<float>(t.pose->pose.error_px),
                 static_cast<float>(t.pose->alternative.error_px), static_cast<float>(a.tilt_deg)});
    while (h.size() > 300) h.pop_front();
  }
  status.pose_history = std::move(poses);
}

// [SECTION] Frame loop
// Keys (ImGui 1.86 indexes keys by GLFW key code). None fires while a text field has the keyboard: io.WantTextInput
// alone says what the previous frame wanted, so a field activated in this frame (or a popup's field) would let
// the first letter typed through as a shortcut; the active item, looked at now, is what is being typed into.
void App::handle_keys() {
  const ImGuiIO& io = ImGui::GetIO();
  const ImGuiContext& g = *ImGui::GetCurrentContext();
  const bool text_field = io.WantTextInput || (g.ActiveId != 0 && g.ActiveId == g.InputTextState.ID);
  // Ctrl+Q types nothing, so it quits from a text field too (with the unsaved-edits question).
  if (ImGui::IsKeyPressed(GLFW_KEY_Q) && io.KeyCtrl && glfw_window) glfwSetWindowShouldClose(glfw_window, 1);
  if (text_field || ImGui::GetTopMostPopupModal() != nullptr) return;
  if (ImGui::IsKeyPressed(GLFW_KEY_S) && !io.KeyCtrl) requests.push_back({ui::RequestKind::snapshot, "", 0, {}, {}});
  if (ImGui::IsKeyPressed(GLFW_KEY_SPACE)) settings.frozen = !settings.frozen;
  if (ImGui::IsKeyPressed(GLFW_KEY_N) && !io.KeyCtrl) requests.push_back({ui::RequestKind::next_frame, "", 0, {}, {}});
  if (ImGui::IsKeyPressed(GLFW_KEY_T) && !io.KeyCtrl) {
    view.tour_active = true;
    settings.frozen = true;
    view.show(ui::Panel::tour);
  }
  if (ImGui::IsKeyPressed(GLFW_KEY_F5)) set_presentation(!view.presentation);
  if (ImGui::IsKeyPressed(GLFW_KEY_Z) && io.KeyCtrl) {
    if (io.KeyShift) redo();
    else undo();
  }
}

void App::draw_menu(GLFWwindow* window) {
  if (!ImGui::BeginMainMenuBar()) return;
  if (ImGui::BeginMenu("File")) {
    if (ImGui::MenuItem("Synthetic source")) requests.push_back({ui::RequestKind::open_source, "synthetic", 0, {}, {}});
    // The browser opens at the next frame's draw_dialogs: a menu item cannot open a modal inside the menu.
    if (ImGui::MenuItem("Open source...")) view.browse_kind = static_cast<int>(ui::FileKind::source);
    if (ImGui::MenuItem("Open scene...")) view.browse_kind = static_cast<int>(ui::FileKind::scene);
    if (ImGui::MenuItem("Load preset...")) view.browse_kind = static_cast<int>(ui::FileKind::preset);
    if (ImGui::BeginMenu("Recent", !status.recent.of(ui::FileKind::source).empty() ||
                                       !status.recent.of(ui::FileKind::scene).empty() ||
                                       !status.recent.of(ui::FileKind::preset).empty())) {
      for (ui::FileKind k : {ui::FileKind::source, ui::FileKind::scene, ui::FileKind::preset}) {
        for (const std::string& p : status.recent.of(k)) {
          const std::string label = std::string(ui::file_kind_name(k)) + ": " + p;
          if (ImGui::MenuItem(label.c_str())) open_path(k, p);
        }
      }
      ImGui::EndMenu();
    }
    ImGui::Separator();
    if (ImGui::MenuItem("Snapshot", "S")) requests.push_back({ui::RequestKind::snapshot, "", 0, {}, {}});
    if (ImGui::MenuItem("Print marker sheet...")) open_sheet_dialog();
    ImGui::Separator();
    // The paper's Code Generator: the scene as a bundle that runs on its own, and trying one in the player.
    if (ImGui::MenuItem("Export...", nullptr, false, frame && !frame->scene.file.empty())) open_export_dialog();
    if (ImGui::MenuItem("Play bundle...")) view.browse_kind = static_cast<int>(ui::FileKind::bundle);
    ImGui::Separator();
    if (ImGui::MenuItem("Quit", "Ctrl+Q")) glfwSetWindowShouldClose(window, 1);
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Edit")) {
    const std::string u = history.undo_name(), r = history.redo_name();
    if (ImGui::MenuItem(u.empty() ? "Undo" : ("Undo " + u).c_str(), "Ctrl+Z", false, !u.empty())) undo();
    if (ImGui::MenuItem(r.empty() ? "Redo" : ("Redo " + r).c_str(), "Ctrl+Shift+Z", false, !r.empty())) redo();
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("View")) {
    for (int i = 0; i < ui::kPanelCount; ++i) {
      ImGui::MenuItem(ui::panel_title(static_cast<ui::Panel>(i)), nullptr, &view.open[static_cast<size_t>(i)]);
    }
    ImGui::Separator();
    bool pres = view.presentation;
    if (ImGui::MenuItem("Presentation mode", "F5", &pres)) set_presentation(pres);
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Teach")) {
    if (ImGui::MenuItem("Guided tour", "T")) {
      view.tour_active = true;
      settings.frozen = true;  // a lesson explains one frame; "Next frame" moves on
      view.show(ui::Panel::tour);
    }
    ImGui::MenuItem("Freeze frame", "Space", &settings.frozen);
    if (ImGui::MenuItem("Next frame", "N")) requests.push_back({ui::RequestKind::next_frame, "", 0, {}, {}});
    ImGui::EndMenu();
  }
  draw_help_menu();
  ImGui::EndMainMenuBar();
}

void App::draw_status_bar(float height) {
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos({vp->Pos.x, vp->Pos.y + vp->Size.y - height});
  ImGui::SetNextWindowSize({vp->Size.x, height});
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                                 ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav |
                                 ImGuiWindowFlags_NoBringToFrontOnFocus;
  ImGui::Begin("##status", nullptr, flags);
  ImGui::Text("%s | UI %.0f fps | detection %.0f fps | %s", status.source.text().c_str(), status.ui_fps, status.detect_fps,
              settings.frozen ? "FROZEN" : "live");
  // A note (undo, redo, a file written) stays for a while; then the newest warning or error.
  const double now = std::chrono::duration<double>(Clock::now() - t0).count();
  if (!note.empty() && now - note_time < kNoteSeconds) {
    ImGui::SameLine();
    ImGui::TextColored(ImVec4(0.6f, 0.85f, 1, 1), "| %s", note.c_str());
  }
  // A scene that runs with mappings skipped, disabled or failing says so for as long as it lasts.
  if (frame) {
    const auto& rows = frame->scene.mappings;
    if (const auto bad = std::count_if(rows.begin(), rows.end(), [](const MappingRow& r) { return r.health != MappingHealth::ok; })) {
      ImGui::SameLine();
      ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "| scene: %d of %zu mappings not working", static_cast<int>(bad), rows.size());
    }
  }
  // The newest warning or error stays visible for a while.
  for (auto it = log_copy.rbegin(); it != log_copy.rend(); ++it) {
    const double age = std::chrono::duration<double>(Clock::now() - t0).count() - it->time_s;
    if (age > 15) break;
    if (it->level == LogLevel::info) continue;
    ImGui::SameLine();
    ImGui::TextColored(it->level == LogLevel::error ? ImVec4(1, 0.35f, 0.3f, 1) : ImVec4(1, 0.8f, 0.3f, 1), "| %s",
                       it->text.c_str());
    break;
  }
  ImGui::End();
}

bool App::take_screenshot(const std::string& path, GLFWwindow* window) {
  std::string why;
  if (ui::save_window_image(window, path, &why)) {
    info("screenshot: " + path);
    return true;
  }
  error("screenshot: " + why);
  return false;
}

namespace {
App* g_app = nullptr;   // for GLFW's drop callback, which has no user pointer of its own to spare
void on_drop(GLFWwindow*, int count, const char** paths) {
  if (!g_app) return;
  for (int i = 0; i < count; ++i) g_app->dropped.emplace_back(paths[i]);
}
}  // namespace

int run_workbench(const WorkbenchOptions& options) {
  App app;
  app.opt = options;
  app.log.verbose = options.verbose;
  std::vector<Action> actions;
  {
    std::string err;
    if (!parse_actions(options.actions, &actions, &err)) {
      std::fprintf(stderr, "arwb: %s\n", err.c_str());
      return 2;
    }
  }
  ui::GlWindow gl;
  if (!ui::open_gl_window("arwb", "ArUco Workbench", options.window, false, &gl)) return 1;
  GLFWwindow* window = gl.window;
  app.glfw_window = window;
  g_app = &app;
  glfwSetDropCallback(window, on_drop);
  app.base_style = ImGui::GetStyle();
  app.font_normal = gl.font_normal;
  app.fonts_large = gl.fonts_large;

  const std::string config_dir = options.config_dir.empty() ? default_config_dir() : options.config_dir;
  std::error_code ec;
  fs::create_directories(config_dir, ec);
  const std::string ini_path = config_dir + "/imgui.ini";
  const std::string workspaces_path = config_dir + "/workspaces.json";
  load_layout(ini_path);
  app.load_workspaces(workspaces_path);
  app.status.config_dir = config_dir;
  app.load_recent();
  {
    int ww = 0, wh = 0;
    glfwGetWindowSize(window, &ww, &wh);
    app.window_height = static_cast<float>(wh);
  }
  if (options.presentation) app.set_presentation(true);
  ui::switch_workspace(app.workspaces, app.workspaces.current, app.view);   // view.open as the workspace has it

  // Tour text.
  {
    const std::string path = options.tour_path.empty() ? data_dirs().assets + "/teaching/tour.txt"
                                                        : options.tour_path;
    std::vector<std::string> errors;
    load_tour(path, &app.tour, &errors);
    for (const auto& e : errors) app.warn("tour: " + e);
  }

  app.settings.params = options.engine.params;
  app.settings.dictionaries = options.engine.dictionaries;
  app.settings.acquisition = options.engine.acquisition;
  app.settings.marker_size = options.engine.marker_size;
  app.sent = app.settings;
  app.committed = {app.settings.params, app.settings.dictionaries};
  app.engine = std::make_unique<Engine>(options.engine, [&app](int level, const std::string& m) {
    app.log.add(level == 0 ? LogLevel::info : (level == 1 ? LogLevel::warning : LogLevel::error), m);
  });
  app.engine->start();
  app.status.cameras = list_cameras();
  app.status.assets_dir = data_dirs().assets;     // installed beside the binary, or the source tree's
  app.status.scripts_dir = data_dirs().examples;
  app.list_presets();
  app.list_examples();
  app.compositor = std::make_unique<render::Compositor>(4);
  if (!options.engine.scene_file.empty()) {
    for (ui::Panel p : {ui::Panel::scene, ui::Panel::console}) app.view.open[static_cast<size_t>(p)] = true;
  }

  const double ui_period = 1.0 / 60.0;
  int ui_frames = 0;
  size_t next_action = 0;
  auto loop_start = Clock::now();
  auto last = Clock::now();
  for (;;) {
    glfwPollEvents();
    // Closing the window, Ctrl+Q, File > Quit: with unsaved edits in the Script editor, ask first.
    if (glfwWindowShouldClose(window)) {
      if (!app.view.script_unsaved || app.quit_confirmed) break;
      glfwSetWindowShouldClose(window, 0);
      if (!app.quit_waiting && !app.deferred) {
        app.quit_waiting = true;
        app.unsaved_ask = true;
      }
    }
    app.feed_typing();
    for (const std::string& p : std::exchange(app.dropped, {})) app.drop(p);
    app.frame = app.engine->latest();
    app.status.source = app.engine->source();
    app.status.detect_fps = app.engine->detect_fps();
    app.log.sync(app.log_copy, app.log_seen);
    app.status.log = &app.log_copy;
    app.record_stats();
    app.poll_background();
    app.update_region();
    // Before a scripted screenshot, make sure there is a finished frame to show.
    if (!app.frame && options.frames > 0) app.frame = app.engine->wait_newer(0, 5.0);

    // Panels flip these; the font and style change between frames, never inside one. A resized window may want
    // another presentation scale.
    {
      int ww = 0, wh = 0;
      glfwGetWindowSize(window, &ww, &wh);
      app.window_height = static_cast<float>(wh);
    }
    if (app.view.presentation != app.presentation_applied ||
        (app.view.presentation && app.scale != presentation_scale(app.window_height))) {
      app.set_presentation(app.view.presentation);
    }
    if (!app.view.open[static_cast<size_t>(ui::Panel::tour)]) app.view.tour_active = false;
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    while (next_action < actions.size() && actions[next_action].frame <= ui_frames) {
      app.run_action(actions[next_action++]);
    }
    app.draw_menu(window);
    const float status_h = ImGui::GetFrameHeightWithSpacing() + 4;
    const ImGuiViewport* vp = ImGui::GetMainViewport();
    const float menu_h = ImGui::GetFrameHeight();
    ui::Context ctx{app.frame.get(), app.settings, app.view, app.status, app.requests, app.textures, app.tour,
                    app.scale, nullptr};
    app.sync_scene();
    // The scene's media on the frame: drawn every UI frame, so a video's texture moves on between detections.
    if (app.frame && app.view.show_media && !app.frame->scene.file.empty()) {
      const auto c0 = Clock::now();
      if (app.compositor->draw(app.frame->image, app.frame->index, app.frame->overlays)) {
        ctx.composite = reinterpret_cast<ImTextureID>(static_cast<intptr_t>(app.compositor->texture()));
        app.composite_ms += std::chrono::duration<double, std::milli>(Clock::now() - c0).count();
        ++app.composites;
      } else if (app.composites >= 0) {
        app.error("media: " + app.compositor->error());
        app.composites = -1;   // said once
      }
    }
    const auto tp0 = Clock::now();
    // The main area between the menu bar and the status bar: the current workspace's regions.
    ui::draw_workspace(ctx, app.workspaces, {vp->Pos.x, vp->Pos.y + menu_h},
                       {vp->Size.x, vp->Size.y - menu_h - status_h}, [&ctx](ui::Panel p) { ui::draw_panel(p, ctx); },
                       &app.audit);
    app.draw_dialogs(ctx);
    // After every panel and dialog, so a text field activated this very frame (a click, a dialog's field taking
    // the keyboard) is known: see handle_keys.
    app.handle_keys();
    app.track_edits();
    app.draw_status_bar(status_h);
    ImGui::Render();
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window, &fw, &fh);
    glViewport(0, 0, fw, fh);
    glClearColor(0.08f, 0.08f, 0.1f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    const auto tp1 = Clock::now();
    {
      const ImDrawData* dd = ImGui::GetDrawData();
      int cmds = 0;
      for (int i = 0; i < dd->CmdListsCount; ++i) cmds += dd->CmdLists[i]->CmdBuffer.Size;
      app.draw_calls += cmds;
      app.vertices += dd->TotalVtxCount;
    }
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glFinish();
    const auto tp2 = Clock::now();
    app.textures.end_frame();
    ++ui_frames;
    const bool last_frame = options.frames > 0 && ui_frames >= options.frames;
    // --screenshot: the last frame drawn, whether the run ends by --frames or by closing the window.
    if (!options.screenshot.empty() && (last_frame || glfwWindowShouldClose(window))) {
      app.take_screenshot(options.screenshot, window);
    }
    glfwSwapBuffers(window);
    const auto tp3 = Clock::now();
    app.ui_ms[0] += std::chrono::duration<double, std::milli>(tp1 - tp0).count();
    app.ui_ms[1] += std::chrono::duration<double, std::milli>(tp2 - tp1).count();
    app.ui_ms[2] += std::chrono::duration<double, std::milli>(tp3 - tp2).count();
    app.handle_requests();
    app.forward_settings();

    // UI pacing and its fps.
    const auto now = Clock::now();
    app.ui_frame_times.push_back(std::chrono::duration<double>(now - loop_start).count());
    while (app.ui_frame_times.size() > 1 && app.ui_frame_times.front() < app.ui_frame_times.back() - 1.0) {
      app.ui_frame_times.pop_front();
    }
    if (app.ui_frame_times.size() > 1) {
      app.status.ui_fps = static_cast<double>(app.ui_frame_times.size() - 1) /
                          (app.ui_frame_times.back() - app.ui_frame_times.front());
    }
    if (last_frame) break;
    const double spent = std::chrono::duration<double>(now - last).count();
    if (spent < ui_period) std::this_thread::sleep_for(std::chrono::duration<double>(ui_period - spent));
    last = Clock::now();
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - loop_start).count();
  if (app.sweep_future.valid()) {
    app.sweep_cancel = true;
    app.sweep_future.wait();
  }
  const uint64_t detected = app.engine->frames_done();
  // Quitting waits for the worker half a second at most: one stuck in a scene's library call must not hold the
  // window open (the UI never waits for it while running, so frames were drawn all along).
  const bool worker_stopped = app.engine->stop(0.5);

  g_app = nullptr;
  save_layout(ini_path);   // ImGui's own: table columns
  app.save_workspaces(workspaces_path);
  if (options.stats) {
    using Json = nlohmann::ordered_json;
    auto per = [](double sum, int n) { return sum / std::max(1, n); };
    Json s = {{"ui_fps", round_decimals(elapsed > 0 ? ui_frames / elapsed : 0, 1)},
              {"detect_fps", round_decimals(elapsed > 0 ? static_cast<double>(detected) / elapsed : 0, 1)},
              {"frames", ui_frames},
              {"detected", detected},
              {"stages", Json::object()}};
    for (int i = 0; i < kStageCount; ++i)
      if (const int n = app.stage_ms_n[static_cast<size_t>(i)])
        s["stages"][std::string(stage_name(static_cast<Stage>(i)))] =
            round_decimals(app.stage_ms_sum[static_cast<size_t>(i)] / n, 3);
    // Detection against the peers on the same frames (when they ran): the same run, the same machine load.
    s["detect_ms"] = round_decimals(per(app.detect_ms_sum, app.detected_seen), 3);
    s["peers_ms"] = Json::object();
    for (const auto& [name, v] : app.peer_ms) s["peers_ms"][name] = round_decimals(per(v.first, v.second), 3);
    s["fps_cap"] = round_decimals(app.settings.acquisition.fps_cap, 1);
    s["overlays"] = app.frame ? app.frame->overlays.size() : 0;
    s["composite_ms"] = round_decimals(per(app.composite_ms, app.composites), 2);
    s["scene"] = app.frame ? app.frame->scene.file : "";
    s["scene_ok"] = app.frame && app.frame->scene.ok;
    // Per mapping of the scene: ok, or error / disabled / skipped with the reason and the line it points at.
    s["scene_mappings"] = Json::array();
    if (app.frame)
      for (const MappingRow& r : app.frame->scene.mappings)
        s["scene_mappings"].push_back({{"ids", r.ids},
                                       {"health", mapping_health_name(r.health)},
                                       {"reason", r.reason},
                                       {"line", r.health == MappingHealth::ok ? r.line : r.reason_line}});
    {
      app.log.sync(app.log_copy, app.log_seen);
      int errors = 0;
      for (const LogEntry& e : app.log_copy) errors += e.level == LogLevel::error;
      s["log_errors"] = errors;   // what the Log panel's "error (N)" counts
    }
    s["ui_ms"] = {{"panels", round_decimals(per(app.ui_ms[0], ui_frames), 2)},
                  {"render", round_decimals(per(app.ui_ms[1], ui_frames), 2)},
                  {"swap", round_decimals(per(app.ui_ms[2], ui_frames), 2)},
                  {"draw_calls", std::llround(per(app.draw_calls, ui_frames))},
                  {"vertices", std::llround(per(app.vertices, ui_frames))}};
    s["markers"] = app.frame ? app.frame->trace.markers.size() : 0;
    // Each track's pose on the last frame, the camera it came from, and how many the live view drew in 3D.
    s["poses"] = Json::array();
    if (app.frame)
      for (const TrackedMarker& t : app.frame->tracks)
        if (t.pose)
          s["poses"].push_back({{"id", t.id},
                                {"instance", t.instance},
                                {"distance", round_decimals(pose_angles(t.pose->pose).distance, 4)},
                                {"tvec", {round_decimals(t.pose->pose.tvec[0], 4), round_decimals(t.pose->pose.tvec[1], 4),
                                          round_decimals(t.pose->pose.tvec[2], 4)}},
                                {"error_px", round_decimals(t.pose->pose.error_px, 3)},
                                {"alternative_error_px", round_decimals(t.pose->alternative.error_px, 3)},
                                {"ambiguity", round_decimals(t.pose->ambiguity, 3)},
                                {"chosen_by_previous", t.pose->chosen_by_previous}});
    s["pose_camera"] = app.frame ? (app.frame->pose_camera.assumed ? "assumed" : app.frame->pose_camera.source) : "";
    s["pose_marker_side"] = app.frame ? app.frame->pose_marker_side : 1.0;
    s["pose_drawn"] = app.view.pose_drawn;
    const ui::LabelReport& lr = app.view.labels;
    s["labels"] = {{"drawn", lr.drawn},         {"hidden", lr.hidden},         {"leaders", lr.leaders},
                   {"shortened", lr.shortened}, {"overlaps", lr.overlaps},     {"on_corners", lr.on_corners},
                   {"boxes", lr.boxes}};
    s["source"] = app.engine->source().text();
    s["synthetic_board"] = app.settings.synthetic.board;   // what the synthetic source shows: "" markers, or a board
    s["problems"] = app.log.problems();
    if (app.view.has_region) {
      // The Why panel's report on the last frame: its headline and the dictionary it advises adding.
      const RegionReport& rep = app.view.region_report;
      Json why = {{"summary", rep.summary},
                  {"candidate", rep.candidates.empty() ? -1 : rep.candidates.front().index},
                  {"dictionaries", app.settings.dictionaries}};
      if (!rep.other_dictionaries.empty()) {
        why["other_dictionary"] = rep.other_dictionaries.front().dict;
        why["other_id"] = rep.other_dictionaries.front().id;
      }
      s["why"] = why;
    }
    {
      // The Lab workspace: the run's progress, each detector's P_Rec per cell (null: not finished), the cell shown.
      Json lab = {{"running", false}, {"cells", 0}, {"cells_done", 0}};
      if (const lab::LabProgress* p = app.status.lab.get()) {
        lab = {{"running", p->running},        {"finished", p->finished},       {"error", p->error},
               {"plan", p->plan.name},          {"cells", p->cells.size()},      {"cells_done", p->cells_done()},
               {"frames_done", p->frames_done}, {"frames_total", p->frames_total}, {"detectors", p->options.detectors},
               {"camera", p->options.camera_name}};
        Json rates = Json::object();
        for (size_t d = 0; d < p->options.detectors.size(); ++d) {
          Json cells = Json::array();
          for (const auto& r : p->results)
            cells.push_back(r ? Json(round_decimals(r->detectors[d].p_rec(), 2)) : Json());
          rates[p->options.detectors[d]] = cells;
        }
        lab["p_rec"] = rates;
        if (app.status.lab_cell >= 0 && size_t(app.status.lab_cell) < p->results.size() && p->results[size_t(app.status.lab_cell)]) {
          Json marks = Json::object();
          for (size_t d = 0; d < p->options.detectors.size(); ++d)
            marks[p->options.detectors[d]] = p->results[size_t(app.status.lab_cell)]->detectors[d].marks;
          lab["cell_marks"] = marks;
        }
      }
      lab["cell_open"] = app.frame && app.frame->source.kind == SourceKind::lab ? app.status.lab_cell : -1;
      lab["frame"] = app.frame && app.frame->source.kind == SourceKind::lab ? app.frame->source.position : -1;
      lab["message"] = app.status.lab_message;
      lab["plan_set"] = app.settings.lab.plan.name;   // the panel's plan (what Run would run)
      s["lab"] = lab;
    }
    {
      // File > Export... and File > Play bundle...: the last check, the last export, the players started.
      const App::ExportDialog& d = app.export_dialog;
      Json rows = Json::array();
      if (d.plan)
        for (const bundle::SelfTestRow& r : d.plan->manifest.self_test)
          rows.push_back({{"id", r.id}, {"line", r.mapping_line}, {"media", r.media}, {"detected", r.detected},
                          {"fired", r.fired}, {"why", r.detail}});
      s["export"] = {{"checked", d.plan != nullptr},
                     {"self_test_passed", d.plan && d.plan->manifest.self_test_passed},
                     {"self_test", rows},
                     {"error", d.error},
                     {"warnings", Json::array()},
                     {"written", d.written}};
      if (d.plan)
        for (const std::string& w : d.plan->warnings) s["export"]["warnings"].push_back(export_window_wording(w));
      std::lock_guard lock(app.players->mutex);
      s["players"] = {{"started", app.players->started},
                      {"ended", app.players->ended},
                      {"refused", app.players->refused},
                      {"running", app.players->running},
                      {"exit_codes", app.players->exit_codes}};
    }
    s["frozen"] = app.settings.frozen;
    s["tour_active"] = app.view.tour_active;
    s["modal"] = app.modal;
    s["script_unsaved"] = app.view.script_unsaved;
    s["undo"] = app.history.undo_name();
    s["redo"] = app.history.redo_name();
    s["note"] = app.note;
    s["params"] = Json::object();
    for (const ParamInfo& info : param_table()) s["params"][info.name] = get_param(app.settings.params, info);
    s["dictionaries"] = app.settings.dictionaries;
    // The Calibrate workspace's session as the last frame had it: views kept, refusals by reason, the newest solve
    // and its checklist; the calibration loaded with --calib; what the live view was undistorted with.
    {
      Json c = {{"active", app.frame && app.frame->calibration != nullptr}};
      if (const CalibrationSnapshot* k = app.frame ? app.frame->calibration.get() : nullptr) {
        c["board"] = k->board.describe();
        c["capture"] = k->capture;
        c["frames"] = k->frames;
        c["boards"] = k->boards;
        c["skipped"] = k->skipped;
        c["views"] = k->views.size();
        c["kept"] = k->tally.count("kept") ? k->tally.at("kept") : 0;
        c["dropped"] = k->dropped;
        Json refused = Json::object();
        for (const auto& [kind, n] : k->tally)
          if (kind != "kept") refused[kind] = n;
        c["refused"] = refused;
        c["verdict"] = k->verdict.reason;
        // The board as the live view draws it: found on the very frame shown (not a frame before it).
        c["board_on_frame"] = k->frame_name == app.frame->calibration_name && k->detection.found;
        c["solving"] = k->solving;
        c["solve_error"] = k->solve_error;
        c["coverage"] = {{"x", round_decimals(k->bars.x, 3)}, {"y", round_decimals(k->bars.y, 3)},
                         {"size", round_decimals(k->bars.size, 3)}, {"skew", round_decimals(k->bars.skew, 3)}};
        if (const Solution* sol = k->solution.get()) {
          const cv::Matx33d& K = sol->calibration.camera_matrix;
          c["solved_views"] = sol->view_names.size();
          c["current"] = k->current();
          c["rms"] = round_decimals(sol->rms, 4);
          c["fx"] = round_decimals(K(0, 0), 3);
          c["fy"] = round_decimals(K(1, 1), 3);
          c["cx"] = round_decimals(K(0, 2), 3);
          c["cy"] = round_decimals(K(1, 2), 3);
          c["distortion"] = sol->calibration.distortion;
          Json checks = Json::array();
          for (const Check& ch : sol->report.checklist) checks.push_back({{"name", ch.name}, {"ok", ch.ok}});
          c["checklist"] = checks;
          c["cross_validation_max_px"] = round_decimals(sol->report.cross_validation_max_px, 3);
        }
      }
      if (app.frame && app.frame->calibration_truth) {
        const cv::Matx33d& T = app.frame->calibration_truth->camera_matrix;
        c["truth"] = {{"fx", round_decimals(T(0, 0), 3)}, {"fy", round_decimals(T(1, 1), 3)},
                      {"cx", round_decimals(T(0, 2), 3)}, {"cy", round_decimals(T(1, 2), 3)}};
      }
      c["loaded"] = app.frame && app.frame->loaded_calibration ? app.frame->loaded_calibration->source : "";
      c["undistorted_by"] = app.frame ? app.frame->undistorted_by : "";
      s["calibration"] = c;
    }
    // The layout as drawn in the last frame: regions, overlaps, anything cut off (ui/workspace.hpp LayoutAudit).
    {
      Json regions = Json::array();
      Json clipped = Json::array();
      for (const ui::LayoutAudit::Region& r : app.audit.regions) {
        Json panels = Json::array();
        for (ui::Panel p : r.tabs) panels.push_back(ui::panel_key(p));
        regions.push_back({{"panels", panels},
                           {"front", r.front == ui::Panel::count ? "" : ui::panel_key(r.front)},
                           {"rect", {std::lround(r.pos.x), std::lround(r.pos.y), std::lround(r.size.x), std::lround(r.size.y)}}});
        for (ui::Panel p : r.tabs)
          for (const std::string& what : app.audit.clipped[static_cast<size_t>(p)])
            clipped.push_back({{"panel", ui::panel_key(p)}, {"what", what}});
      }
      s["layout"] = {{"workspace", app.workspaces.now().name},
                     {"presentation", app.view.presentation},
                     {"scale", round_decimals(app.scale, 3)},
                     {"font_px", round_decimals(ImGui::GetFontSize(), 1)},
                     {"regions", regions},
                     {"overlaps", app.audit.overlaps},
                     {"clipped", clipped}};
    }
    std::printf("%s\n", s.dump(-1, ' ', false, Json::error_handler_t::replace).c_str());
  }
  if (!worker_stopped) {
    // The layout is saved; the worker still runs on its own state, so leave without the destructors it could race.
    std::fprintf(stderr, "arwb: the worker did not stop within 0.5 s (stuck in a scene's script?); quitting without it\n");
    std::fflush(stdout);
    std::fflush(stderr);
    std::_Exit(0);
  }
  app.textures = render::TextureCache{};
  app.compositor.reset();
  ui::close_gl_window(gl);
  return 0;
}

}  // namespace arwb
