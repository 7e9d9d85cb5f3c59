// The workbench window: what it owns and what it does, shared by the files that carry it out. Panels never see it;
// they get ui/context.hpp.
//   ui/window.cpp           start-up, one UI frame, the loop and its end; edits forwarded to the worker
//   ui/menus.cpp            the menu bar, the keys, the status bar
//   ui/requests.cpp         carry_out: every request (ui/request.hpp) is carried out there; sources, snapshots,
//                           presets, sweeps, marker sheets, the calibration saved
//   ui/view_requests.cpp    what the window shows: panels, workspaces, overlays, the selection, the region
//   ui/waits.cpp            what a script waits for (--actions next, calib_wait, lab_wait, export_wait, play_wait)
//   ui/background.cpp       the sweep's and the dictionaries' threads, the script editor's file, the listed files
//   ui/dialogs.cpp          the file browser, dropping, undo, the unsaved-edits question, typing, the dialogs
//   ui/lab_requests.cpp     the Lab workspace's run, cells, plan files, report
//   ui/export_requests.cpp  File > Export... and File > Play bundle...
//   ui/layout.cpp           the workspaces file, ImGui's settings file, presentation mode
//   ui/stats.cpp            the history the Timings and Pose panels plot, and --stats
#pragma once

#include "inspect/diagnose.hpp"
#include "lab/session.hpp"
#include "teach/tour.hpp"
#include "ui/actions.hpp"
#include "render/compositor.hpp"
#include "render/texture.hpp"
#include "ui/context.hpp"
#include "ui/dialogs.hpp"
#include "ui/export_requests.hpp"
#include "ui/history.hpp"
#include "ui/recent_files.hpp"
#include "ui/request.hpp"
#include "ui/stats.hpp"
#include "ui/workspace.hpp"
#include "workbench/engine.hpp"
#include "workbench/log.hpp"
#include "workbench/options.hpp"

#include <imgui.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct GLFWwindow;

namespace arwb {

using Clock = std::chrono::steady_clock;

struct App {
  // The window and the frame (ui/window.cpp).
  WorkbenchOptions opt;
  Clock::time_point t0 = Clock::now();
  Log log{t0};
  std::unique_ptr<Engine> engine;
  GLFWwindow* glfw_window = nullptr;
  ui::Settings settings, sent;     // as edited, and as last sent to the worker
  StageViewStyle stage_style_sent;
  ui::View view;
  ui::Status status;
  std::vector<LogEntry> log_copy;
  uint64_t log_seen = 0;
  std::vector<ui::Request> requests;   // what panels and dialogs asked for this frame
  std::vector<ui::ScriptStep> script;  // --actions, by frame (ui/actions.hpp)
  size_t script_next = 0;              // the first step not yet due
  std::vector<TourStep> tour;
  render::TextureCache textures;
  std::unique_ptr<render::Compositor> compositor;   // the frame with the scene's media, for the live view
  std::shared_ptr<const Frame> frame;
  uint64_t scene_generation = 0;
  uint64_t region_frame = 0;
  cv::Rect2f region_done{-1, -1, 0, 0};
  bool calibrating_sent = false;   // what the engine was last told: a Calibrate panel is shown
  // The synthetic source shows the Calibrate workspace's board while a Calibrate panel is on screen, when it was
  // showing markers: put there by the window (the kind it follows), taken away again when the panels close.
  std::string synthetic_board_auto;
  std::vector<std::string> dropped;   // paths dropped on the window, opened at the next frame
  std::deque<double> ui_frame_times;
  StatsTotals totals;                 // ui/stats.cpp
  // The workspaces and presentation mode (ui/layout.cpp).
  ui::Workspaces workspaces;
  bool workspaces_unsaved = false;      // its file could not be read nor set aside: never written over
  bool layout_unsaved = false;          // the same for imgui.ini
  ui::LayoutAudit audit;                // what the last frame's layout looked like, for --stats
  ImFont* font_normal = nullptr;
  std::map<int, ImFont*> fonts_large;   // by pixel size: presentation mode picks one by the window's height
  ImGuiStyle base_style;
  bool presentation_applied = false;
  float scale = 1;                      // ctx.scale: 1, or presentation mode's scale
  float window_height = 900;            // the window's height when the scale was chosen
  // Undo and the status bar's note (ui/dialogs.cpp).
  ui::SettingsHistory history;      // undo and redo of the parameters and dictionaries
  ui::DetectorState committed;      // the state the last history entry ended in
  std::string change_name;          // names the next entry ("preset fast.yml"); "" : described from the change
  std::string note;                 // shown in the status bar for a while (undo, redo, a marker sheet written)
  double note_time = -100;
  static constexpr double kNoteSeconds = 10;   // how long a note stays in the status bar
  Dialogs dialogs;                  // ui/dialogs.hpp
  // Work off the UI thread, polled each frame (ui/background.cpp): the sweep, dictionary distances by name, and
  // the script editor's file on disk as last read (Status::script_file).
  std::future<SweepResult> sweep_future;
  std::atomic<double> sweep_progress{0};
  std::atomic<bool> sweep_cancel{false};
  std::map<std::string, std::future<ui::DictionaryStats>> dictionary_futures;
  std::filesystem::file_time_type script_mtime{};
  uintmax_t script_size = 0;
  double script_next_check = 0;
  // The Lab workspace's run, and a report being saved (ui/lab_requests.cpp).
  lab::LabSession lab_session;
  std::future<Status> lab_save_future;
  std::string lab_save_dir;
  // The clip being recorded from the source (Record), and the row and folder it goes into videos.csv with.
  std::shared_ptr<ClipRecorder> recorder;
  lab::VideoRow recording_row;
  std::string recording_dir;
  // File > Export... and the players started (ui/export_requests.cpp).
  ExportDialog export_dialog;
  std::shared_ptr<Players> players = std::make_shared<Players>();
  std::vector<std::string> play_args;   // more arguments for the players started (--actions play_args=)

