// A scene in use: a Lua script (scene API, docs/scene-api.md) or the paper's XML database, loaded in a sandbox
// and run once per frame on the worker. It turns the tracker's markers into overlays: which media, placed where.
//
// Faults never stop the frame loop. A script that fails to load leaves the last good scene in place; errors read
// "file:line: message" and go to the console (repeats collapsed); a callback that runs past its instruction
// budget, its wall time or asks for more memory than the cap is stopped with a message and disabled until the
// next reload, as is one that overflows the stack or fails the same way on several frames in a row; bad values
// (id -1, a NaN size, an unknown placement) are reported with their line and skipped. What a scene makes the host
// do per frame (console lines, warnings about fields) is capped too.
#pragma once

#include "track/overlay.hpp"
#include "detect/trace.hpp"
#include "track/tracker.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace arwb::media { class MediaProvider; }

namespace arwb::script {

struct ScriptLimits {
  std::size_t memory_bytes = 64u << 20;        // the Lua state's allocator refuses past this
  long long instructions_per_call = 5'000'000; // each callback, computed text and the main chunk
  // Wall time of one call (the main chunk, a callback, a computed text). The budget's 5 million instructions take
  // 20-50 ms; this catches what instructions do not count (library functions over long strings) with room for a
  // loaded machine, and a call past it is disabled like one past the budget.
  double call_ms = 250;
  // Wall time of a frame's scene work: once the frame's calls have taken this long, the frame's remaining
  // on_update and text calls are skipped (not disabled) until the next frame. At the 20 fps cap a frame is 50 ms;
  // past 150 ms the scene is unusable anyway, and detection keeps at least a few frames a second.
  double frame_ms = 150;
  int failures_in_a_row = 3;                   // a callback failing the same way on this many frames is disabled
  int console_lines = 200;                     // lines kept in SceneStatus::console
  int output_lines_per_frame = 100;            // print and warn lines a frame (the rest counted, not shown)
  std::size_t output_bytes_per_frame = 64u << 10;
};

// What the scene sees of one frame.
struct SceneInput {
  const std::vector<TrackedMarker>* tracks = nullptr;
  const std::vector<TrackEvent>* events = nullptr;
  double t_s = 0;          // frame time (seconds, non-decreasing)
  double dt_s = 0;         // since the previous update (0 on the first)
  cv::Size frame{};        // working image size
  // The frame's stage pictures (trace_view.hpp), for stage media; null when the trace is not full.
  const std::array<cv::Mat, kStageCount>* views = nullptr;
  uint64_t frame_index = 0;
  // The camera the tracks' poses were made with (the loaded calibration, or the default values marked assumed),
  // and the marker side their tvec is measured in. Null: 3D media cannot be drawn.
  const Calibration* camera = nullptr;
  double marker_side = 1.0;
  std::string pose_unit = "marker sides";   // what tvec's unit is called: "mm" with a printed size given
};

class SceneRuntime {
 public:
  explicit SceneRuntime(media::MediaProvider& media, ScriptLimits limits = {});
  ~SceneRuntime();
  SceneRuntime(const SceneRuntime&) = delete;
  SceneRuntime& operator=(const SceneRuntime&) = delete;

  // Loads a scene: a Lua script, or an XML database (recognised by its content: an XML declaration or a
  // <database> root). True on success. On failure the previous scene (if any) stays and status().error says why.
  bool load(const std::string& path);
  // Loads again when the file's modification time or size changed since the last attempt. True if it tried.
  bool reload_if_changed();
  void unload();

  // One frame: on_enter / on_leave for the events, on_update for markers in view, computed texts, then
  // placement. Media of markers that left are paused (videos) and dropped from the overlays.
  std::vector<Overlay> update(const SceneInput& in);

  const SceneStatus& status() const;
  // The error lines reported since the last call (load refusals of marker(), runtime errors, media that cannot be
  // loaded), each distinct text once per loaded scene, for the workbench's log. A failed load's own error is not
  // among them: status().error carries it.
  std::vector<std::string> take_errors();
  // The dictionary the scene asked for with dictionary "NAME" (or the database's attribute), "" if none.
  std::string dictionary() const;
  // The dictionary the scene's ids are checked against: the one it asked for, else ARUCO_ORIGINAL.
  std::string dictionary_name() const;
  // The ids each mapping covers (inclusive ranges, as written), in the order of status().mappings; empty for a
  // mapping refused for its ids, and no rows when no scene is loaded. What `arwb export`'s self-test draws.
  std::vector<std::vector<std::pair<int, int>>> mapping_ids() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arwb::script
