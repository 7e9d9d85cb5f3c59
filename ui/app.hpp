// The window's own state, shared by its three files: ui/window.cpp (the frame loop, actions, menus, stats),
// ui/requests.cpp (carrying out what panels asked for: files, presets, sweeps, dictionary distances, the watched
// script file) and ui/layout.cpp (the workspaces file, ImGui's settings file, presentation mode). Not for panels:
// they see only ui/context.hpp.
#pragma once

#include "inspect/diagnose.hpp"
#include "bundle/bundle.hpp"
#include "lab/session.hpp"
#include "teach/tour.hpp"
#include "render/compositor.hpp"
#include "render/texture.hpp"
#include "ui/context.hpp"
#include "ui/file_browser.hpp"
#include "ui/history.hpp"
#include "ui/recent_files.hpp"
#include "ui/workspace.hpp"
#include "workbench/actions.hpp"
#include "workbench/engine.hpp"
#include "workbench/log.hpp"
#include "workbench/options.hpp"

#include <imgui.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <future>
#include <map>
#include <mutex>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct GLFWwindow;

namespace arwb {

using Clock = std::chrono::steady_clock;

struct App {
  WorkbenchOptions opt;
  Clock::time_point t0 = Clock::now();
  Log log{t0};
  std::unique_ptr<Engine> engine;
  ui::Settings settings, sent;
  ui::View view;
  ui::Status status;
  std::vector<LogEntry> log_copy;
  uint64_t log_seen = 0;
  std::vector<ui::Request> requests;
  std::vector<TourStep> tour;
  render::TextureCache textures;
  std::unique_ptr<render::Compositor> compositor;   // the frame with the scene's media, for the live view
  uint64_t scene_generation = 0;
  double composite_ms = 0;
  int composites = 0;
  std::shared_ptr<const Frame> frame;
  uint64_t region_frame = 0;
  cv::Rect2f region_done{-1, -1, 0, 0};
  // Sweep on its own thread; the UI polls.
  std::future<SweepResult> sweep_future;
  std::atomic<double> sweep_progress{0};
  std::atomic<bool> sweep_cancel{false};
  // The Lab workspace's run, and a report being saved (ui/lab_requests.cpp).
  lab::LabSession lab_session;
  std::future<Status> lab_save_future;
  std::string lab_save_dir;
  // Dictionary distances being computed, by name; the UI polls.
  std::map<std::string, std::future<ui::DictionaryStats>> dictionary_futures;
  // The script editor's file on disk as last read (Status::script_file).
  std::filesystem::file_time_type script_mtime{};
  uintmax_t script_size = 0;
  double script_next_check = 0;
  // Stats
  uint64_t last_frame_index = 0;
  int detected_seen = 0;
  double detect_ms_sum = 0;
  std::array<double, kStageCount> stage_ms_sum{};
  std::map<std::string, std::pair<double, int>> peer_ms;   // name: summed ms, frames
  std::array<int, kStageCount> stage_ms_n{};
  std::deque<double> ui_frame_times;
  ImFont* font_normal = nullptr;
  std::map<int, ImFont*> fonts_large;   // by pixel size: presentation mode picks one by the window's height
  ImGuiStyle base_style;
  bool presentation_applied = false;
  float scale = 1;                      // ctx.scale: 1, or presentation mode's scale (ui/layout.cpp)
  float window_height = 900;            // the window's height when the scale was chosen
  ui::Workspaces workspaces;
  ui::LayoutAudit audit;                // what the last frame's layout looked like, for --stats
  double draw_calls = 0, vertices = 0;   // summed over UI frames
  std::array<double, 3> ui_ms{};   // summed: building the panels, rendering them, swapping
  GLFWwindow* glfw_window = nullptr;   // for quitting from a dialog or an action
  // Desktop habits (ui/dialogs.cpp)
  ui::FileBrowser browser;          // File > Open source / scene / preset
  ui::FileBrowser calibration_browser;   // the Calibrate panel's Save...
  bool calibrating_sent = false;    // what the engine was last told: a Calibrate panel is shown
  // The synthetic source shows the Calibrate workspace's board while a Calibrate panel is on screen, when it was
  // showing markers: put there by the window (the kind it follows), taken away again when the panels close.
  std::string synthetic_board_auto;
  ui::SettingsHistory history;      // undo and redo of the parameters and dictionaries
  ui::DetectorState committed;      // the state the last history entry ended in
  std::string change_name;          // names the next entry ("preset fast.yml"); "" : described from the change
  std::string note;                 // shown in the status bar for a while (undo, redo, a marker sheet written)
  double note_time = -100;
  static constexpr double kNoteSeconds = 10;   // how long a note stays in the status bar
  std::vector<std::string> dropped; // paths dropped on the window, opened at the next frame
  // The unsaved-edits question: what waits for the answer.
  bool unsaved_ask = false;         // open the modal at the next draw
  bool quit_waiting = false;        // a quit waits
  std::optional<ui::Request> deferred;   // a source or scene change waits
  bool quit_confirmed = false;      // the user chose: quit for real
  int save_wait = -1;               // frames since "Save" was chosen, while the editor's save is awaited
  std::string answer;               // --actions answer=save|discard|cancel|write: a dialog's button, pressed
  // --actions type=: one character a frame, its key held for one frame, then released.
  std::deque<int> typing;
  int key_down = -1;
  // Help menu windows.
  bool show_shortcuts = false, show_first_steps = false, show_about = false;
  // File > Print marker sheet...
  struct SheetDialog {
    bool opening = false;
    std::string dictionary;
    char ids[256] = "0-11";
    double size_mm = 50;
    char path[1024] = "";
    ui::FileBrowser browser;
  } sheet;
  // File > Export...: the scene loaded, as a bundle (ui/export_requests.cpp). Check and Export run plan_export
  // (and write_export) on a thread of their own; the dialog shows the last check's self-test.
  struct ExportDialog {
    bool opening = false;
    char title[256] = "";
    double size_mm = 50;
    bool use_calibration = true;      // the calibration loaded with --calib, when there is one
    bool force = false;               // replace an existing bundle at `out`
    char out[1024] = "";
    ui::FileBrowser browser;
    std::future<Result<bundle::ExportPlan>> checking;   // Check, or the check before writing
    bool write_after = false;         // the check running is Export's: write when it passes
    std::future<Status> writing;
    std::shared_ptr<const bundle::ExportPlan> plan;     // the last check that passed
    std::string error;                // the last check's or write's failure, one line
    std::string written;              // where the last export went
  } export_dialog;
  // File > Play bundle...: each player started runs as a process of its own; a thread per player verifies the
  // bundle first, starts it and waits for it, and leaves its messages here for the UI thread's log.
  struct Players {
    std::mutex mutex;
    std::vector<std::pair<LogLevel, std::string>> messages;
    int running = 0;                  // verifying, or started and not yet ended
    int started = 0, ended = 0, refused = 0;
    std::vector<int> exit_codes;      // of the players that ended, in the order they ended
  };
  std::shared_ptr<Players> players = std::make_shared<Players>();
  std::vector<std::string> play_args;   // --actions play_args=: more arguments for the players started (tests)
  std::string modal;                // the modal shown this frame ("Unsaved edits"), for --stats

