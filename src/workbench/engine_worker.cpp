// The worker's loop (engine_state.hpp): take what the UI changed, take a frame when it is due, detect, run the
// tracker, the scene and the peers on it, publish it, and idle until the next frame is due or a setting changes.
#include "workbench/engine_state.hpp"

#include "capture/opencv_error.hpp"
#include "inspect/trace_view.hpp"
#include "peers/match.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
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

void Engine::State::run() {
  while (running_) {
    Pending p;
    {
      std::lock_guard lock(mutex_);
      p = std::move(*pending_);
      *pending_ = Pending{};
    }
    doing_ = "applying new settings";
    apply(p);
    const double now = seconds_since(worker_->t0);
    doing_ = "reading the source";
    const bool fresh = capture(now);
    Worker& w = *worker_;
    if ((fresh || w.redetect) && !w.raw.empty() && w.detector) {
      detect_and_publish(fresh, now);
      served_ = w.asked;   // after the frame it took is the latest
      continue;
    }
    served_ = w.asked;   // the source gave nothing new (a still image, a paused video, its end)
    doing_ = "waiting for a frame";
    idle();
  }
}

void Engine::State::adopt(std::unique_ptr<FrameSource> src) {
  Worker& w = *worker_;
  w.source = std::move(src);
  if (!w.source) return;
  w.source->set_playback(source_playback());
  if (auto* syn = dynamic_cast<SyntheticSource*>(w.source.get())) {
    syn->world().set_controls(w.synthetic);
    syn->set_frame_step(w.config.synthetic_step_s);
  }
}

void Engine::State::fall_back(const std::string& why) {
  log_(2, why + "; showing the synthetic source");
  std::string err;
  adopt(arwb::open_source(SourceSpec{}, &err));
  worker_->config.source = SourceSpec{};
  std::lock_guard lock(mutex_);
  source_in_use_ = SourceSpec{};
}

// [SECTION] 1. What the UI changed

void Engine::State::apply(Pending& p) {
  Worker& w = *worker_;
  w.asked = std::max(w.asked, p.asked);
  if (p.recorder) w.recorder = std::move(*p.recorder);   // before the source: its first frame is the clip's
  apply_source(p);
  apply_detector(p);
  apply_playback(p);
  apply_scene(p);
  apply_calibration(p);
}

