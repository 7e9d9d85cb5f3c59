#include "media/video_player.hpp"

#include "capture/video_reader.hpp"
#include "media/contents.hpp"
#include "media/media_path.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <system_error>
#include <thread>
#include <utility>

namespace arwb::media {

namespace {

using Clock = std::chrono::steady_clock;

class VideoPlayer final : public VideoContent {
 public:
  static std::shared_ptr<VideoPlayer> open(const std::string& path, bool loop, StoreMode mode, std::string* error);
  VideoPlayer(const VideoPlayer&) = delete;
  VideoPlayer& operator=(const VideoPlayer&) = delete;
  ~VideoPlayer() override;

  cv::Size size() const override { return size_; }
  std::shared_ptr<const cv::Mat> current(uint64_t* version) const override;
  void set_clock(double position_s, bool playing) override;
  double duration_s() const override;
  double fps() const override { return fps_; }
  uint64_t frames_decoded() const override { return decoded_.load(); }
  std::string error() const override;

 private:
  VideoPlayer(VideoReader reader, bool loop, StoreMode mode) : loop_(loop), mode_(mode), reader_(std::move(reader)) {}

  long long target_index(Clock::time_point now) const;  // m_ held
  double position(Clock::time_point now) const;         // m_ held; unwrapped seconds
  bool holding_at_end(Clock::time_point now) const;     // m_ held
  bool slightly_behind(long long target) const;         // m_ held
  Clock::time_point next_frame_due(Clock::time_point now) const;  // m_ held
  void step(long long target);
  void seek(long long target);
  void reached_end(VideoReader::Read r);
  void fail(const std::string& reason);
  void publish(cv::Mat frame, long long index);
  void run();

  // Fixed once open() returns.
  const bool loop_;
  const StoreMode mode_;
  double fps_ = 25;
  cv::Size size_;
  long long seek_ahead_ = 50;  // frames ahead beyond which seeking beats decoding every frame
  long long jitter_ = 2;       // frames the clock may fall back while playing without a seek

  // The decoder's own state: touched only by the player thread (live) or under decode_mutex_ (offline).
  VideoReader reader_;
  int skipped_ = 0;           // frames skipped without being shown since the last shown one
  std::mutex decode_mutex_;

  // Shared state, under m_.
  mutable std::mutex m_;
  std::condition_variable cv_;
  double position_s_ = 0;
  bool playing_ = false;
  Clock::time_point set_at_ = Clock::now();
  uint64_t clock_generation_ = 0;
  bool stop_ = false;
  bool dead_ = false;               // cannot decode any more: the last frame holds
  long long frame_count_ = 0;       // 0 while unknown; shrinks to where decoding really ended
  std::shared_ptr<const cv::Mat> frame_;
  long long shown_index_ = -1;      // index of frame_
  uint64_t version_ = 0;
  std::string error_;
  std::atomic<uint64_t> decoded_{0};

