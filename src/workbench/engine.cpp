// The Engine the UI holds (engine.hpp): the worker's thread started and stopped, the latest frame handed over,
// and setters that only store a value for the worker to apply before its next frame (engine_worker.cpp).
#include "workbench/engine_state.hpp"

#include <chrono>
#include <cstdio>

namespace arwb {

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
      s_->log_(2, stuck_message(timeout_s));
      thread_.detach();
      return false;
    }
  }
  thread_.join();
  return true;
}

std::string Engine::stuck_message(double timeout_s) const {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", timeout_s);
  return std::string("the worker did not stop within ") + b + " s (it was " + s_->doing_.load() +
         "); quitting without it";
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
void Engine::set_stage_style(const StageViewStyle& style) { ARWB_SET(stage_style, style); }
void Engine::load_scene(const std::string& path) { ARWB_SET(scene_file, path); }
void Engine::set_calibrating(bool on) { ARWB_SET(calibrating, on); }
void Engine::set_calibration_board(const BoardSpec& board) { ARWB_SET(calibration_board, board); }
void Engine::set_calibration_capture(bool on) { ARWB_SET(calibration_capture, on); }
void Engine::reset_calibration() { ARWB_SET(calibration_reset, true); }
void Engine::load_calibration(const std::string& path) { ARWB_SET(calibration_file, path); }
void Engine::set_undistort(bool on) { ARWB_SET(undistort, on); }
void Engine::set_marker_size(double side) { ARWB_SET(marker_size, side); }
void Engine::set_recorder(std::shared_ptr<ClipRecorder> recorder) { ARWB_SET(recorder, std::move(recorder)); }
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
}  // namespace arwb
