// The worker's inside, shared by the engine's files (internal to src/workbench):
//   engine.cpp            the Engine the UI holds: start, stop, the latest frame, setters that only store a value
//   engine_worker.cpp     the worker's loop: take what the UI changed, a frame when due, detect and publish, idle
//   engine_calibrate.cpp  the frame's camera and calibration: the session fed, the truth, the undistorted image
#pragma once

#include "workbench/engine.hpp"

#include "calibration/calibration_file.hpp"
#include "calibration/session.hpp"
#include "detect/video_search.hpp"
#include "peers/peers.hpp"
#include "workbench/scene_stage.hpp"

#include <chrono>
#include <deque>
#include <optional>

namespace arwb {

struct Engine::Pending {
  std::optional<SourceSpec> source;
  std::unique_ptr<FrameSource> made;   // open_made_source; `source` then names it
  std::optional<DetectorParams> params;
  std::optional<std::vector<std::string>> dictionaries;
  std::optional<AcquisitionSettings> acquisition;
  std::optional<Playback> playback;
  std::vector<int> steps;
  std::optional<int> seek;
  std::optional<SyntheticControls> synthetic;
  std::optional<bool> frozen;
  bool next_frame = false;
  uint64_t asked = 0;   // the last ticket of next_frame() or step() among these
  std::optional<std::pair<bool, bool>> peers;
  std::optional<StageViewStyle> stage_style;
  std::optional<std::string> scene_file;
  std::optional<bool> calibrating, calibration_capture, undistort;
  std::optional<BoardSpec> calibration_board;
  std::vector<std::string> calibration_drops;
  bool calibration_reset = false;
  std::optional<std::string> calibration_file;
  std::optional<double> marker_size;
  std::optional<std::shared_ptr<ClipRecorder>> recorder;
  bool any() const {
    return source || made || params || dictionaries || acquisition || playback || !steps.empty() || seek || synthetic || frozen ||
           next_frame || peers || stage_style || scene_file || calibrating || calibration_capture || undistort || calibration_board ||
           !calibration_drops.empty() || calibration_reset || calibration_file || marker_size ||
           recorder;
  }
};

struct Engine::Worker {
  EngineConfig config;
  std::unique_ptr<FrameSource> source;
  // The user's playback and scene settings, given to every source opened, so a source switched back to (or
  // fallen back to) shows what the sliders say.
  Playback playback;
  SyntheticControls synthetic;
  std::optional<Detector> detector;
  // Video mode: what the stream's last frames found, so that the next is searched around them (search_regions);
  // and as it was before the frame shown, so that the same frame again (a slider moved, a frozen frame) is searched
  // as it was the first time, its regions following the sliders.
  VideoSearch video, video_before;
  bool frozen = false;
  bool take_one = false;
  bool peer_opencv = false, peer_apriltag = false;
  StageViewStyle stage_style;
  std::unique_ptr<OpenCvArucoPeer> opencv;
  std::unique_ptr<AprilTagPeer> apriltag;
  std::string peers_dict;        // the dictionary the peers were made for
  cv::Mat raw;                   // the source's last frame, before acquisition
  std::shared_ptr<ClipRecorder> recorder;   // set_recorder: takes every new raw frame
  std::vector<TruthMarker> raw_truth;
  SourceInfo info;
  double capture_ms = 0;
  bool redetect = false;
  bool ended_logged = false;
  double next_due = 0;
  std::deque<double> finished;   // finish times of the last second
  std::unique_ptr<SceneStage> stage;   // the Lua scene or XML database, once one was asked for
  uint64_t index = 0;
  uint64_t asked = 0;   // the last ticket of next_frame() or step() taken from the UI
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  // Calibration: the session (made when first asked for, kept when the workspace is left), the loaded file (as
  // read, and as fitted to the frames' size) and the undistortion maps of the calibration last used.
  bool calibrating = false;
  bool undistort = false;
  double marker_size = 0;   // EngineConfig::marker_size, then set_marker_size
  std::string calibration_name;   // the name the last frame was offered under
  bool calibration_searched = false;   // the frame shown was taken by the board search (not skipped as it was busy)
  std::unique_ptr<CalibrationSession> session;
  std::optional<Calibration> loaded_raw;
  std::shared_ptr<const Calibration> loaded;
  cv::Size loaded_for;
  // The newest solve (made at the source's own size) fitted to the frames' size, for the undistorted view.
  std::shared_ptr<const Solution> fitted_of;
  std::shared_ptr<const Calibration> fitted;
  cv::Size fitted_for;
  std::shared_ptr<const void> maps_of;   // held, so that its address is not another calibration's later
  cv::Size maps_size;
  cv::Mat map1, map2;
  CalibrationSession& calibration() {
    if (!session) session = std::make_unique<CalibrationSession>();
    return *session;
  }
};

struct Engine::State {
  void run();
  // The loop's steps, in the order run() takes them.
  void apply(Pending& p);                         // 1. what the UI changed
  bool capture(double now);                       // 2. a new frame when due (the fps cap), unless frozen: true if new
  void detect_and_publish(bool fresh, double now);   // 3.
  void idle();                                    // 4. until the next frame is due or a setting changes
  // apply()'s parts.
  void apply_source(Pending& p);
  void apply_detector(const Pending& p);
  void apply_playback(const Pending& p);
  Playback source_playback() const;
  void apply_scene(const Pending& p);
  void apply_calibration(const Pending& p);
  // detect_and_publish()'s parts, on the frame being made.
  void run_scene(Frame& f, double now);
  void run_peers(Frame& f);
  // A source taken into use with the user's playback and synthetic settings; a failed one replaced by the
  // synthetic source, logged with `why`.
  void adopt(std::unique_ptr<FrameSource> src);
  void fall_back(const std::string& why);
  void publish(std::shared_ptr<Frame> f);
  // The frame's calibration: the session fed with a new frame while calibrating, the synthetic camera's truth
  // (its matrix scaled by sx, sy to the frame's size) and the undistorted image.
  void calibrate(Worker& w, Frame& f, bool fresh);
  // The frame's camera for poses, before the tracker runs: the loaded calibration made for its size (null
  // without one) and the marker's side.
  void camera(Worker& w, Frame& f);

  LogFn log_;
  mutable std::mutex mutex_;
  mutable std::condition_variable published_;
  std::unique_ptr<Pending> pending_ = std::make_unique<Pending>();
  std::unique_ptr<Worker> worker_ = std::make_unique<Worker>();
  std::shared_ptr<const Frame> latest_;
  std::atomic<bool> running_{false};
  bool done_ = true;   // the thread has finished run() (guarded by mutex_)
  std::atomic<uint64_t> frames_{0};
  std::atomic<uint64_t> asked_{0}, served_{0};   // next_frame()'s and step()'s tickets, and the last one served
  std::atomic<double> detect_fps_{0};
  // What the worker is doing now, said when it does not stop in time ("running the scene's script").
  std::atomic<const char*> doing_{"waiting for a frame"};
  SourceSpec source_in_use_;
};

}  // namespace arwb