  std::thread thread_;
};

constexpr int kMaxSkipped = 4;  // when behind, show at least every fifth frame

std::shared_ptr<VideoPlayer> VideoPlayer::open(const std::string& path, bool loop, StoreMode mode,
                                               std::string* error) {
  cv::Mat first;
  Result<VideoReader> reader = VideoReader::open(path, &first, kMaxMediaPixels);
  if (!reader) {
    if (error) *error = reader.error();
    return nullptr;
  }
  std::shared_ptr<VideoPlayer> p(new VideoPlayer(std::move(*reader), loop, mode));
  if (p->reader_.fps() > 0) p->fps_ = p->reader_.fps();
  p->seek_ahead_ = std::max<long long>(50, std::llround(2 * p->fps_));
  p->jitter_ = std::max<long long>(2, std::llround(0.25 * p->fps_));
  p->size_ = p->reader_.size();
  p->frame_count_ = p->reader_.frame_count();
  p->decoded_ = 1;
  p->publish(std::move(first), 0);
  if (mode == StoreMode::live) {
    try {
      p->thread_ = std::thread([raw = p.get()] { raw->run(); });
    } catch (const std::system_error&) {
      if (error) *error = path + ": cannot start a decoding thread";
      return nullptr;
    }
  }
  if (error) error->clear();
  return p;
}

VideoPlayer::~VideoPlayer() {
  {
    std::lock_guard lock(m_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

std::shared_ptr<const cv::Mat> VideoPlayer::current(uint64_t* version) const {
  std::lock_guard lock(m_);
  if (version) *version = version_;
  return frame_;
}

double VideoPlayer::duration_s() const {
  std::lock_guard lock(m_);
  return frame_count_ > 0 ? static_cast<double>(frame_count_) / fps_ : 0.0;
}

std::string VideoPlayer::error() const {
  std::lock_guard lock(m_);
  return error_;
}

double VideoPlayer::position(Clock::time_point now) const {
  double t = position_s_;
  if (mode_ == StoreMode::live && playing_) t += std::chrono::duration<double>(now - set_at_).count();
  // About 30 years: far enough for any scene, small enough that t * fps stays an exact integer range.
  return std::clamp(t, 0.0, 1e9);
}

long long VideoPlayer::target_index(Clock::time_point now) const {
  // The small epsilon makes k / fps land on frame k despite rounding.
  long long index = static_cast<long long>(std::floor(position(now) * fps_ + 1e-6));
  if (frame_count_ > 0) index = loop_ ? index % frame_count_ : std::min(index, frame_count_ - 1);
  return index;
}

bool VideoPlayer::holding_at_end(Clock::time_point now) const {
  if (frame_count_ == 1) return true;  // a single picture, looping or not
  return !loop_ && frame_count_ > 0 &&
         std::floor(position(now) * fps_ + 1e-6) >= static_cast<double>(frame_count_ - 1);
}

// The scene sets the clock every frame from its own time, which wobbles against the wall clock this player
// extrapolates with: a clock a frame or two behind the picture while playing is waited for, not sought back to
// (a seek per wobble would stutter). Looping, "behind" is counted around the end.
bool VideoPlayer::slightly_behind(long long target) const {
  if (shown_index_ < 0) return false;
  long long behind = shown_index_ - target;
  if (loop_ && frame_count_ > 0) behind = (behind % frame_count_ + frame_count_) % frame_count_;
  return behind > 0 && behind <= jitter_;
}

Clock::time_point VideoPlayer::next_frame_due(Clock::time_point now) const {
  const double p = position(now);
  const double boundary = (std::floor(p * fps_ + 1e-6) + 1) / fps_;
  // Half a millisecond late rather than early, so the wake-up finds the next frame due; never less than 1 ms.
  const double wait = std::clamp(boundary - p + 0.0005, 0.001, 1.0);
  return now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait));
}

void VideoPlayer::set_clock(double position_s, bool playing) {
  if (!std::isfinite(position_s) || position_s < 0) position_s = 0;
  if (mode_ == StoreMode::live) {
    {
      std::lock_guard lock(m_);
      position_s_ = position_s;
      playing_ = playing;
      set_at_ = Clock::now();
      ++clock_generation_;
    }
    cv_.notify_all();
    return;
  }
  // Offline: decode here, up to the frame due at position_s, before returning.
  std::lock_guard decode_lock(decode_mutex_);
  for (;;) {
    long long target = 0;
    {
      std::lock_guard lock(m_);
      position_s_ = position_s;
      playing_ = playing;
      if (dead_) return;
      target = target_index(Clock::now());
      if (target == shown_index_) return;
    }
    step(target);
  }
}

void VideoPlayer::run() {
  std::unique_lock lock(m_);
  while (!stop_) {
    if (dead_) {
      cv_.wait(lock, [&] { return stop_; });
      break;
    }
    const Clock::time_point now = Clock::now();
    const long long target = target_index(now);
    if (target != shown_index_ && !(playing_ && slightly_behind(target))) {
      lock.unlock();
      step(target);
      lock.lock();
      continue;
    }
    // Ahead of the clock: sleep until the next frame is due, or until the clock is set or the player goes.
    const uint64_t generation = clock_generation_;
    const auto woken = [&] { return stop_ || clock_generation_ != generation; };
    if (!playing_ || holding_at_end(now)) cv_.wait(lock, woken);
    else cv_.wait_until(lock, next_frame_due(now), woken);
  }
}

// One unit of work toward showing frame `target`: a seek, a frame decoded and skipped, or a frame shown.
void VideoPlayer::step(long long target) {
  const long long next = reader_.next_index();
  if (target < next || (reader_.can_seek() && target - next > seek_ahead_)) {
    seek(target);
    return;
  }
  // Live playback that falls behind still shows some frames; offline, only the asked one matters.
  const bool show = target == next || (mode_ == StoreMode::live && skipped_ >= kMaxSkipped);
  cv::Mat frame;
  if (const VideoReader::Read r = reader_.read(show ? &frame : nullptr); r != VideoReader::Read::frame) {
    reached_end(r);
    return;
  }
  ++decoded_;
  if (!show) {
    ++skipped_;
    return;
  }
  skipped_ = 0;
  publish(std::move(frame), next);
}

void VideoPlayer::seek(long long target) {
  skipped_ = 0;
  if (!reader_.seek(target)) fail(reader_.error());
}

// No frame where one was asked for: the end of the video, or a damaged file when the container promised more
// (the reader says so, and counts only what could be decoded).
void VideoPlayer::reached_end(VideoReader::Read r) {
  if (reader_.next_index() == 0) {  // not even the first frame any more
    fail(reader_.error());
    return;
  }
  std::lock_guard lock(m_);
  if (r == VideoReader::Read::damaged && error_.empty()) error_ = reader_.error();
  frame_count_ = reader_.frame_count();
}

void VideoPlayer::fail(const std::string& reason) {
  std::lock_guard lock(m_);
  if (error_.empty()) error_ = reason;
  dead_ = true;
}

void VideoPlayer::publish(cv::Mat frame, long long index) {
  auto shared = std::make_shared<const cv::Mat>(std::move(frame));
  std::lock_guard lock(m_);
  frame_ = std::move(shared);
  shown_index_ = index;
  version_ = next_version();
}

}  // namespace

std::shared_ptr<VideoContent> open_video_player(const std::string& path, bool loop, StoreMode mode,
                                                std::string* error) {
  return VideoPlayer::open(path, loop, mode, error);
}

}  // namespace arwb::media