  void info(const std::string& s) { log.add(LogLevel::info, s); }
  void warn(const std::string& s) { log.add(LogLevel::warning, s); }
  void error(const std::string& s) { log.add(LogLevel::error, s); }
  void note_status(const std::string& s);   // info in the log, and in the status bar for a while

  // ui/window.cpp
  void start(const WorkbenchOptions& options);
  bool run_frame();
  void run_due_steps();
  void sync_scene();
  void forward_settings();
  void follow_calibration_board(bool calibrating);
  void update_region();
  bool take_screenshot(const std::string& path);
  // ui/menus.cpp
  void draw_menu();
  void handle_keys();
  void draw_status_bar(float height);
  // ui/requests.cpp
  void carry_out(const ui::Request& r);
  void handle_requests();   // what panels and dialogs asked for, in order
  void open_source(const ui::OpenSource& r);
  void snapshot();
  void sweep();
  void load_preset(const std::string& text);
  void save_preset(const std::string& text);
  std::string preset_path(const std::string& text, bool saving) const;
  void save_script(const ui::SaveScript& r);
  void open_url(const std::string& url);
  void write_marker_sheet(const ui::WriteMarkerSheet& r);
  void open_file(const ui::OpenFile& r);
  void drop_calibration_view(const ui::DropCalibrationView& r);
  void save_calibration(const std::string& path, bool paper_files);
  // ui/view_requests.cpp
  void set_panel_open(const ui::SetPanelOpen& r);
  void switch_workspace(const std::string& name);
  void move_panel(const ui::MovePanel& r);
  void set_splitter(const ui::SetSplitter& r);
  void start_tour(const std::string& step);
  void select_candidate(std::optional<int> index);
  void set_labels(const ui::SetLabels& r);
  void set_pose_drawing(const ui::SetPoseDrawing& r);
  void click_live_view(cv::Point2d at);
  void focus(ui::TextField field);
  void add_dictionary(const std::string& name);
  // ui/waits.cpp
  void next_frame_shown();
  void wait_for_calibration(int views);
  void wait_for_lab(int cells);
  void wait_export(double timeout_s);
  void wait_players(double timeout_s);
  void wait_source(double timeout_s);
  std::string asked_source;   // the source last opened (SourceSpec::text), which source_wait waits for
  // ui/background.cpp
  void poll_background();
  void compute_dictionary_stats(const std::string& name);
  void list_presets();
  void list_examples();
  void watch_file(const std::string& path, bool reread);
  void list_dir(const std::string& path);
  // ui/dialogs.cpp
  void draw_dialogs(ui::Context& ctx);
  void open_sheet_dialog(const ui::OpenSheetDialog& r);
  void open_path(ui::FileKind kind, const std::string& path);
  void drop(const std::string& path);
  bool ask_before(const ui::OpenSource& r);   // true: deferred until the unsaved edits are saved or discarded
  bool ask_before(const ui::LoadScene& r);
  void proceed();                            // carries out what waited
  void track_edits();
  void undo();
  void redo();
  void type_text(const std::string& text);
  void feed_typing();
  void load_recent();
  void save_recent();
  // ui/lab_requests.cpp
  void start_lab();
  void open_lab_cell(int cell, int frame_index);
  void read_lab_plan(const std::string& path);
  void save_lab_report(const std::string& dir);
  void save_clip(const std::optional<ui::ClipRow>& typed);
  void mark_clip_span(ui::SpanEnd end);
  void record_clip(const std::optional<ui::ClipRow>& typed);
  void stop_clip();
  void print_clip_marker();
  void why_lab_marker();
  void lab_say(const std::string& message, bool is_error);
  void poll_lab();
  // ui/export_requests.cpp
  void open_export_dialog(const std::string& out = "");
  void draw_export_dialog(ui::Context& ctx);
  void start_export(bool write);
  void write_export(const std::optional<std::string>& out);
  void play_bundle(const std::string& path);
  void poll_export();   // a finished check or write; the players' messages
  // ui/serve_requests.cpp
  void draw_serve_section(ui::Context& ctx, float width);
  void serve_bundle(bool on);
  void poll_serve();    // a server started, or refused
  bundle::ExportOptions export_options() const;
  // ui/layout.cpp
  void set_presentation(bool on);
  void load_workspaces(const std::string& path);
  void save_workspaces(const std::string& path);
  // ui/stats.cpp
  void record_stats();
};

// ui/layout.cpp
std::string default_config_dir();
// ImGui's own settings (table column widths and order) in imgui.ini: loaded when it exists, saved at exit; a
// message on stderr when it cannot be. The workspaces are in their own file (App::load_workspaces).
// False when the file could not be read nor set aside: save_layout must then not write it.
bool load_layout(const std::string& ini_path);
void save_layout(const std::string& ini_path);
// Presentation mode's scale for a window `height` pixels high: fonts of at least 28 px at 1080.
float presentation_scale(float height);

}  // namespace arwb
