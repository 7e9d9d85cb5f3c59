// A scene in use: a Lua script (scene API, docs/scene-api.md) or the paper's XML database, loaded in a sandbox
// and run once per frame on the worker. It turns the tracker's markers into overlays: which media, placed where.
//
// Faults never stop the frame loop. A script that fails to load leaves the last good scene in place; errors read
// "file:line: message" and go to the console (repeats collapsed); a callback that runs past its instruction
// budget or asks for more memory than the cap is stopped with a message and disabled until the next reload;
// bad values (id -1, a NaN size, an unknown placement) are reported with their line and skipped.
#pragma once

#include "track/overlay.hpp"
#include "detect/trace.hpp"
#include "track/tracker.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace arwb::media { class MediaStore; }

namespace arwb::script {

struct ScriptLimits {
  std::size_t memory_bytes = 64u << 20;        // the Lua state's allocator refuses past this
  long long instructions_per_call = 5'000'000; // each callback, computed text and the main chunk
  int console_lines = 200;                     // lines kept in SceneStatus::console
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
};

class SceneRuntime {
 public:
  explicit SceneRuntime(media::MediaStore& store, ScriptLimits limits = {});
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
  // The dictionary the scene asked for with dictionary "NAME" (or the database's attribute), "" if none.
  std::string dictionary() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace arwb::script
