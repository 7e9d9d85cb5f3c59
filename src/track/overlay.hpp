// What a scene decided for one frame: the media to draw, each with its quad (placement.hpp), and the scene's
// state for the workbench's Scene panel and console. Produced by src/script (Lua scenes and XML databases) on the
// worker, drawn by src/render on screen and by `arwb render` offline.
#pragma once

#include "track/media_spec.hpp"
#include "track/mesh.hpp"
#include "track/placement.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace arwb {

// A mesh drawn in the marker's 3D frame through the camera's lens model: a 3D media (cube, axes, model), or a
// flat media (on_marker, beside) drawn on a grid so that it bends with the image where the lens distorts.
struct SolidDraw {
  std::shared_ptr<const Mesh> mesh;
  cv::Matx44d mesh_to_marker = cv::Matx44d::eye();   // mesh units to the marker frame (marker sides)
  cv::Vec3d rvec{0, 0, 0}, tvec{0, 0, 0};            // the marker's pose: marker frame to camera, tvec in sides
  cv::Matx33d camera_matrix = cv::Matx33d::eye();
  std::vector<double> distortion;                    // OpenCV's order, up to 8 used (k1 k2 p1 p2 k3 k4 k5 k6)
};

struct Overlay {
  int marker_id = -1;          // -1 for a screen placement not tied to a marker
  uint64_t track_id = 0;       // the print of that id it belongs to (TrackedMarker::track_id); 0 for none
  int mapping = -1;            // index into SceneStatus::mappings
  MediaSpec media;
  PlaceSpec place;
  MediaQuad quad;
  std::shared_ptr<MediaContent> content;   // the pixels; null when the media failed to load (reported)
  // Set: drawn as this mesh with a depth buffer (3D media; flat media when a calibration is loaded), `quad` then
  // bounds it on screen for clicks. Unset: `quad` is drawn through its homography.
  std::optional<SolidDraw> solid;
};

// Whether a mapping does what it says. Anything but ok keeps its row, with the reason, so a fault never looks
// like a mapping that merely waits for its marker.
enum class MappingHealth {
  ok,
  error,      // something failed on this frame (a callback, a text function, media that cannot be loaded)
  disabled,   // a callback was stopped (a limit, or failures on several frames in a row) until the scene reloads
  skipped,    // marker() was refused while the scene loaded (a missing media file, a bad placement): nothing runs
};
const char* mapping_health_name(MappingHealth h);   // "ok", "error", "disabled", "skipped"

// One row of the Scene panel: a marker(...) call or a database row.
struct MappingRow {
  std::string ids;             // "7", "100-199"
  std::string media;           // MediaSpec::describe(), or "callbacks only"
  std::string placement;       // PlaceSpec::describe()
  std::string state;           // "waiting", "visible 3.2 s", "held", "error: ...", "disabled: ...", "skipped: ..."
  int line = 0;                // where it was declared in the scene file (0 for none)
  MappingHealth health = MappingHealth::ok;
  std::string reason;          // why it is not ok, "scene.lua:12: message"; "" when ok
  int reason_line = 0;         // the line the reason points at (a callback's failing statement), else `line`
};

struct ConsoleLine {
  int level = 0;               // 0 print output, 1 warning, 2 error
  std::string text;            // errors read "file:line: message"
  int repeats = 1;             // the same line in a row is shown once with its count
};

struct SceneStatus {
  std::string file;            // the scene file in use ("" when none is loaded)
  std::string dictionary;      // what the scene asked for ("" when it did not)
  bool ok = false;             // a scene is loaded (the last good one stays when a reload fails)
  std::string error;           // the last load error, "file:line: message"; empty after a good load
  int error_line = 0;
  uint64_t generation = 0;     // increases at every successful (re)load
  std::vector<MappingRow> mappings;
  std::vector<ConsoleLine> console;   // the newest lines, oldest first
  uint64_t console_serial = 0;        // increases whenever a line is added or repeated
  double script_ms = 0;               // time spent in Lua on this frame
};

// The topmost overlay whose quad holds image point p (the last drawn wins), only web cards when `web_only`;
// -1 when none. What a click on the live view, or `--actions click=X,Y`, lands on.
int overlay_at(const std::vector<Overlay>& overlays, cv::Point2d p, bool web_only);

}  // namespace arwb
