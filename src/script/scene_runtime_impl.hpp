// The scene runtime's inside, shared by its files (internal to src/script):
//   scene_runtime.cpp   the frame step: enter and leave, on_update, overlays, the Scene panel's rows
//   scene_load.cpp      loading and reloading a file (Lua or XML), and the console
//   scene_callbacks.cpp calling the scene's Lua functions and applying what they return
//   scene_content.cpp   the pixels behind a media: images, cards, video players, stage pictures
//   scene_solid.cpp     3D media (cube, axes, model) and flat media drawn through the pose and the lens model
#pragma once

#include "script/scene_runtime.hpp"

#include "media/media_provider.hpp"
#include "script/scene_model.hpp"

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>
#include <vector>

namespace arwb::script {

// One (mapping, marker id, slot): what its callbacks changed and what it shows. Each track of an id in view holds
// a slot (the lowest free one when it entered), so two prints of one id have their own media, and a marker that
// leaves and comes back alone finds its video where it stopped.
struct Instance {
  bool media_set = false;      // a callback's return replaced the media
  MediaSpec media;
  int text_fn = LUA_NOREF;     // the replacing media's computed-text function
  bool place_set = false;
  PlaceSpec place;
  std::string content_key;     // image and web content, loaded once per key
  std::shared_ptr<MediaContent> content;
  std::string video_key;       // this instance's own video player
  std::shared_ptr<media::VideoContent> video;
  std::string mesh_key;        // a 3D media's mesh, made or loaded once per key
  std::shared_ptr<const Mesh> mesh;
  std::string load_error;      // why content or mesh could not be loaded (the loader's words), kept with its key
  double position = 0;         // seconds into the video: grows while the marker is tracked
  std::optional<Side> card_side;   // a text or web card: the side of its marker it was put on (place_apart)
  bool inside = false;
  bool fresh = false;          // entered on this frame (no dt to add yet)
  std::string error;           // this frame's problem, for the Scene panel
};

struct Program {
  std::unique_ptr<LuaState> lua;   // null for an XML database
  SceneDef def;
  std::string path, display;
  std::map<std::tuple<int, int, int>, Instance> instances;   // (mapping, id, slot)
  std::set<int> disabled;                              // functions stopped by a limit or repeated failures
  struct Streak {                                      // a function's failures with no success between
    std::string message;
    uint64_t frame = 0;
    int frames = 0;
  };
  std::map<std::pair<int, int>, Streak> streaks;       // (function, marker id)
  std::vector<std::string> mapping_error;              // per mapping: why part of it is disabled
  // Per mapping: the last on_enter or on_leave that failed, until the next of them runs cleanly (or is absent).
  // They run once per visit (on_leave with the marker gone), so a frame's own errors showed them for one frame,
  // or never.
  std::vector<std::string> event_error;
  std::map<uint64_t, int> inside;                      // tracks entered and not left -> their slot
  std::map<uint64_t, TrackedMarker> last;              // their last state (for on_leave)
  bool stage_note = false;                             // "no stage pictures" was said
};

struct FileSig {
  bool exists = false;
  long long mtime_ns = 0, size = 0, inode = 0;
  bool operator==(const FileSig&) const = default;
};

// "64 MiB", for messages about the memory cap.
std::string mib(std::size_t bytes);

struct SceneRuntime::Impl : Reporter {
  Impl(media::MediaProvider& s, ScriptLimits l) : store(s), limits(l) {}
  ~Impl() override { prog.reset(); }

  media::MediaProvider& store;
  ScriptLimits limits;
  SceneStatus status;
  std::unique_ptr<Program> prog;
  bool attempted = false;
  std::string attempt_path;
  FileSig attempt_sig;
  double frame_ms = 0;      // script time on this frame so far
  double pose_side = 1;     // this frame's marker side in the poses' unit, and the unit's name (m.pose.side, .unit)
  std::string pose_unit = "marker sides";
  uint64_t frame_no = 0;    // frames updated since construction
  bool skipped = false;     // an on_update or text call waited for the next frame (ScriptLimits::frame_ms)
  // Error lines not yet handed to the workbench's log (take_errors), each text once until the next load; at most
  // kMaxLoggedErrors distinct texts per load, then one line saying the rest are in the console.
  std::vector<std::string> fresh_errors;
  std::set<std::string> logged_errors;
  static constexpr size_t kMaxLoggedErrors = 50;
  std::vector<std::string> take_errors();
  // The first track whose on_update waited (id, track_id): the next frame starts there.
  std::pair<int, uint64_t> resume{-1, 0};
  // Reports print and warn lines that were over the frame's allowance.
  void report_suppressed(Program& p);