  void note_status(const std::string& s);   // info in the log, and in the status bar for a while

  void info(const std::string& s) { log.add(LogLevel::info, s); }
  void warn(const std::string& s) { log.add(LogLevel::warning, s); }
  void error(const std::string& s) { log.add(LogLevel::error, s); }

  void run_action(const Action& a);
  // ui/dialogs.cpp: the file browser, dropping, undo, the unsaved-edits question, Help, the marker sheet dialog.
  void draw_dialogs(ui::Context& ctx);
  void draw_help_menu();
  void open_sheet_dialog();
  void handle_keys();
  void open_path(ui::FileKind kind, const std::string& path);
  void drop(const std::string& path);
  bool ask_before(const ui::Request& r);     // true: deferred until the unsaved edits are saved or discarded
  void proceed();                            // carries out what waited
  void track_edits();
  void undo();
  void redo();
  void feed_typing();
  void load_recent();
  void save_recent();
  void list_dir(const std::string& path);
  std::string preset_path(const std::string& text, bool saving) const;
  void sync_scene();
  void forward_settings();
  void follow_calibration_board(bool calibrating);
  void update_region();
  void record_stats();
  void draw_menu(GLFWwindow* window);
  void draw_status_bar(float height);
  bool take_screenshot(const std::string& path, GLFWwindow* window);
  // ui/requests.cpp
  void handle_requests();
  void save_calibration(const std::string& path, bool paper_files);
  void poll_background();        // the sweep's and the dictionaries' results, the watched file
  void list_presets();
  void list_examples();
  // ui/lab_requests.cpp: running a plan, opening a cell in the live view, plan files, saving the report.
  void lab_request(const ui::Request& r);
  void poll_lab();
  void watch_file(const std::string& path, bool reread);
  // ui/export_requests.cpp: File > Export... and File > Play bundle...
  void open_export_dialog(const std::string& out = "");
  void draw_export_dialog(ui::Context& ctx);
  void export_request(const ui::Request& r);
  void poll_export();   // a finished check or write; the players' messages
  bundle::ExportOptions export_options() const;
  void wait_export(double timeout_s);    // --actions export_wait
  void wait_players(double timeout_s);   // --actions play_wait
  // ui/layout.cpp
  void set_presentation(bool on);
  void load_workspaces(const std::string& path);
  void save_workspaces(const std::string& path);
};

// ui/export_requests.cpp: an export message (bundle/bundle.hpp words it for `arwb export`: --out, --calib, --force)
// in the Export dialog's words (the path, the calibration, the 'replace an existing bundle there' checkbox).
std::string export_window_wording(std::string text);

// ui/layout.cpp
std::string default_config_dir();
// ImGui's own settings (table column widths and order) in imgui.ini: loaded when it exists, saved at exit; a
// message on stderr when it cannot be. The workspaces are in their own file (App::load_workspaces).
void load_layout(const std::string& ini_path);
void save_layout(const std::string& ini_path);
// Presentation mode's scale for a window `height` pixels high: fonts of at least 28 px at 1080.
float presentation_scale(float height);

}  // namespace arwb