void Engine::State::apply_source(Pending& p) {
  if (!p.source) return;
  Worker& w = *worker_;
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

// Dictionaries, parameters, acquisition and the peers: the detector as the sliders say.
void Engine::State::apply_detector(const Pending& p) {
  Worker& w = *worker_;
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
  if (p.stage_style && !(*p.stage_style == w.stage_style)) {
    w.stage_style = *p.stage_style;
    w.redetect = true;
  }
}

// What a file source is told to do: a freeze pauses a video or folder, which resumes from the frame shown.
Playback Engine::State::source_playback() const {
  Playback pb = worker_->playback;
  pb.playing = pb.playing && !worker_->frozen;
  return pb;
}

// Playback, steps, seeking, the synthetic world's sliders, freezing and the next frame asked for.
void Engine::State::apply_playback(const Pending& p) {
  Worker& w = *worker_;
  if (p.playback) w.playback = *p.playback;
  if (p.synthetic) w.synthetic = *p.synthetic;
  if (p.frozen) w.frozen = *p.frozen;
  if (!w.source) return;
  if (p.playback || p.frozen) w.source->set_playback(source_playback());
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
  if (p.next_frame) {
    // A video or folder shows the frame after the one shown, not the one a playing video's clock has reached
    // meanwhile (which showed frame 25 after frame 2).
    if (w.info.kind == SourceKind::video || w.info.kind == SourceKind::folder) w.source->step(1);
    w.take_one = true;
  }
}

void Engine::State::apply_scene(const Pending& p) {
  if (!p.scene_file) return;
  Worker& w = *worker_;
  if (!w.stage) w.stage = std::make_unique<SceneStage>(media::StoreMode::live);
  doing_ = "loading the scene's script";
  if (w.stage->load(*p.scene_file)) {
    log_(0, p.scene_file->empty() ? "scene unloaded" : "scene: " + *p.scene_file);
  } else {
    log_(2, w.stage->status().error + (w.stage->status().ok ? " (the last good scene stays)" : ""));
  }
  // marker() calls the scene refused while loading: errors of the log too, not only of the scene's console.
  for (const std::string& e : w.stage->take_errors()) log_(2, e);
  w.redetect = true;   // show the new scene on the current frame, even when frozen
}

void Engine::State::apply_calibration(const Pending& p) {
  Worker& w = *worker_;
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
}

// [SECTION] 2. A frame when due

bool Engine::State::capture(double now) {
  Worker& w = *worker_;
  const double period = w.config.acquisition.fps_cap > 0 ? 1.0 / w.config.acquisition.fps_cap : 0.0;
  if (!w.source || !((!w.frozen && now >= w.next_due) || w.take_one)) return false;
  bool fresh = false;
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
        if (w.recorder) w.recorder->push(w.raw);
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
  return fresh;
}

// [SECTION] 3. Detect and publish

void Engine::State::detect_and_publish(bool fresh, double now) {
  Worker& w = *worker_;
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
  doing_ = "detecting markers";
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
  if (w.config.level == TraceLevel::full) {
    f->view_style = w.stage_style;
    render_stage_views(f->image, f->trace, f->views, w.stage_style, &f->view_labels);
  }
  // The tracker runs on every frame (its tracks carry the poses the Pose panel and the 3D overlays show); the
  // scene, when there is one, runs on its tracks.
  camera(w, *f);
  doing_ = "running the scene's script";
  run_scene(*f, now);
  doing_ = "drawing the stage pictures";
  thumbnail(f->image, f->image_thumb);
  for (int i = 0; i < kStageCount; ++i) thumbnail(f->views[size_t(i)], f->thumbs[size_t(i)]);
  doing_ = "running the peer detectors";
  run_peers(*f);
  doing_ = "searching for the calibration board";
  calibrate(w, *f, fresh);
  const double done = seconds_since(w.t0);
  w.finished.push_back(done);
  while (!w.finished.empty() && w.finished.front() < done - 1.0) w.finished.pop_front();
  detect_fps_ = double(w.finished.size());
  ++frames_;
  publish(std::move(f));
}

void Engine::State::run_scene(Frame& f, double now) {
  Worker& w = *worker_;
  if (!w.stage) w.stage = std::make_unique<SceneStage>(media::StoreMode::live);
  if (!w.stage->loaded()) {
    w.stage->run(f, now);
    return;
  }
  const uint64_t before = w.stage->status().generation;
  const std::string before_error = w.stage->status().error;
  w.stage->run(f, now);
  // Reloads after an edit on disk are news for the log too.
  const SceneStatus& st = f.scene;
  if (st.generation != before && before != 0) log_(0, "scene reloaded: " + st.file);
  if (!st.error.empty() && st.error != before_error) log_(2, st.error);
  // Runtime errors (callbacks, text functions, media that cannot be loaded), each text once per load.
  for (const std::string& e : w.stage->take_errors()) log_(2, e);
}

// The peers asked for, on the first dictionary: each one's markers matched to arwb's, or why it could not run.
void Engine::State::run_peers(Frame& f) {
  Worker& w = *worker_;
  const std::string& dict = w.config.dictionaries.empty() ? std::string("ARUCO_ORIGINAL") : w.config.dictionaries[0];
  if (w.peers_dict != dict) {
    w.opencv.reset();
    w.apriltag.reset();
    w.peers_dict = dict;
  }
  auto run_peer = [&](const char* name, auto&& detect) {
    PeerDetections pd;
    pd.name = name;
    pd.dict = dict;
    try {
      PeerResult r = detect();
      pd.markers = std::move(r.markers);
      pd.ms = r.ms;
      match_with_arwb(f.trace.markers, pd);
    } catch (const std::exception& e) {
      pd.error = one_line_reason(e);
    }
    f.peers.push_back(std::move(pd));
  };
  if (w.peer_opencv) {
    run_peer("opencv_aruco", [&] {
      try {
        if (!w.opencv) w.opencv = std::make_unique<OpenCvArucoPeer>(dict);
      } catch (const std::exception& e) {
        throw std::runtime_error("OpenCV aruco cannot read " + dict + ": " + one_line_reason(e));
      }
      return w.opencv->detect(f.image);
    });
  }
  if (w.peer_apriltag) {
    run_peer("apriltag", [&] {
      if (!AprilTagPeer::supports(dict))
        throw std::runtime_error("AprilTag reads only the APRILTAG_* families, not " + dict);
      if (!w.apriltag) w.apriltag = std::make_unique<AprilTagPeer>(dict);
      return w.apriltag->detect(f.image);
    });
  }
}

void Engine::State::publish(std::shared_ptr<Frame> f) {
  {
    std::lock_guard lock(mutex_);
    latest_ = std::move(f);
  }
  published_.notify_all();
}

// [SECTION] 4. Idle

void Engine::State::idle() {
  Worker& w = *worker_;
  const double wait = std::clamp(w.next_due - seconds_since(w.t0), 0.001, 0.02);
  std::unique_lock lock(mutex_);
  published_.wait_for(lock, std::chrono::duration<double>(wait), [&] { return !running_ || pending_->any(); });
  const double idle_since = seconds_since(w.t0);
  while (!w.finished.empty() && w.finished.front() < idle_since - 1.0) w.finished.pop_front();
  detect_fps_ = double(w.finished.size());
}

}  // namespace arwb