  // [SECTION] Console and loading (scene_load.cpp)
  void report(int level, const std::string& text_in) override;
  bool fail_load(const std::string& msg, int line);
  bool load(const std::string& path);
  bool load_lua(Program& p, const std::string& text, std::string* msg, int* line);
  bool load_xml(Program& p, const std::string& text, std::string* msg, int* line);
  bool reload_if_changed();
  void unload();

  // [SECTION] Calling Lua (scene_callbacks.cpp)
  std::string dict_of(const Program& p, const TrackedMarker& t) const;
  // "scene.lua:LINE: " for a function: where it was defined.
  std::string function_prefix(Program& p, int fn);
  // Calls function `fn` with m [, dt]. True with its one result on the stack when it ran; false when it failed
  // (reported; the function disabled when it passed a limit, overflowed the stack or failed the same way on
  // ScriptLimits::failures_in_a_row frames) or, for on_update and text, when the frame's time was used up.
  bool call(Program& p, int mi, int fn, const TrackedMarker& t, bool held, const double* dt, const std::string& what,
            Instance* inst);
  void set_media(Program& p, Instance& inst, const MediaSpec& spec, int text_fn);
  // A callback's result (on top of the stack, popped): nothing, or {media = ..., place = ...}.
  void apply_return(Program& p, int fn, Instance& inst, const std::string& ctx);
  // Calls `fn` (when there is one) and applies what it returns; false when it failed (call() reported it).
  bool run_callback(Program& p, int mi, int fn, const TrackedMarker& t, bool held, const double* dt,
                    const char* what, Instance& inst);
  // on_enter or on_leave: the same, and the mapping's event_error set or cleared by how it went.
  void run_event(Program& p, int mi, int fn, const TrackedMarker& t, bool held, const char* what, Instance& inst);
  void enter(Program& p, const TrackedMarker& t);
  void leave(Program& p, uint64_t track_id);
  // The instance of mapping `mi` for a track in view.
  Instance& instance_of(Program& p, int mi, const TrackedMarker& t);

  // [SECTION] Media content (scene_content.cpp)
  // The pixels for a media of an instance; null (reported) when there are none.
  std::shared_ptr<MediaContent> content_for(Program& p, const Mapping& m, Instance& inst, const MediaSpec& spec,
                                            const SceneInput& in,
                                            std::array<std::shared_ptr<MediaContent>, kStageCount>& stages);

  // [SECTION] 3D (scene_solid.cpp)
  // A 3D media's overlay for track t: its mesh in the marker's frame through t's pose. False (reported, with
  // inst.error set) when it cannot be drawn: no pose, a model that cannot be loaded, a placement that is not in
  // the marker's frame.
  bool solid_overlay(Program& p, const Mapping& m, Instance& inst, const MediaSpec& spec, const PlaceSpec& place,
                     const TrackedMarker& t, const SceneInput& in, Overlay* o);
  // With a calibration (not the assumed default values) and a pose, a flat media placed in the marker's plane
  // is drawn as a grid through the pose and the lens model, so it bends as the image does.
  static void through_lens(const TrackedMarker& t, const SceneInput& in, Overlay* o);

  // [SECTION] One frame (scene_runtime.cpp)
  std::vector<Overlay> update(const SceneInput& in);
  std::vector<cv::Rect2d> cards;   // this frame's text and web cards placed so far: the next keep clear of them
  // update()'s steps: on_enter and on_leave, on_update, and the overlay of mapping mi for one track.
  void enter_and_leave(Program& p, const std::vector<TrackEvent>& events, const std::vector<const TrackedMarker*>& seen,
                       const std::map<uint64_t, const TrackedMarker*>& by_track);
  void run_updates(Program& p, const std::vector<const TrackedMarker*>& seen, const SceneInput& in);
  void add_overlay(Program& p, int mi, const TrackedMarker& t, const SceneInput& in,
                   std::array<std::shared_ptr<MediaContent>, kStageCount>& stages, std::vector<Overlay>& overlays);
  void fill_rows(const std::vector<const TrackedMarker*>* seen);
};

}  // namespace arwb::script
