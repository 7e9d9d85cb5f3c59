#include "workbench/engine.hpp"

#include "capture/opencv_error.hpp"

#include "peers/match.hpp"
#include "peers/peers.hpp"
#include "workbench/scene_stage.hpp"
#include "inspect/trace_view.hpp"
#include "detect/video_search.hpp"
#include "calibration/calibration_file.hpp"
#include "calibration/session.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>
#include <optional>
#include <stdexcept>

namespace arwb {

namespace {
using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// arwb's markers of the peer's dictionary against the peer's, by the one matching rule (arwb the reference), so
// the Peers panel only draws the result.
void match_with_arwb(const std::vector<Marker>& ours, PeerDetections& pd) {
  std::vector<Marker> same;
  std::vector<size_t> index;   // into `ours`
  for (size_t i = 0; i < ours.size(); ++i) {
    if (ours[i].dict != pd.dict) {
      ++pd.other_dicts;
      continue;
    }
    same.push_back(ours[i]);
    index.push_back(i);
  }
  pd.matching = match_markers(same, pd.markers);
  for (MatchedPair& p : pd.matching.pairs) p.reference = index[p.reference];
  for (size_t& i : pd.matching.only_reference) i = index[i];
}
}  // namespace

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
  std::optional<std::string> scene_file;
  std::optional<bool> calibrating, calibration_capture, undistort;
  std::optional<BoardSpec> calibration_board;
  std::vector<std::string> calibration_drops;
  bool calibration_reset = false;
  std::optional<std::string> calibration_file;
  std::optional<double> marker_size;
  bool any() const {
    return source || made || params || dictionaries || acquisition || playback || !steps.empty() || seek || synthetic || frozen ||
           next_frame || peers || scene_file || calibrating || calibration_capture || undistort || calibration_board ||
           !calibration_drops.empty() || calibration_reset || calibration_file || marker_size;
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
  std::unique_ptr<OpenCvArucoPeer> opencv;
  std::unique_ptr<AprilTagPeer> apriltag;
  std::string peers_dict;        // the dictionary the peers were made for
  cv::Mat raw;                   // the source's last frame, before acquisition
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
  Clock::time_point t0 = Clock::now();
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
  void publish(std::shared_ptr<Frame> f);
  void calibrate(Worker& w, Frame& f, bool fresh, double sx, double sy);
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
  SourceSpec source_in_use_;
};

Engine::Engine(EngineConfig config, LogFn log) : s_(std::make_shared<State>()) {
  s_->log_ = std::move(log);
  s_->worker_->config = std::move(config);
  s_->pending_->source = s_->worker_->config.source;
  s_->pending_->dictionaries = s_->worker_->config.dictionaries;
  if (!s_->worker_->config.scene_file.empty()) s_->pending_->scene_file = s_->worker_->config.scene_file;
  s_->source_in_use_ = s_->worker_->config.source;
  if (!s_->worker_->config.calibration_file.empty()) s_->pending_->calibration_file = s_->worker_->config.calibration_file;
  if (s_->worker_->config.marker_size > 0) s_->pending_->marker_size = s_->worker_->config.marker_size;
}

Engine::~Engine() { stop(); }

void Engine::start() {
  if (s_->running_.exchange(true)) return;
  {
    std::lock_guard lock(s_->mutex_);
    s_->done_ = false;
  }
  // The thread holds the state too: if stop() gives up on it, it can go on (or come back) without a dangling Engine.
  thread_ = std::thread([s = s_] {
    s->run();
    {
      std::lock_guard lock(s->mutex_);
      s->done_ = true;
    }
    s->published_.notify_all();
  });
}

bool Engine::stop(double timeout_s) {
  s_->running_ = false;
  s_->published_.notify_all();
  if (!thread_.joinable()) return true;
  if (timeout_s >= 0) {
    std::unique_lock lock(s_->mutex_);
    if (!s_->published_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return s_->done_; })) {
      lock.unlock();
      char b[32];
      std::snprintf(b, sizeof b, "%.1f", timeout_s);
      s_->log_(2, std::string("the worker did not stop within ") + b +
                      " s (stuck in a scene's script?); quitting without it");
      thread_.detach();
      return false;
    }
  }
  thread_.join();
  return true;
}

