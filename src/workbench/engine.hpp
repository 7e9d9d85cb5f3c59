// The workbench's worker: capture and detection on their own thread. It pulls frames from the source at the
// acquisition's fps cap, runs the detector with the full trace (its first stage is acquisition's resize; the Frame
// shows the resized image) and the peer detectors when asked, draws the stage views and publishes the finished
// Frame. The UI thread takes the latest one without waiting.
//
// Settings reach the worker through setters that only store the new value; the worker applies them before its
// next frame. A source that fails is logged and replaced by the synthetic source, so the loop never stops.
//
// Stopping waits for the worker, but not for ever: a scene stuck in a library call that never returns (none is
// known: every call is bounded, see script/lua_host.hpp) must not keep the window from closing. After the wait the
// worker is left running on its own state, which it shares, so the Engine can still be destroyed safely.
#pragma once

#include "board/board_spec.hpp"
#include "detect/detector.hpp"
#include "workbench/frame.hpp"
#include "detect/params.hpp"
#include "synth/synthetic_source.hpp"
#include "capture/clip_recorder.hpp"
#include "capture/source.hpp"

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace arwb {

struct EngineConfig {
  SourceSpec source;
  std::vector<std::string> dictionaries{"ARUCO_ORIGINAL"};
  DetectorParams params;
  AcquisitionSettings acquisition;
  TraceLevel level = TraceLevel::full;
  int threads = 1;   // detector threads (the UI has the other core)
  std::string scene_file;   // a Lua scene or XML database to load at start ("" none)
  std::string calibration_file;   // a calibration to load at start (--calib; "" none)
  // The printed marker's side (--marker-size, any unit: mm, cm, m): poses in that unit. 0: in marker sides.
  double marker_size = 0;
  // > 0: the synthetic source's world moves on this many seconds per frame taken, not with the clock, and the
  // Calibrate workspace judges every frame it gives (--synthetic-step): the same frames on any machine.
  double synthetic_step_s = 0;
};

class Engine {
 public:
  // `log(level, message)` is called from the worker thread for what a user should see (0 info, 1 warning, 2 error).
  using LogFn = std::function<void(int level, const std::string& message)>;
  Engine(EngineConfig config, LogFn log);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

  void start();
  // Stops the worker and waits for it up to timeout_s (negative: for ever). False when it did not finish in time:
  // it is then detached (logged), and the process should exit rather than wait.
  bool stop(double timeout_s = -1);
  // "the worker did not stop within 0.5 s (it was running the scene's script); quitting without it": what the
  // worker was doing when stop(timeout_s) gave up on it.
  std::string stuck_message(double timeout_s) const;

  // The newest finished frame, or null before the first. Never blocks on detection.
  std::shared_ptr<const Frame> latest() const;
  // Waits (up to timeout_s) for a frame newer than `after`; for scripted runs and tests.
  std::shared_ptr<const Frame> wait_newer(uint64_t after, double timeout_s) const;

  void open_source(const SourceSpec& spec);
  // A source made elsewhere (a lab cell: lab/cell_source.hpp), shown under `spec`'s name; it is opened like any
  // other (playback applied, its first frame shown even when frozen). A TruthSource's markers become the truth.
  void open_made_source(std::unique_ptr<FrameSource> source, const SourceSpec& spec);
  SourceSpec source() const;
  void set_params(const DetectorParams& p);
  void set_dictionaries(const std::vector<std::string>& names);
  void set_acquisition(const AcquisitionSettings& a);
  void set_playback(const Playback& p);
  // step() and next_frame() return a ticket: served() reaches it once the worker has taken that frame and, when the
  // source gave a new one, published it (for scripts and tests that must see each step).
  uint64_t step(int delta);
  void seek(int position);
  void set_synthetic(const SyntheticControls& c);
  void set_frozen(bool frozen);
  uint64_t next_frame();   // while frozen: one new frame; a video or folder's is the one after the frame shown
  uint64_t served() const;
  bool running() const;   // the worker is running (started, not stopped)
  void set_peers(bool opencv, bool apriltag);
  // How the stage pictures are drawn (inspect/trace_view.hpp); a change redraws a frozen frame's.
  void set_stage_style(const StageViewStyle& style);
  // Loads a scene (Lua or XML database; "" unloads). Errors reach the frame's SceneStatus and the log; the last
  // good scene stays. The file is then watched and reloaded when it changes on disk.
  void load_scene(const std::string& path);

  // Calibration (the Calibrate workspace). While calibrating, every new frame is searched for the board and fed
  // to the session, whose state each Frame carries; the solve runs on a thread of its own, and a finished one is
  // published with the current frame even when no new frame comes (frozen, or a video at its end).
  void set_calibrating(bool on);
  void set_calibration_board(const BoardSpec& board);
  void set_calibration_capture(bool on);
  void drop_calibration_view(const std::string& name);
  void reset_calibration();
  // Reads a calibration file (read_calibration) for the undistorted view; a bad one is logged and the last good one
  // stays. "" forgets it.
  void load_calibration(const std::string& path);
  // Each frame also undistorted (Frame::undistorted) with the newest calibration.
  void set_undistort(bool on);
  // The printed marker's side for poses (Frame::pose_marker_side); 0 or less: poses in marker sides.
  void set_marker_size(double side);
  // Every new frame from the source, as taken (before acquisition), into `recorder` (the Lab workspace's Record);
  // null stops handing them over. The recorder encodes on its own thread: the worker never waits on the disk.
  void set_recorder(std::shared_ptr<ClipRecorder> recorder);

  double detect_fps() const;                 // finished frames per second over the last second or so
  uint64_t frames_done() const;

 private:
  struct Pending;                            // settings changed since the worker last looked
  struct Worker;                             // state only the worker thread touches
  struct State;                              // everything the worker uses, shared with it (see stop())
  std::shared_ptr<State> s_;
  std::thread thread_;
};

}  // namespace arwb
