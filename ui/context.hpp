// What every panel is handed each UI frame. Panels are immediate-mode drawers: they read the latest finished
// frame through a const pointer, edit the user's settings and their own view state, and ask for what they cannot
// do themselves by appending requests (ui/request.hpp). They hold no algorithm, do no I/O and never talk to the
// worker thread; the window (ui/requests.cpp) carries out the requests after the panels are drawn, forwards edited
// settings to the worker (ui/window.cpp), and reports back through the Status.
#pragma once

#include "board/board_spec.hpp"
#include "inspect/diagnose.hpp"
#include "lab/plan.hpp"
#include "lab/session.hpp"
#include "lab/videos.hpp"
#include "workbench/frame.hpp"
#include "detect/params.hpp"
#include "synth/synthetic_world.hpp"
#include "capture/clip_recorder.hpp"
#include "capture/source.hpp"
#include "detect/trace.hpp"
#include "workbench/log.hpp"
#include "ui/panel_id.hpp"
#include "ui/recent_files.hpp"
#include "ui/request.hpp"

#include <imgui.h>
#include <opencv2/core.hpp>

#include <array>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace arwb {
struct TourStep;
}
namespace arwb::render {
class TextureCache;
}

namespace arwb::ui {

// The Calibrate workspace's settings: the board looked for, whether frames are judged and kept, and whether the
// live view shows the frame undistorted with the newest calibration.
struct CalibrationSettings {
  BoardSpec board;
  bool capture = true;
  bool undistort = false;
};

// The Lab workspace's plan and run settings, as the Lab panel edits them (a run takes the detector's current
// parameters, and the loaded calibration as its camera when there is one and use_calibration).
struct LabSettings {
  lab::LabPlan plan = lab::paper_plan();
  std::vector<std::string> detectors{"arwb", "opencv", "opencv-aruco3"};
  int seed = 1;
  bool use_calibration = true;
  // Marking the video playing as a row of a videos.csv (arwb lab --videos): its marker, conditions and span
  // (first_frame and last_frame -1: not marked, the whole clip), and the folder whose videos.csv gets the row
  // ("": the clip's own folder).
  lab::VideoRow clip{"", "", 0, "ARUCO_ORIGINAL", 65, 1, 850, -1, -1, 0};
  std::string videos_dir;
  // Recording clips from the source with those conditions: the folder whose videos.csv lists them ("": the user's
  // lab/videos), and the paper's protocol as ticked (panel_lab_clips.cpp's protocol(), in its order).
  std::string record_dir;
  std::array<bool, 6> protocol{};
};

// Where Record writes clips/ and videos.csv: the folder typed, or the user's lab/videos.
inline std::string record_folder(const LabSettings& s, const std::string& config_dir) {
  return s.record_dir.empty() ? config_dir + "/lab/videos" : s.record_dir;
}

// Settings the user edits; the workbench sends each change to the worker.
struct Settings {
  DetectorParams params;
  std::vector<std::string> dictionaries{"ARUCO_ORIGINAL"};
  AcquisitionSettings acquisition;
  Playback playback;
  SyntheticControls synthetic;
  bool frozen = false;
  bool peer_opencv = false;
  bool peer_apriltag = false;
  CalibrationSettings calibration;
  // The printed marker's side in the user's unit (mm, cm, m): poses, distances and Lua's m.pose in that unit.
  // 0: in marker sides.
  double marker_size = 0;
  LabSettings lab;
};

using arwb::LogEntry;
using arwb::LogLevel;

struct SweepStatus {
  bool running = false;
  double progress = 0;
  bool has_result = false;
  SweepResult result;
  cv::Rect2f region;
};

// A dictionary's distances (detect/dictionary.hpp), computed once off the UI thread when a panel asks.
struct DictionaryStats {
  int min_distance = 0;
  std::vector<DictPair> pairs;  // the closest 50
  std::vector<int> histogram;   // distance_histogram
  double ms = 0;                // time it took
};

struct PresetFile {
  std::string path;
  std::string name;     // file name without .yml
  std::string comment;  // the file's first comment line, if any
};

struct ExampleScene {
  std::string path;     // as given to load_scene
  std::string label;    // relative to the scripts folder: "museum/museum.lua"
};

// The file the script editor shows, as the window last read it. The window looks at the disk twice a second and
// reads the file again when its time or size changed; `version` counts the readings.
struct WatchedFile {
  std::string path;         // "" none
  uint64_t version = 0;
  bool exists = false;
  bool read = false;        // `text` holds its content
  std::string text;
  std::string error;        // why it could not be read (missing, over 1 MB, permissions)
};

// A folder as the file browser shows it: folders first, then files, each by name (hidden ones left out).
struct DirEntry {
  std::string name;
  bool folder = false;
};
struct DirListing {
  std::string dir;        // absolute, as listed ("" before the first listing)
  std::string parent;     // "" at the root
  std::vector<DirEntry> entries;
  std::string error;      // why it (or the path last typed) could not be opened
  uint64_t version = 0;   // counts listings, so the browser sees a new one
};

// One frame's pose of a track, for the Pose panel's plots.
struct PoseSample {
  float time_s = 0;
  float distance = 0;       // in the unit of the marker side
  float ambiguity = 0;
  float error_px = 0;
  float alternative_error_px = 0;
  float tilt_deg = 0;
};

// Read-only facts about the application that panels show.
struct Status {
  double ui_fps = 0;
  double detect_fps = 0;                          // frames the worker finished per second
  std::deque<std::array<float, kStageCount + 1>> history;  // per finished frame: ms per stage, then total
  std::map<uint64_t, std::deque<PoseSample>> pose_history;  // per track id with a pose: the last 300 frames
  const std::vector<LogEntry>* log = nullptr;
  SweepStatus sweep;
  std::vector<int> cameras;                       // /dev/videoN found
  std::string last_snapshot;                      // folder of the last snapshot
  SourceSpec source;                              // the source in use
  std::string assets_dir;                         // shipped presets, the tour, fonts
  std::string scripts_dir;                        // the shipped example scenes (scripts/)
  std::map<std::string, DictionaryStats> dictionary_stats;   // by name, once computed
  std::vector<PresetFile> presets;                // list_presets: default first, then by name
  std::string presets_dir;                        // where they were found ("" when no folder)
  std::vector<PresetFile> user_presets;           // list_presets: the user's own, in config_dir/presets
  std::vector<ExampleScene> examples;             // list_examples, by label
  std::string examples_error;
  WatchedFile script_file;                        // watch_file
  DirListing listing;                             // list_dir
  RecentFiles recent;                             // kept in config_dir/recent.txt
  uint64_t opened = 0;                            // counts files opened through open_file (the browser closes)
  std::string config_dir;                         // the user's settings (presets/, marker-sheets/, recent.txt)
  // The Lab workspace: the run in the background (null before the first), the cell the live view shows (-1:
  // none; the source is then another), and the last thing to say about a run, a plan file or a save.
  std::shared_ptr<const lab::LabProgress> lab;
  int lab_cell = -1;
  std::string lab_message;
  bool lab_message_error = false;
  bool lab_saving = false;
  // A clip being recorded (lab_recording), or the last one recorded: its file, frames and dropped frames.
  bool lab_recording = false;
  ClipSummary lab_clip;
};

// Zoom and pan of an image view; the live view and the pipeline's large view share one, so the same pixel sits
// under the cursor in both.
struct ImageViewState {
  bool fit = true;       // fit the image to the panel (zoom and pan follow)
  float zoom = 1;        // screen pixels per image pixel
  ImVec2 centre{0, 0};   // image pixel at the middle of the panel
};

// A panel's own view state (filters, sort order, edit buffers), declared in the panel's file as a struct derived
// from this one and kept by the View (panel_state), so each window has its own and a new View starts afresh.
struct PanelState {
  virtual ~PanelState() = default;
};

// What the live view's marker labels came to when it last drew them (ui/label_layout.hpp), for --stats.
struct LabelReport {
  int drawn = 0, hidden = 0;   // hidden: no free place for them
  int leaders = 0;             // drawn away from their marker, joined by a line
  int shortened = 0;           // the id alone, where the dictionary's name found no room
  int overlaps = 0;            // pairs of drawn labels that overlap (the layout keeps this 0)
  int on_corners = 0;          // drawn labels over a marker's corner (the layout keeps this 0)
  std::vector<std::array<int, 4>> boxes;   // the drawn labels, screen x0, y0, x1, y1
};

// View state shared between panels (selection, hover, the overlays chosen), and each panel's own.
struct View {
  std::array<bool, kPanelCount> open{};
  ImageViewState image;
  int hovered_candidate = -1;    // a ledger row under the mouse this frame: the live view highlights it
  int selected_candidate = -1;   // the inspector shows it
  int pipeline_stage = -1;       // the stage shown large in the pipeline panel; -1: the input frame
  bool show_accepted = true;
  bool show_rejected = true;
  std::array<bool, kStageCount> show_rejected_stage{};  // per stage, when show_rejected
  bool show_truth = false;       // synthetic source: the exact corners
  bool show_peer_opencv = true;  // when the peer ran
  bool show_peer_apriltag = true;
  // 3D over each tracked marker with a pose, drawn through the pose's camera (lens distortion included): its axes
  // (x red, y green, z blue, one marker side long), the paper's cube standing on it, and the other solution of
  // the planar ambiguity's cube beside the one used, each with its error.
  bool show_axes = false;
  bool show_cube = false;
  bool show_alternative = false;
  int pose_drawn = 0;            // poses the live view drew over (axes or cube) at its last draw, for --stats
  bool label_ids = true;         // marker labels say the id...
  bool label_dict = true;        // ...and the dictionary (neither: no labels)
  LabelReport labels;            // written by the live view
  // "Why isn't my marker detected?": the rectangle dragged on the live view (working-image pixels).
  bool region_tool = false;
  bool has_region = false;
  cv::Rect2f region;
  RegionReport region_report;    // recomputed by the workbench for each new frame while has_region
  bool show_media = true;        // the scene's media composited on the live view
  int script_goto_line = 0;      // a line of the scene file the Script editor scrolls to next (1-based; 0: none)
  // The Script editor's unsaved edits, for the window's "save, discard, cancel" question before a quit, a source
  // or a scene change: the editor sets script_unsaved as it draws and, at its next draw, saves (script_save_now)
  // or drops its edits (script_discard) when the window asks.
  bool script_unsaved = false;
  bool script_save_now = false;
  bool script_discard = false;
  TextField focus_field = TextField::none;   // takes the keyboard at its next draw (ui::Focus)
  bool calibration_paper_files = false;   // saving also writes the paper's cameraMatrix.xml and distCoeffs.xml
  Panel front = Panel::count;    // a panel the workspace brings to the front of its region next (added if absent)
  // Opens panel p and brings its tab to the front: what a click, a shortcut or an action that leads to a panel does.
  void show(Panel p) {
    open[static_cast<size_t>(p)] = true;
    front = p;
  }
  // Teaching
  bool presentation = false;
  int tour_step = 0;
  bool tour_active = false;
  float tour_overflow_px = 0;   // the most the tour's title, Look line and Try controls ran past its panel's bottom
  // The large stage picture as last drawn: its zoom (a whole-image stage's; presentation mode's outlines are made
  // wide enough for it) and the text drawn over it by the window (StageViewStyle::text false), for --stats.
  float stage_zoom = 1;
  int stage_labels_drawn = 0;
  float stage_label_px = 0;     // the smallest of their type sizes, screen pixels
  std::array<std::unique_ptr<PanelState>, kPanelCount> panel_states;   // see panel_state
  View();
};

// Panel p's own state in `v`, made on first use.
template <class T>
T& panel_state(View& v, Panel p) {
  std::unique_ptr<PanelState>& slot = v.panel_states[static_cast<size_t>(p)];
  if (!dynamic_cast<T*>(slot.get())) slot = std::make_unique<T>();
  return static_cast<T&>(*slot);
}

struct Context {
  const Frame* frame = nullptr;        // the latest finished frame; null before the first
  Settings& settings;
  View& view;
  const Status& status;
  std::vector<Request>& requests;
  render::TextureCache& textures;
  const std::vector<TourStep>& tour;   // the teaching tour (assets/teaching/tour.txt)
  float scale = 1;                     // above 1 in presentation mode (4/3 to 2): sizes in panels multiply by it
  // The latest frame with the scene's media drawn on it (render::Compositor), when there is a scene and
  // view.show_media; null otherwise. Same size and pixel coordinates as frame->image.
  ImTextureID composite = nullptr;

  // Asks the window for something (ui/request.hpp); it is carried out after the panels are drawn.
  // Out of line: its body instantiates the whole variant's moves, seconds of compiling in every file that includes
  // this header.
  void request(Request r);
  // An ImGui texture id for an image, uploaded only when `version` changed (usually the frame index).
  ImTextureID texture(const std::string& key, const cv::Mat& image, uint64_t version, bool nearest = true);
};

}  // namespace arwb::ui