std::shared_ptr<const Frame> Engine::latest() const {
  std::lock_guard lock(s_->mutex_);
  return s_->latest_;
}

std::shared_ptr<const Frame> Engine::wait_newer(uint64_t after, double timeout_s) const {
  std::unique_lock lock(s_->mutex_);
  s_->published_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                      [&] { return (s_->latest_ && s_->latest_->index > after) || !s_->running_; });
  return s_->latest_;
}

#define ARWB_SET(field, value)    \
  do {                            \
    std::lock_guard lock(s_->mutex_); \
    s_->pending_->field = value;      \
  } while (0)

void Engine::open_source(const SourceSpec& spec) {
  std::lock_guard lock(s_->mutex_);
  s_->pending_->source = spec;
  s_->pending_->made.reset();
}
void Engine::open_made_source(std::unique_ptr<FrameSource> source, const SourceSpec& spec) {
  std::lock_guard lock(s_->mutex_);
  s_->pending_->source = spec;
  s_->pending_->made = std::move(source);
}
SourceSpec Engine::source() const {
  std::lock_guard lock(s_->mutex_);
  return s_->source_in_use_;
}
void Engine::set_params(const DetectorParams& p) { ARWB_SET(params, p); }
void Engine::set_dictionaries(const std::vector<std::string>& names) { ARWB_SET(dictionaries, names); }
void Engine::set_acquisition(const AcquisitionSettings& a) { ARWB_SET(acquisition, a); }
void Engine::set_playback(const Playback& p) { ARWB_SET(playback, p); }
void Engine::seek(int position) { ARWB_SET(seek, position); }
void Engine::set_synthetic(const SyntheticControls& c) { ARWB_SET(synthetic, c); }
void Engine::set_frozen(bool frozen) { ARWB_SET(frozen, frozen); }
uint64_t Engine::next_frame() {
  std::lock_guard lock(s_->mutex_);
  s_->pending_->next_frame = true;
  return s_->pending_->asked = ++s_->asked_;
}
void Engine::set_peers(bool opencv, bool apriltag) { ARWB_SET(peers, std::make_pair(opencv, apriltag)); }
void Engine::load_scene(const std::string& path) { ARWB_SET(scene_file, path); }
void Engine::set_calibrating(bool on) { ARWB_SET(calibrating, on); }
void Engine::set_calibration_board(const BoardSpec& board) { ARWB_SET(calibration_board, board); }
void Engine::set_calibration_capture(bool on) { ARWB_SET(calibration_capture, on); }
void Engine::reset_calibration() { ARWB_SET(calibration_reset, true); }
void Engine::load_calibration(const std::string& path) { ARWB_SET(calibration_file, path); }
void Engine::set_undistort(bool on) { ARWB_SET(undistort, on); }
void Engine::set_marker_size(double side) { ARWB_SET(marker_size, side); }
#undef ARWB_SET
void Engine::drop_calibration_view(const std::string& name) {
  std::lock_guard lock(s_->mutex_);
  s_->pending_->calibration_drops.push_back(name);
}
uint64_t Engine::step(int delta) {
  std::lock_guard lock(s_->mutex_);
  s_->pending_->steps.push_back(delta);
  return s_->pending_->asked = ++s_->asked_;
}
uint64_t Engine::served() const { return s_->served_.load(); }
bool Engine::running() const { return s_->running_.load(); }

double Engine::detect_fps() const { return s_->detect_fps_.load(); }
uint64_t Engine::frames_done() const { return s_->frames_.load(); }

void Engine::State::publish(std::shared_ptr<Frame> f) {
  {
    std::lock_guard lock(mutex_);
    latest_ = std::move(f);
  }
  published_.notify_all();
}

// The frame's calibration: the session fed with a new frame while calibrating, the loaded calibration fitted to
// the frame's size, the synthetic camera's truth and the undistorted image.
void Engine::State::camera(Worker& w, Frame& f) {
  if (w.loaded_raw && f.image.size() != w.loaded_for) {
    w.loaded_for = f.image.size();
    if (Result<Calibration> c = calibration_for_size(*w.loaded_raw, f.image.size())) {
      w.loaded = std::make_shared<const Calibration>(std::move(*c));
    } else {
      w.loaded.reset();
      log_(2, c.error());
    }
  }
  if (!w.loaded_raw) w.loaded.reset();
  f.loaded_calibration = w.loaded;
  f.pose_marker_side = w.marker_size > 0 && std::isfinite(w.marker_size) ? w.marker_size : 1.0;
}

