// [SECTION] Index
//   Frame state  the scene's dictionary, edits forwarded to the worker, the region report
//   Start-up     the window's files, the settings from the command line, the worker
//   Frame        one UI frame: the worker's news, the script's steps due, menus, panels and dialogs, shown, then
//                what they asked for
//   Loop         the frames, paced; the end, and --stats
// What the window is asked to do is carried out in ui/requests.cpp; the menus and keys are in ui/menus.cpp.
#include "ui/window.hpp"

#include "ui/actions.hpp"
#include "ui/app.hpp"
#include "ui/workspace_audit.hpp"
#include "ui/gl_window.hpp"
#include "base/data_dirs.hpp"
#include "ui/panels.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>
#include <utility>

namespace arwb {

namespace fs = std::filesystem;

// [SECTION] Frame state
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

// On the synthetic source, the Calibrate workspace shows the kind of board it looks for (that kind's defaults: the
// paper's chessboard, the CLI's ChArUco board), so that a class sees calibration without a camera; leaving the
// workspace brings the markers back. A board the user chose in the Source panel is left as it is.
void App::follow_calibration_board(bool calibrating) {
  const bool synthetic = frame && frame->source.kind == SourceKind::synthetic;
  std::string& shown = settings.synthetic.board;
  if (calibrating && !calibrating_sent && synthetic && shown.empty()) synthetic_board_auto = std::string("?");
  if (!synthetic_board_auto.empty() && shown != synthetic_board_auto && synthetic_board_auto != "?") {
    synthetic_board_auto.clear();   // the user chose another in the Source panel
    return;
  }
  if (calibrating && !synthetic_board_auto.empty()) {
    synthetic_board_auto = board_kind_name(settings.calibration.board.kind);
    shown = synthetic_board_auto;
  }
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
  // A projector's stage pictures: outlines about 1.5 type-scale pixels wide on the screen, whatever the picture's
  // zoom, and their text drawn by the window in its own type.
  StageViewStyle style;
  if (view.presentation) {
    style.text = false;
    style.line = std::clamp(static_cast<int>(std::lround(1.5f * scale / std::max(view.stage_zoom, 0.05f))), 1, 8);
  }
  if (!(style == stage_style_sent)) engine->set_stage_style(stage_style_sent = style);
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

bool App::take_screenshot(const std::string& path) {
  std::string why;
  if (ui::save_window_image(glfw_window, path, &why)) {
    info("screenshot: " + path);
    return true;
  }
  error("screenshot: " + why);
  return false;
}

// [SECTION] Start-up
namespace {
App* g_app = nullptr;   // for GLFW's drop callback, which has no user pointer of its own to spare
void on_drop(GLFWwindow*, int count, const char** paths) {
  if (!g_app) return;
  for (int i = 0; i < count; ++i) g_app->dropped.emplace_back(paths[i]);
}
}  // namespace

// The window's files (ImGui's layout, the workspaces, the recent files, the tour), the settings from the command
// line, the worker started, the shipped presets and example scenes listed.
void App::start(const WorkbenchOptions& options) {
  opt = options;
  log.verbose = options.verbose;
  g_app = this;
  glfwSetDropCallback(glfw_window, on_drop);
  base_style = ImGui::GetStyle();
  const std::string config_dir = options.config_dir.empty() ? default_config_dir() : options.config_dir;
  std::error_code ec;
  fs::create_directories(config_dir, ec);
  layout_unsaved = !load_layout(config_dir + "/imgui.ini");
  load_workspaces(config_dir + "/workspaces.json");
  status.config_dir = config_dir;
  load_recent();
  int ww = 0, wh = 0;
  glfwGetWindowSize(glfw_window, &ww, &wh);
  window_height = static_cast<float>(wh);
  if (options.presentation) set_presentation(true);
  ui::switch_workspace(workspaces, workspaces.current, view);   // view.open as the workspace has it
  const std::string tour_path = options.tour_path.empty() ? data_dirs().assets + "/teaching/tour.txt" : options.tour_path;
  std::vector<std::string> errors;
  load_tour(tour_path, &tour, &errors);
  for (const auto& e : errors) warn("tour: " + e);

  settings.params = options.engine.params;
  settings.dictionaries = options.engine.dictionaries;
  settings.acquisition = options.engine.acquisition;
  settings.marker_size = options.engine.marker_size;
  sent = settings;
  committed = {settings.params, settings.dictionaries};
  engine = std::make_unique<Engine>(options.engine, [this](int level, const std::string& m) {
    log.add(level == 0 ? LogLevel::info : (level == 1 ? LogLevel::warning : LogLevel::error), m);
  });
  engine->start();
  status.cameras = list_cameras();
  status.assets_dir = data_dirs().assets;   // installed beside the binary, or the source tree's
  status.scripts_dir = data_dirs().examples;
  list_presets();
  list_examples();
  compositor = std::make_unique<render::Compositor>(4);
  if (!options.engine.scene_file.empty()) {
    for (ui::Panel p : {ui::Panel::scene, ui::Panel::console}) view.open[static_cast<size_t>(p)] = true;
  }
}

// [SECTION] Frame
namespace {

// Closing the window, Ctrl+Q, File > Quit: with unsaved edits in the Script editor, ask first. True: it closes.
bool closes(App& app) {
  if (!glfwWindowShouldClose(app.glfw_window)) return false;
  Dialogs::Unsaved& u = app.dialogs.unsaved;
  if (!app.view.script_unsaved || u.quit_confirmed) return true;
  glfwSetWindowShouldClose(app.glfw_window, 0);
  if (!u.quit_waiting && !u.deferred) {
    u.quit_waiting = true;
    u.ask = true;
  }
  return false;
}

// The worker's newest frame and what comes with it; what background threads finished.
void take_news(App& app) {
  app.frame = app.engine->latest();
  app.status.source = app.engine->source();
  app.status.detect_fps = app.engine->detect_fps();
  app.log.sync(app.log_copy, app.log_seen);
  app.status.log = &app.log_copy;
  app.record_stats();
  app.poll_background();
  app.update_region();
  // Before a scripted screenshot, make sure there is a finished frame to show.
  if (!app.frame && app.opt.frames > 0) app.frame = app.engine->wait_newer(0, 5.0);
}

// Panels flip presentation mode; the font and style change between frames, never inside one. A resized window may
// want another presentation scale.
void fit_presentation(App& app) {
  int ww = 0, wh = 0;
  glfwGetWindowSize(app.glfw_window, &ww, &wh);
  app.window_height = static_cast<float>(wh);
  if (app.view.presentation != app.presentation_applied ||
      (app.view.presentation && app.scale != presentation_scale(app.window_height))) {
    app.set_presentation(app.view.presentation);
  }
}

// The scene's media on the frame: drawn every UI frame, so a video's texture moves on between detections.
ImTextureID composite(App& app) {
  if (!app.frame || !app.view.show_media || app.frame->scene.file.empty()) return nullptr;
  const auto c0 = Clock::now();
  if (app.compositor->draw(app.frame->image, app.frame->index, app.frame->overlays)) {
    app.totals.composite_ms += std::chrono::duration<double, std::milli>(Clock::now() - c0).count();
    ++app.totals.composites;
    return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(app.compositor->texture()));
  }
  if (app.totals.composites >= 0) {
    app.error("media: " + app.compositor->error());
    app.totals.composites = -1;   // said once
  }
  return nullptr;
}

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

}  // namespace

// The script's steps whose frame has come, each carried out at once, before the panels draw: a step acts on the
// frame it names. A step that could not be a request says why now.
void App::run_due_steps() {
  for (; script_next < script.size() && script[script_next].frame <= totals.ui_frames; ++script_next) {
    const Result<ui::Request>& r = script[script_next].request;
    if (r) carry_out(*r);
    else warn(r.error());
  }
}

// One UI frame. False: the window closes (nothing drawn).
bool App::run_frame() {
  glfwPollEvents();
  if (closes(*this)) return false;
  feed_typing();
  for (const std::string& p : std::exchange(dropped, {})) carry_out(ui::Drop{p});
  take_news(*this);
  fit_presentation(*this);
  if (!view.open[static_cast<size_t>(ui::Panel::tour)]) view.tour_active = false;

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  run_due_steps();
  draw_menu();
  const float status_h = ImGui::GetFrameHeightWithSpacing() + 4;
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  const float menu_h = ImGui::GetFrameHeight();
  ui::Context ctx{frame.get(), settings, view, status, requests, textures, tour, scale, nullptr};
  sync_scene();
  ctx.composite = composite(*this);
  const auto tp0 = Clock::now();
  // The main area between the menu bar and the status bar: the current workspace's regions.
  ui::draw_workspace(ctx, workspaces, {vp->Pos.x, vp->Pos.y + menu_h}, {vp->Size.x, vp->Size.y - menu_h - status_h},
                     [&ctx](ui::Panel p) { ui::draw_panel(p, ctx); }, &audit);
  draw_dialogs(ctx);
  // After every panel and dialog, so a text field activated this very frame (a click, a dialog's field taking
  // the keyboard) is known: see handle_keys.
  handle_keys();
  track_edits();
  draw_status_bar(status_h);
  audit.off_screen = ui::windows_off_screen();

  ImGui::Render();
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(glfw_window, &fw, &fh);
  glViewport(0, 0, fw, fh);
  const ImVec4 bg = ImGui::GetStyle().Colors[ImGuiCol_WindowBg];
  glClearColor(bg.x, bg.y, bg.z, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  const auto tp1 = Clock::now();
  const ImDrawData* dd = ImGui::GetDrawData();
  for (int i = 0; i < dd->CmdListsCount; ++i) totals.draw_calls += dd->CmdLists[i]->CmdBuffer.Size;
  totals.vertices += dd->TotalVtxCount;
  if (opt.stats) {   // only --stats reports it: not summed on every frame of an ordinary run
    totals.covered_px += ui::covered_area(dd);
    totals.window_px += double(fw) * double(fh);
  }
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  glFinish();
  const auto tp2 = Clock::now();
  textures.end_frame();
  ++totals.ui_frames;
  // --screenshot: the last frame drawn, whether the run ends by --frames or by closing the window.
  const bool last = opt.frames > 0 && totals.ui_frames >= opt.frames;
  if (!opt.screenshot.empty() && (last || glfwWindowShouldClose(glfw_window))) take_screenshot(opt.screenshot);
  glfwSwapBuffers(glfw_window);
  const auto tp3 = Clock::now();
  totals.ui_ms[0] += ms_between(tp0, tp1);
  totals.ui_ms[1] += ms_between(tp1, tp2);
  totals.ui_ms[2] += ms_between(tp2, tp3);

  handle_requests();
  forward_settings();
  return true;
}

// [SECTION] Loop
int run_workbench(const WorkbenchOptions& options) {
  Result<std::vector<ui::ScriptStep>> script = ui::parse_script(options.actions);
  if (!script) {
    std::fprintf(stderr, "arwb: %s\n", script.error().c_str());
    return 2;
  }
  ui::GlWindow gl;
  if (!ui::open_gl_window("arwb", "ArUco Workbench", options.window, options.fullscreen, &gl)) return 1;
  App app;
  app.glfw_window = gl.window;
  app.font_normal = gl.font_normal;
  app.fonts_large = gl.fonts_large;
  app.script = std::move(*script);
  app.start(options);

  const double ui_period = 1.0 / 60.0;
  const auto loop_start = Clock::now();
  auto last = Clock::now();
  while (app.run_frame()) {
    // The UI's fps over the last second; then the pace.
    const auto now = Clock::now();
    app.ui_frame_times.push_back(std::chrono::duration<double>(now - loop_start).count());
    while (app.ui_frame_times.size() > 1 && app.ui_frame_times.front() < app.ui_frame_times.back() - 1.0) {
      app.ui_frame_times.pop_front();
    }
    if (app.ui_frame_times.size() > 1) {
      app.status.ui_fps = static_cast<double>(app.ui_frame_times.size() - 1) /
                          (app.ui_frame_times.back() - app.ui_frame_times.front());
    }
    if (options.frames > 0 && app.totals.ui_frames >= options.frames) break;
    const double spent = std::chrono::duration<double>(now - last).count();
    if (spent < ui_period) std::this_thread::sleep_for(std::chrono::duration<double>(ui_period - spent));
    last = Clock::now();
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - loop_start).count();
  if (app.sweep_future.valid()) {
    app.sweep_cancel = true;
    app.sweep_future.wait();
  }
  // A clip still recording is closed and listed, as Stop does: quitting loses no footage.
  if (app.status.lab_recording) app.stop_clip();
  const uint64_t detected = app.engine->frames_done();
  // Quitting waits for the worker half a second at most: one stuck in a scene's library call must not hold the
  // window open (the UI never waits for it while running, so frames were drawn all along).
  const bool worker_stopped = app.engine->stop(0.5);

  g_app = nullptr;
  if (!app.layout_unsaved) save_layout(app.status.config_dir + "/imgui.ini");   // ImGui's own: table columns
  app.save_workspaces(app.status.config_dir + "/workspaces.json");
  if (options.stats) std::printf("%s\n", stats_json(app, elapsed, detected).c_str());
  if (!worker_stopped) {
    // The layout is saved; the worker still runs on its own state, so leave without the destructors it could race.
    std::fprintf(stderr, "arwb: %s\n", app.engine->stuck_message(0.5).c_str());
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
