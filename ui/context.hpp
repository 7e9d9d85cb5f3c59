// What every panel is handed each UI frame. Panels are immediate-mode drawers: they read the latest finished
// frame through a const pointer, edit the user's settings and their own view state, and ask for actions by
// appending requests. They hold no algorithm and never talk to the worker thread; the workbench (ui/window.cpp)
// forwards edited settings and requests to it after the panels are drawn.
#pragma once

#include "detect/diagnose.hpp"
#include "workbench/frame.hpp"
#include "detect/params.hpp"
#include "synth/synthetic_world.hpp"
#include "capture/source.hpp"
#include "detect/trace.hpp"
#include "workbench/log.hpp"

#include <imgui.h>
#include <opencv2/core.hpp>

#include <array>
#include <deque>
#include <functional>
#include <string>
#include <vector>

namespace arwb {
struct TourStep;
}
namespace arwb::render {
class TextureCache;
}

namespace arwb::ui {

// The panels, in the order of the View menu. Their titles are the window names ImGui saves the layout under.
enum class Panel { live_view, pipeline, candidates, inspector, parameters, timings, dictionary, peers, source, tour,
                   why, log, scene, script, console, count };
constexpr int kPanelCount = static_cast<int>(Panel::count);
const char* panel_title(Panel p);
const char* panel_key(Panel p);   // "live_view", "pipeline"... (for --at N:open=KEY and the saved layout)
bool panel_from_key(std::string_view key, Panel* out);

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
};

enum class RequestKind {
  open_source,   // text: a --source spec
  step,          // value: +1 / -1 (video frame, folder image)
  seek,          // value: position
  next_frame,    // frozen: take one new frame from the source
  snapshot,      // save frame, stage images and trace
  sweep,         // region: run the parameter sweep there
  load_preset,   // text: path
  save_preset,   // text: path
  marker_sheet,  // text: path of the PDF to write, with the first dictionary's ids `value`.. (arwb markers)
  load_scene,    // text: a scene file (.lua or .xml); "" unloads the scene
  save_script,   // text: path, payload: the file's new content (the scene then reloads by itself)
  open_url,      // text: a web card's URL, opened in the system's browser
};

struct Request {
  RequestKind kind;
  std::string text;
  int value = 0;
  cv::Rect2f region;
  std::string payload;
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

// Read-only facts about the application that panels show.
struct Status {
  double ui_fps = 0;
  double detect_fps = 0;                          // frames the worker finished per second
  std::deque<std::array<float, kStageCount + 1>> history;  // per finished frame: ms per stage, then total
  const std::vector<LogEntry>* log = nullptr;
  SweepStatus sweep;
  std::vector<int> cameras;                       // /dev/videoN found
  std::string last_snapshot;                      // folder of the last snapshot
  SourceSpec source;                              // the source in use
  std::string assets_dir;                         // shipped presets, the tour, fonts
  std::string scripts_dir;                        // the shipped example scenes (scripts/)
};

// Zoom and pan of an image view; the live view and the pipeline's large view share one, so the same pixel sits
// under the cursor in both.
struct ImageViewState {
  bool fit = true;       // fit the image to the panel (zoom and pan follow)
  float zoom = 1;        // screen pixels per image pixel
  ImVec2 centre{0, 0};   // image pixel at the middle of the panel
};

// View state shared between panels (selection, hover, the overlays chosen). Each panel keeps the rest of its
// view state itself.
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
  // "Why isn't my marker detected?": the rectangle dragged on the live view (working-image pixels).
  bool region_tool = false;
  bool has_region = false;
  cv::Rect2f region;
  RegionReport region_report;    // recomputed by the workbench for each new frame while has_region
  bool show_media = true;        // the scene's media composited on the live view
  int script_goto_line = 0;      // a line of the scene file the Script editor scrolls to next (1-based; 0: none)
  // Teaching
  bool presentation = false;
  int tour_step = 0;
  bool tour_active = false;
  View();
};

struct Context {
  const Frame* frame = nullptr;        // the latest finished frame; null before the first
  Settings& settings;
  View& view;
  const Status& status;
  std::vector<Request>& requests;
  render::TextureCache& textures;
  const std::vector<TourStep>& tour;   // the teaching tour (assets/teaching/tour.txt)
  float scale = 1;                     // 2 in presentation mode: sizes in panels multiply by it
  // The latest frame with the scene's media drawn on it (render::Compositor), when there is a scene and
  // view.show_media; null otherwise. Same size and pixel coordinates as frame->image.
  ImTextureID composite = nullptr;
  // Called before each panel's window begins: the workbench places windows on their first use there.
  std::function<void(Panel)> place;

  void request(RequestKind kind, std::string text = {}, int value = 0, cv::Rect2f region = {},
               std::string payload = {}) {
    requests.push_back({kind, std::move(text), value, region, std::move(payload)});
  }
  // An ImGui texture id for an image, uploaded only when `version` changed (usually the frame index).
  ImTextureID texture(const std::string& key, const cv::Mat& image, uint64_t version, bool nearest = true);
};

}  // namespace arwb::ui