void Engine::State::calibrate(Worker& w, Frame& f, bool fresh, double sx, double sy) {
  if (w.calibrating) {
    CalibrationSession& session = w.calibration();
    if (fresh) {
      const bool stills = w.info.kind == SourceKind::folder || w.info.kind == SourceKind::image;
      session.set_stills(stills);
      const std::string name = w.info.kind == SourceKind::folder && !w.info.item.empty() ? w.info.item
                               : w.info.kind == SourceKind::video ? "frame " + std::to_string(w.info.position)
                                                                  : "frame " + std::to_string(f.index);
      // Offered to the search on the session's own thread: a frame without a board can take OpenCV a second, which
      // must not stop the live view (nor quitting). A folder's image that comes while it is busy is skipped; a
      // looping folder shows it again.
      // A synthetic world stepped per frame waits for the search instead: a frame skipped would put the next
      // frame judged a step further on, and a slow machine would see the board move between every two.
      const auto* syn = dynamic_cast<const SyntheticSource*>(w.source.get());
      if (syn && syn->frame_step() > 0) {
        session.feed(f.image, name);
        w.calibration_searched = true;
      } else {
        w.calibration_searched = session.offer(f.image, name);
      }
      w.calibration_name = name;
    } else if (!w.calibration_searched) {
      // The frame shown was skipped while the search was busy: searched once the search is free, so that a frozen
      // or ended source shows its board (the finished search's poll brings the worker back here).
      w.calibration_searched = session.offer(f.image, w.calibration_name);
    }
    f.calibration_name = w.calibration_name;
    f.calibration = session.snapshot();
  }
  if (const auto* syn = dynamic_cast<const SyntheticSource*>(w.source.get())) {
    if (const SynthCamera* cam = syn->board_camera()) {
      Calibration t;
      t.camera_matrix = cam->camera_matrix;
      // Pixel centres scale, not pixel corners (the same rule as the truth's corners above).
      t.camera_matrix(0, 0) *= sx;
      t.camera_matrix(1, 1) *= sy;
      t.camera_matrix(0, 2) = (t.camera_matrix(0, 2) + 0.5) * sx - 0.5;
      t.camera_matrix(1, 2) = (t.camera_matrix(1, 2) + 0.5) * sy - 0.5;
      t.distortion = cam->distortion;
      t.image_size = f.image.size();
      t.source = "the synthetic camera";
      f.calibration_truth = std::move(t);
    }
  }
  if (!w.undistort) return;
  // The newest solve, else the loaded file.
  const Calibration* use = nullptr;
  std::shared_ptr<const void> owner;
  std::string by;
  std::shared_ptr<const CalibrationSnapshot> snap = w.session ? w.session->snapshot() : nullptr;
  if (snap && snap->solution && snap->solution->calibration.image_size == f.image.size()) {
    use = &snap->solution->calibration;
    owner = snap->solution;
    by = "the solve of " + std::to_string(snap->solution->view_names.size()) + " views";
  } else if (w.loaded) {
    use = w.loaded.get();
    owner = w.loaded;
    by = w.loaded->source;
  }
  if (!use) return;
  if (owner != w.maps_of || f.image.size() != w.maps_size) {
    try {
      cv::initUndistortRectifyMap(cv::Mat(use->camera_matrix), use->distortion, cv::noArray(),
                                  cv::Mat(use->camera_matrix), f.image.size(), CV_16SC2, w.map1, w.map2);
    } catch (const cv::Exception& e) {
      log_(2, "undistort: " + one_line_reason(e));
      w.undistort = false;
      return;
    }
    w.maps_of = owner;
    w.maps_size = f.image.size();
  }
  cv::remap(f.image, f.undistorted, w.map1, w.map2, cv::INTER_LINEAR);
  f.undistorted_by = by;
}

void Engine::State::run() {
  Worker& w = *worker_;
  auto adopt = [&](std::unique_ptr<FrameSource> src) {
    w.source = std::move(src);
    if (!w.source) return;
    w.source->set_playback(w.playback);
    if (auto* syn = dynamic_cast<SyntheticSource*>(w.source.get())) {
      syn->world().set_controls(w.synthetic);
      syn->set_frame_step(w.config.synthetic_step_s);
    }
  };
  auto fall_back = [&](const std::string& why) {
    log_(2, why + "; showing the synthetic source");
    std::string err;
    adopt(arwb::open_source(SourceSpec{}, &err));
    w.config.source = SourceSpec{};
    std::lock_guard lock(mutex_);
    source_in_use_ = SourceSpec{};
  };
  while (running_) {
    // 1. Take what the UI changed.
    Pending p;
    {
      std::lock_guard lock(mutex_);
      p = std::move(*pending_);
      *pending_ = Pending{};
    }
    w.asked = std::max(w.asked, p.asked);
    if (p.source) {
      std::string err;
      std::unique_ptr<FrameSource> src;
      // A source made by the window (a lab cell) is handed over whole: from now on only this thread touches it.
      if (p.made) src = std::move(p.made);
      else src = arwb::open_source(*p.source, &err);
      if (src) {
        adopt(std::move(src));
        w.config.source = *p.source;
        w.ended_logged = false;
        w.next_due = 0;
        w.take_one = true;   // show the new source's first frame even when frozen
        {
          std::lock_guard lock(mutex_);
          source_in_use_ = *p.source;
        }
        log_(0, "source: " + p.source->text());
        w.video.reset();
        w.video_before.reset();
      } else if (!w.source) {
        fall_back(err);
      } else {
        log_(2, err + "; keeping " + w.config.source.text());
      }
    }
    if (p.dictionaries) {
      std::string list;
      for (const auto& n : *p.dictionaries) list += (list.empty() ? "" : ",") + n;
      std::string err;
      if (auto dicts = parse_dictionaries(list, &err)) {
        w.config.dictionaries = *p.dictionaries;
        w.detector.emplace(std::move(*dicts), w.config.params);
        w.detector->set_acquisition(w.config.acquisition);
        w.redetect = true;
      } else {
        log_(2, "dictionaries: " + err);
      }
    }
    if (!w.detector) {
      w.detector.emplace(std::vector<Dictionary>{make_aruco_original()}, w.config.params);
      w.detector->set_acquisition(w.config.acquisition);
    }
    if (p.params) {
      w.config.params = *p.params;
      w.detector->set_params(*p.params);
      w.redetect = true;
    }
    if (p.acquisition) {
      w.config.acquisition = *p.acquisition;
      w.detector->set_acquisition(*p.acquisition);
      w.video.reset();   // the known markers are in the old working image's pixels
      w.video_before.reset();
      w.next_due = 0;
      w.redetect = true;
    }
    if (p.peers) {
      w.peer_opencv = p.peers->first;
      w.peer_apriltag = p.peers->second;
      w.redetect = true;
    }
    if (p.playback) w.playback = *p.playback;
    if (p.synthetic) w.synthetic = *p.synthetic;
    if (w.source) {
      if (p.playback) w.source->set_playback(*p.playback);
      for (int d : p.steps) {
        w.source->step(d);
        w.take_one = true;
      }
      if (p.seek) {
        w.source->seek(*p.seek);
        w.take_one = true;
      }
      if (p.seek || !p.steps.empty()) {   // the next frame does not follow the last
        w.video.reset();
        w.video_before.reset();
      }
      auto* syn = dynamic_cast<SyntheticSource*>(w.source.get());
      if (p.synthetic && syn) {
        syn->world().set_controls(*p.synthetic);
        if (w.frozen) w.take_one = true;   // a frozen synthetic source still shows the new slider values
      }
    }
    if (p.frozen) w.frozen = *p.frozen;
    if (p.next_frame) w.take_one = true;
    if (p.scene_file) {
      if (!w.stage) w.stage = std::make_unique<SceneStage>(media::StoreMode::live);
      if (w.stage->load(*p.scene_file)) {
        log_(0, p.scene_file->empty() ? "scene unloaded" : "scene: " + *p.scene_file);
      } else {
        log_(2, w.stage->status().error + (w.stage->status().ok ? " (the last good scene stays)" : ""));
      }
      // marker() calls the scene refused while loading: errors of the log too, not only of the scene's console.
      for (const std::string& e : w.stage->take_errors()) log_(2, e);
      w.redetect = true;   // show the new scene on the current frame, even when frozen
    }

    if (p.calibrating) w.calibrating = *p.calibrating;
    if (p.calibration_board) w.calibration().set_board(*p.calibration_board);
    if (p.calibration_capture) w.calibration().set_capture(*p.calibration_capture);
    if (p.calibration_reset) w.calibration().reset();
    for (const std::string& name : p.calibration_drops) {
      if (w.calibration().drop_view(name)) {
        log_(0, "calibration: dropped " + name + "; solving the " +
                    std::to_string(w.calibration().snapshot()->views.size()) + " views left");
      } else {
        log_(1, "calibration: no view '" + name + "' to drop");
      }
    }
    if (p.undistort) w.undistort = *p.undistort;
    if (p.marker_size) w.marker_size = *p.marker_size;
    if (p.calibration_file) {
      if (p.calibration_file->empty()) {
        w.loaded_raw.reset();
      } else if (Result<Calibration> c = read_calibration(*p.calibration_file)) {
        w.loaded_raw = std::move(*c);
        log_(0, "calibration: " + *p.calibration_file);
      } else {
        log_(2, c.error() + (w.loaded_raw ? " (the calibration loaded before stays)" : ""));
      }
      w.loaded.reset();
      w.loaded_for = {};
    }
    // Show at once what changed the calibration (a view dropped, a solve finished), even when no new frame comes.
    if (p.calibrating || p.calibration_board || p.calibration_capture || p.calibration_reset ||
        !p.calibration_drops.empty() || p.undistort || p.calibration_file || p.marker_size) {
      w.redetect = true;
    }
    if (w.calibrating && w.session && w.session->poll()) w.redetect = true;

    // 2. A new frame when it is due (the fps cap), unless frozen.
    const double now = seconds_since(w.t0);
    bool fresh = false;
    const double period = w.config.acquisition.fps_cap > 0 ? 1.0 / w.config.acquisition.fps_cap : 0.0;
    if (w.source && ((!w.frozen && now >= w.next_due) || w.take_one)) {
      w.take_one = false;
      const auto c0 = Clock::now();
      cv::Mat next;
      const SourceStatus st = w.source->next(now, next);
      w.capture_ms = ms_between(c0, Clock::now());
      // Keep to the cap's grid, but never try to catch up on frames missed while busy.
      w.next_due = std::max(w.next_due + period, now);
      switch (st.status) {
        case FrameStatus::ok:
          if (!next.empty()) {
            w.raw = std::move(next);
            const auto* known = dynamic_cast<const TruthSource*>(w.source.get());
            w.raw_truth = known ? known->truth() : std::vector<TruthMarker>{};
            fresh = true;
          }
          break;
        case FrameStatus::same: break;
        case FrameStatus::end:
          if (!w.ended_logged) log_(0, w.config.source.text() + ": end (the last frame stays; seek or enable loop)");
          w.ended_logged = true;
          break;
        case FrameStatus::error: log_(1, st.message); break;
        case FrameStatus::gone: fall_back(st.message); break;
      }
      w.info = w.source->info();
    }

    // 3. Detect and publish.
    if ((fresh || w.redetect) && !w.raw.empty() && w.detector) {
      w.redetect = false;
      auto f = std::make_shared<Frame>();
      f->index = ++w.index;
      f->time_s = now;
      f->source = w.info;
      f->capture_ms = w.capture_ms;
      // Acquisition's resize is the detector's first stage, timed in the trace; the frame shows its result.
      const auto d0 = Clock::now();
      if (fresh) w.video_before = w.video;
      else w.video = w.video_before;
      w.video.detect(*w.detector, w.raw, &f->trace, w.config.level, w.config.threads, &f->image);
      f->detect_ms = ms_between(d0, Clock::now());
      f->params = w.config.params;
      f->dictionaries = w.config.dictionaries;
      if (f->image.channels() == 1) cv::cvtColor(f->image, f->image, cv::COLOR_GRAY2BGR);
      const double sx = double(f->image.cols) / w.raw.cols, sy = double(f->image.rows) / w.raw.rows;
      for (TruthMarker t : w.raw_truth) {
        for (auto& c : t.corners) c = {float((c.x + 0.5) * sx - 0.5), float((c.y + 0.5) * sy - 0.5)};
        f->truth.push_back(std::move(t));
      }
      if (w.config.level == TraceLevel::full) render_stage_views(f->image, f->trace, f->views);
      auto shrink = [](const cv::Mat& in, cv::Mat& out) {
        if (in.empty()) return;
        const double s = std::min({192.0 / in.cols, 144.0 / in.rows, 1.0});
        cv::resize(in, out, cv::Size(std::max(1, int(in.cols * s)), std::max(1, int(in.rows * s))), 0, 0,
                   cv::INTER_AREA);
      };
      // The tracker runs on every frame (its tracks carry the poses the Pose panel and the 3D overlays show); the
      // scene, when there is one, runs on its tracks.
      camera(w, *f);
      if (!w.stage) w.stage = std::make_unique<SceneStage>(media::StoreMode::live);
      if (!w.stage->loaded()) {
        w.stage->run(*f, now);
      } else {
        const uint64_t before = w.stage->status().generation;
        const std::string before_error = w.stage->status().error;
        w.stage->run(*f, now);
        // Reloads after an edit on disk are news for the log too.
        const SceneStatus& st = f->scene;
        if (st.generation != before && before != 0) log_(0, "scene reloaded: " + st.file);
        if (!st.error.empty() && st.error != before_error) log_(2, st.error);
        // Runtime errors (callbacks, text functions, media that cannot be loaded), each text once per load.
        for (const std::string& e : w.stage->take_errors()) log_(2, e);
      }
      shrink(f->image, f->image_thumb);
      for (int i = 0; i < kStageCount; ++i) shrink(f->views[size_t(i)], f->thumbs[size_t(i)]);
      // Peers, on the first dictionary.
      const std::string& dict = w.config.dictionaries.empty() ? std::string("ARUCO_ORIGINAL") : w.config.dictionaries[0];
      if (w.peers_dict != dict) {
        w.opencv.reset();
        w.apriltag.reset();
        w.peers_dict = dict;
      }
      // One peer on this frame: its markers matched to arwb's, or why it could not run.
      auto run_peer = [&](const char* name, auto&& detect) {
        PeerDetections pd;
        pd.name = name;
        pd.dict = dict;
        try {
          PeerResult r = detect();
          pd.markers = std::move(r.markers);
          pd.ms = r.ms;
          match_with_arwb(f->trace.markers, pd);
        } catch (const std::exception& e) {
          pd.error = one_line_reason(e);
        }
        f->peers.push_back(std::move(pd));
      };
      if (w.peer_opencv) {
        run_peer("opencv_aruco", [&] {
          try {
            if (!w.opencv) w.opencv = std::make_unique<OpenCvArucoPeer>(dict);
          } catch (const std::exception& e) {
            throw std::runtime_error("OpenCV aruco cannot read " + dict + ": " + one_line_reason(e));
          }
          return w.opencv->detect(f->image);
        });
      }
      if (w.peer_apriltag) {
        run_peer("apriltag", [&] {
          if (!AprilTagPeer::supports(dict))
            throw std::runtime_error("AprilTag reads only the APRILTAG_* families, not " + dict);
          if (!w.apriltag) w.apriltag = std::make_unique<AprilTagPeer>(dict);
          return w.apriltag->detect(f->image);
        });
      }
      calibrate(w, *f, fresh, sx, sy);
      const double done = seconds_since(w.t0);
      w.finished.push_back(done);
      while (!w.finished.empty() && w.finished.front() < done - 1.0) w.finished.pop_front();
      detect_fps_ = double(w.finished.size());
      ++frames_;
      publish(std::move(f));
      served_ = w.asked;   // after the frame it took is the latest
      continue;
    }
    served_ = w.asked;   // the source gave nothing new (a still image, a paused video, its end)
    // 4. Idle until the next frame is due or a setting changes.
    const double wait = std::clamp(w.next_due - seconds_since(w.t0), 0.001, 0.02);
    std::unique_lock lock(mutex_);
    published_.wait_for(lock, std::chrono::duration<double>(wait), [&] { return !running_ || pending_->any(); });
    const double idle_since = seconds_since(w.t0);
    while (!w.finished.empty() && w.finished.front() < idle_since - 1.0) w.finished.pop_front();
    detect_fps_ = double(w.finished.size());
  }
}

}  // namespace arwb
