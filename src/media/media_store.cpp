#include "media/media_store.hpp"

#include "capture/image_io.hpp"
#include "media/media_path.hpp"

#include <cairo.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include <algorithm>
#include <atomic>
#include <system_error>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <numbers>
#include <thread>
#include <utility>
#include <vector>

namespace arwb::media {

namespace {

using Clock = std::chrono::steady_clock;

// Every picture any content here publishes takes the next number: versions grow within a content and are never
// shared between contents, so a texture cache keyed by a content's address cannot take a new content allocated
// at a recycled address (a new card, a new player) for the old one.
std::atomic<uint64_t> g_versions{0};
uint64_t next_version() { return ++g_versions; }

class StillContent final : public MediaContent {
 public:
  explicit StillContent(cv::Mat pixels)
      : pixels_(std::make_shared<const cv::Mat>(std::move(pixels))), version_(next_version()) {}
  cv::Size size() const override { return pixels_->size(); }
  std::shared_ptr<const cv::Mat> current(uint64_t* version) const override {
    if (version) *version = version_;
    return pixels_;
  }
  size_t bytes() const { return pixels_->total() * pixels_->elemSize(); }

 private:
  std::shared_ptr<const cv::Mat> pixels_;
  uint64_t version_;
};

// Any decoded picture as 8-bit BGR, or BGRA when it has alpha (grey -> BGR, 16-bit and float -> 8-bit).
cv::Mat to_bgr8(const cv::Mat& in) {
  cv::Mat m = in;
  if (m.depth() != CV_8U) {
    double scale = 1.0;
    if (m.depth() == CV_16U) scale = 1.0 / 257.0;
    else if (m.depth() == CV_32F || m.depth() == CV_64F) scale = 255.0;  // float images are 0..1
    cv::Mat eight;
    m.convertTo(eight, CV_8U, scale);
    m = eight;
  }
  cv::Mat out;
  switch (m.channels()) {
    case 1: cv::cvtColor(m, out, cv::COLOR_GRAY2BGR); break;
    case 2: {  // grey and alpha
      std::vector<cv::Mat> ga;
      cv::split(m, ga);
      cv::merge(std::vector<cv::Mat>{ga[0], ga[0], ga[0], ga[1]}, out);
      break;
    }
    case 3:
    case 4: out = m; break;
    default: {  // more channels than any format here gives: keep the first three
      std::vector<cv::Mat> ch;
      cv::split(m, ch);
      cv::merge(std::vector<cv::Mat>{ch[0], ch[1], ch[2]}, out);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// Video

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
  VideoPlayer(std::string path, bool loop, StoreMode mode) : path_(std::move(path)), loop_(loop), mode_(mode) {}

  bool open_capture();
  long long target_index(Clock::time_point now) const;  // m_ held
  double position(Clock::time_point now) const;         // m_ held; unwrapped seconds
  bool holding_at_end(Clock::time_point now) const;     // m_ held
  bool slightly_behind(long long target) const;         // m_ held
  Clock::time_point next_frame_due(Clock::time_point now) const;  // m_ held
  void step(long long target);
  void seek(long long target);
  void reached_end(long long index);
  void fail(const std::string& reason);
  void publish(cv::Mat frame, long long index);
  cv::Mat normalise(cv::Mat frame) const;
  void run();

  // Fixed once open() returns.
  const std::string path_;
  const bool loop_;
  const StoreMode mode_;
  double fps_ = 25;
  cv::Size size_;
  long long seek_ahead_ = 50;  // frames ahead beyond which seeking beats decoding every frame
  long long jitter_ = 2;       // frames the clock may fall back while playing without a seek

  // The decoder's own state: touched only by the player thread (live) or under decode_mutex_ (offline).
  cv::VideoCapture cap_;
  long long next_index_ = 0;  // index of the frame the next grab returns
  int skipped_ = 0;           // frames grabbed without being shown since the last shown one
  bool seek_ok_ = true;       // the backend accepted CAP_PROP_POS_FRAMES so far
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
  const auto failed = [&](const std::string& reason) -> std::shared_ptr<VideoPlayer> {
    if (error) *error = path + ": " + reason;
    return nullptr;
  };
  std::shared_ptr<VideoPlayer> p(new VideoPlayer(path, loop, mode));
  if (!p->open_capture()) return failed("cannot open the video");

  const double fps = p->cap_.get(cv::CAP_PROP_FPS);
  // Containers sometimes report a time base (90000) or nothing as their rate.
  if (std::isfinite(fps) && fps >= 1 && fps <= 500) p->fps_ = fps;
  p->seek_ahead_ = std::max<long long>(50, std::llround(2 * p->fps_));
  p->jitter_ = std::max<long long>(2, std::llround(0.25 * p->fps_));
  const double w = p->cap_.get(cv::CAP_PROP_FRAME_WIDTH), h = p->cap_.get(cv::CAP_PROP_FRAME_HEIGHT);
  const auto too_large = [](double fw, double fh) -> std::string {
    const std::string size = std::to_string(std::llround(fw)) + "x" + std::to_string(std::llround(fh)) + " pixels, ";
    if (fw * fh > static_cast<double>(kMaxMediaPixels)) return size + "more than " + std::to_string(kMaxMediaPixels);
    if (fw > kMaxImageSide || fh > kMaxImageSide) return size + "a side longer than " + std::to_string(kMaxImageSide);
    return {};
  };
  // Refused before any frame is decoded, as an image is by its header.
  if (std::isfinite(w) && std::isfinite(h))
    if (std::string reason = too_large(w, h); !reason.empty()) return failed("frames of " + reason);
  const double count = p->cap_.get(cv::CAP_PROP_FRAME_COUNT);
  if (std::isfinite(count) && count >= 1 && count < 1e9) p->frame_count_ = std::llround(count);

  // The first frame, decoded now: it proves the video has frames and gives the size when the properties do not.
  cv::Mat first;
  bool ok = false;
  try {
    ok = p->cap_.read(first) && !first.empty();
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) return failed("has no frames that can be decoded");
  if (std::string reason = too_large(first.cols, first.rows); !reason.empty()) return failed("frames of " + reason);
  p->size_ = first.size();
  p->decoded_ = 1;
  p->next_index_ = 1;
  p->publish(p->normalise(std::move(first)), 0);
  if (mode == StoreMode::live) {
    try {
      p->thread_ = std::thread([raw = p.get()] { raw->run(); });
    } catch (const std::system_error&) {
      return failed("cannot start a decoding thread");
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

bool VideoPlayer::open_capture() {
  // FFmpeg first: it seeks by frame and reads every container here. Then the other backends that read files,
  // by name: CAP_ANY would also try camera backends (gphoto2 scans the USB bus) and CAP_IMAGES (one still).
  for (const cv::VideoCaptureAPIs api : {cv::CAP_FFMPEG, cv::CAP_GSTREAMER, cv::CAP_OPENCV_MJPEG}) {
    if (!cv::videoio_registry::hasBackend(api)) continue;
    try {
      if (cap_.open(path_, api) && cap_.isOpened()) return true;
    } catch (const cv::Exception&) {
    }
  }
  return false;
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
  if (target < next_index_ || (seek_ok_ && target - next_index_ > seek_ahead_)) {
    seek(target);
    return;
  }
  // Live playback that falls behind still shows some frames; offline, only the asked one matters.
  const bool show = target == next_index_ || (mode_ == StoreMode::live && skipped_ >= kMaxSkipped);
  cv::Mat frame;
  bool ok = false;
  try {
    ok = show ? cap_.read(frame) && !frame.empty() : cap_.grab();
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) {
    reached_end(next_index_);
    return;
  }
  ++decoded_;
  const long long index = next_index_++;
  if (!show) {
    ++skipped_;
    return;
  }
  skipped_ = 0;
  publish(normalise(std::move(frame)), index);
}

void VideoPlayer::seek(long long target) {
  skipped_ = 0;
  if (target > 0 && seek_ok_) {
    bool ok = false;
    try {
      ok = cap_.set(cv::CAP_PROP_POS_FRAMES, static_cast<double>(target));
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (ok) {
      next_index_ = target;
      return;
    }
    seek_ok_ = false;  // from now on: reopen and decode forward
  }
  if (target >= next_index_) return;  // forward without seeking: step decodes up to it
  cap_.release();
  if (!open_capture()) {
    fail(path_ + ": cannot reopen the video");
    return;
  }
  next_index_ = 0;
}

// Decoding failed at frame `index`: the end of the video, or a damaged file when the container promised more.
void VideoPlayer::reached_end(long long index) {
  if (index == 0) {
    fail(path_ + ": cannot decode the first frame any more");
    return;
  }
  std::lock_guard lock(m_);
  // One frame of slack: containers often count one frame more than they hold.
  if (frame_count_ > 0 && index + 1 < frame_count_ && error_.empty())
    error_ = path_ + ": cannot decode frame " + std::to_string(index) + " of " + std::to_string(frame_count_) +
             " (damaged or truncated file); the video ends at frame " + std::to_string(index - 1);
  if (frame_count_ == 0 || index < frame_count_) frame_count_ = index;
  next_index_ = index;
}

void VideoPlayer::fail(const std::string& reason) {
  std::lock_guard lock(m_);
  if (error_.empty()) error_ = reason;
  dead_ = true;
}

cv::Mat VideoPlayer::normalise(cv::Mat frame) const {
  if (!frame.u) frame = frame.clone();  // a backend's own buffer would be overwritten by the next frame
  if (frame.depth() != CV_8U || frame.channels() != 3) {
    cv::Mat bgr = to_bgr8(frame);
    if (bgr.channels() == 4) cv::cvtColor(bgr, bgr, cv::COLOR_BGRA2BGR);
    frame = bgr;
  }
  // A stream that changes resolution midway keeps the size the consumer was told.
  if (frame.size() != size_) cv::resize(frame, frame, size_, 0, 0, cv::INTER_AREA);
  return frame;
}

void VideoPlayer::publish(cv::Mat frame, long long index) {
  auto shared = std::make_shared<const cv::Mat>(std::move(frame));
  std::lock_guard lock(m_);
  frame_ = std::move(shared);
  shown_index_ = index;
  version_ = next_version();
}

// ---------------------------------------------------------------------------------------------------------------
// Cards

// Valid UTF-8 with U+FFFD for invalid bytes; tabs as spaces; other control characters dropped, except '\n'.
std::string clean_text(std::string_view in) {
  std::string out;
  out.reserve(in.size());
  size_t i = 0;
  while (i < in.size()) {
    const auto c = static_cast<unsigned char>(in[i]);
    if (c < 0x80) {
      if (c == '\n') out += '\n';
      else if (c == '\t') out += "    ";
      else if (c >= 0x20 && c != 0x7f) out += static_cast<char>(c);
      ++i;
      continue;
    }
    size_t len = 0;
    uint32_t cp = 0;
    if (c >= 0xC2 && c <= 0xDF) len = 2, cp = c & 0x1Fu;
    else if (c >= 0xE0 && c <= 0xEF) len = 3, cp = c & 0x0Fu;
    else if (c >= 0xF0 && c <= 0xF4) len = 4, cp = c & 0x07u;
    bool valid = len > 0 && i + len <= in.size();
    for (size_t k = 1; valid && k < len; ++k) {
      const auto cc = static_cast<unsigned char>(in[i + k]);
      valid = (cc & 0xC0) == 0x80;
      cp = cp << 6 | (cc & 0x3Fu);
    }
    // Overlong forms, surrogates and code points past U+10FFFF are invalid too.
    if (valid && ((len == 3 && cp < 0x800) || (len == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ||
                  (cp >= 0xD800 && cp <= 0xDFFF)))
      valid = false;
    if (!valid) {
      out += "\uFFFD";
      ++i;
      continue;
    }
    if (!(cp >= 0x80 && cp <= 0x9F)) out.append(in.substr(i, len));  // C1 controls dropped
    i += len;
  }
  return out;
}

// The longest prefix of valid UTF-8 `s` of at most `bytes` bytes that ends on a character boundary.
size_t utf8_prefix(std::string_view s, size_t bytes) {
  if (bytes >= s.size()) return s.size();
  while (bytes > 0 && (static_cast<unsigned char>(s[bytes]) & 0xC0) == 0x80) --bytes;
  return bytes;
}

constexpr std::string_view kEllipsis = "\u2026";
constexpr double kPi = std::numbers::pi;

// RAII for a cairo image surface and its context.
class Canvas {
 public:
  Canvas(int width, int height)
      : surface_(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height)), cr_(cairo_create(surface_)) {}
  ~Canvas() {
    cairo_destroy(cr_);
    cairo_surface_destroy(surface_);
  }
  Canvas(const Canvas&) = delete;
  Canvas& operator=(const Canvas&) = delete;
  cairo_t* cr() const { return cr_; }
  bool ok() const {
    return cairo_surface_status(surface_) == CAIRO_STATUS_SUCCESS && cairo_status(cr_) == CAIRO_STATUS_SUCCESS;
  }

  // The pixels as BGRA with straight alpha. Cairo's ARGB32 is premultiplied, one native-endian 32-bit word a
  // pixel (alpha in the top byte), so it is read by words, whatever the byte order.
  cv::Mat to_bgra() const {
    if (!ok()) return cv::Mat(1, 1, CV_8UC4, cv::Scalar::all(0));  // out of memory: a transparent dot
    cairo_surface_flush(surface_);
    const int w = cairo_image_surface_get_width(surface_), h = cairo_image_surface_get_height(surface_);
    const int stride = cairo_image_surface_get_stride(surface_);
    const unsigned char* data = cairo_image_surface_get_data(surface_);
    cv::Mat out(h, w, CV_8UC4);
    for (int y = 0; y < h; ++y) {
      const auto* src = reinterpret_cast<const uint32_t*>(data + static_cast<ptrdiff_t>(y) * stride);
      auto* dst = out.ptr<cv::Vec4b>(y);
      for (int x = 0; x < w; ++x) {
        const uint32_t px = src[x];
        const uint32_t a = px >> 24;
        const auto un = [a](uint32_t c) {
          return static_cast<uchar>(a == 0 ? 0 : std::min(255u, (c * 255 + a / 2) / a));
        };
        dst[x] = cv::Vec4b(un(px & 0xFF), un(px >> 8 & 0xFF), un(px >> 16 & 0xFF), static_cast<uchar>(a));
      }
    }
    return out;
  }

 private:
  cairo_surface_t* surface_;
  cairo_t* cr_;
};

void set_font(cairo_t* cr, double px, bool bold = false) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, px);
}

double text_width(cairo_t* cr, const std::string& s) {
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  return std::max(e.x_advance, e.x_bearing + e.width);
}

// `s` if it fits in `max_width` with the current font (and no ellipsis is forced), else its longest prefix
// that fits followed by "…".
std::string fit(cairo_t* cr, const std::string& s, double max_width, bool force_ellipsis = false) {
  if (!force_ellipsis && text_width(cr, s) <= max_width) return s;
  std::vector<size_t> ends{0};  // byte offsets where a character ends
  for (size_t i = 1; i <= s.size(); ++i)
    if (i == s.size() || (static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) ends.push_back(i);
  const auto with_ellipsis = [&](size_t k) { return s.substr(0, ends[k]) + std::string(kEllipsis); };
  size_t lo = 0, hi = ends.size() - 1;  // the answer is in [lo, hi]; prefix 0 ("…" alone) is the fallback
  while (lo < hi) {
    const size_t mid = (lo + hi + 1) / 2;
    if (text_width(cr, with_ellipsis(mid)) <= max_width) lo = mid;
    else hi = mid - 1;
  }
  return with_ellipsis(lo);
}

void rounded_rect(cairo_t* cr, double x, double y, double w, double h, double r) {
  r = std::min({r, w / 2, h / 2});
  cairo_new_sub_path(cr);
  cairo_arc(cr, x + w - r, y + r, r, -kPi / 2, 0);
  cairo_arc(cr, x + w - r, y + h - r, r, 0, kPi / 2);
  cairo_arc(cr, x + r, y + h - r, r, kPi / 2, kPi);
  cairo_arc(cr, x + r, y + r, r, kPi, 3 * kPi / 2);
  cairo_close_path(cr);
}

double channel(double v) { return std::isfinite(v) ? std::clamp(v, 0.0, 255.0) / 255.0 : 1.0; }

void set_bgra(cairo_t* cr, const cv::Scalar& c) {
  cairo_set_source_rgba(cr, channel(c[2]), channel(c[1]), channel(c[0]), channel(c[3]));
}

cv::Mat draw_text_card(const MediaSpec& spec) {
  const double font_px = std::isfinite(spec.font_px) ? std::clamp(spec.font_px, 4.0, 512.0) : 32.0;
  std::string text = clean_text(spec.text);
  if (text.size() > MediaStore::kMaxCardText)
    text = text.substr(0, utf8_prefix(text, MediaStore::kMaxCardText)) + std::string(kEllipsis);

  std::vector<std::string> lines;
  for (size_t start = 0;;) {
    const size_t nl = text.find('\n', start);
    lines.push_back(text.substr(start, nl == std::string::npos ? std::string::npos : nl - start));
    if (nl == std::string::npos) break;
    start = nl + 1;
  }

  // Measure on a 1x1 surface, then draw on one of the measured size.
  Canvas probe(1, 1);
  set_font(probe.cr(), font_px);
  cairo_font_extents_t fe;
  cairo_font_extents(probe.cr(), &fe);
  const int pad = static_cast<int>(std::ceil(font_px * 0.35));
  const int line_h = std::max(1, static_cast<int>(std::ceil(fe.height)));
  const int max_text = MediaStore::kMaxCardSide - 2 * pad;
  const size_t max_lines = static_cast<size_t>(std::max(1, max_text / line_h));
  bool cut_lines = false;
  if (lines.size() > max_lines) {
    lines.resize(max_lines);
    cut_lines = true;
  }
  double widest = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    const bool last_cut = cut_lines && i + 1 == lines.size();
    lines[i] = fit(probe.cr(), lines[i], max_text, last_cut);
    widest = std::max(widest, text_width(probe.cr(), lines[i]));
  }
  const int width = std::min(MediaStore::kMaxCardSide, static_cast<int>(std::ceil(widest)) + 2 * pad);
  const int height = std::min(MediaStore::kMaxCardSide, static_cast<int>(lines.size()) * line_h + 2 * pad);

  Canvas canvas(std::max(1, width), std::max(1, height));
  cairo_t* cr = canvas.cr();
  if (spec.background[3] > 0) {
    rounded_rect(cr, 0, 0, width, height, font_px * 0.3);
    set_bgra(cr, spec.background);
    cairo_fill(cr);
  }
  set_font(cr, font_px);
  set_bgra(cr, spec.colour);
  for (size_t i = 0; i < lines.size(); ++i) {
    cairo_move_to(cr, pad, pad + static_cast<double>(i) * line_h + fe.ascent);
    cairo_show_text(cr, lines[i].c_str());
  }
  return canvas.to_bgra();
}

cv::Mat draw_web_card(const MediaSpec& spec) {
  constexpr int W = MediaStore::kWebCardWidth, H = MediaStore::kWebCardHeight;
  Canvas canvas(W, H);
  cairo_t* cr = canvas.cr();
  rounded_rect(cr, 1, 1, W - 2, H - 2, 16);
  cairo_set_source_rgba(cr, 0.13, 0.14, 0.16, 0.92);
  cairo_fill_preserve(cr);
  cairo_set_source_rgba(cr, 0.35, 0.6, 0.95, 1.0);
  cairo_set_line_width(cr, 2);
  cairo_stroke(cr);

  // The globe: an outline, two meridians and three parallels.
  const double cx = 100, cy = H / 2.0, r = 62;
  cairo_set_line_width(cr, 4);
  cairo_set_source_rgba(cr, 0.55, 0.8, 1.0, 1.0);
  cairo_arc(cr, cx, cy, r, 0, 2 * kPi);
  cairo_stroke(cr);
  cairo_set_line_width(cr, 3);
  cairo_save(cr);
  cairo_translate(cr, cx, cy);
  cairo_scale(cr, 0.45, 1.0);
  cairo_arc(cr, 0, 0, r, 0, 2 * kPi);
  cairo_restore(cr);
  cairo_stroke(cr);
  cairo_move_to(cr, cx, cy - r);
  cairo_line_to(cr, cx, cy + r);
  for (const double dy : {-r / 2, 0.0, r / 2}) {
    const double half = std::sqrt(r * r - dy * dy);
    cairo_move_to(cr, cx - half, cy + dy);
    cairo_line_to(cr, cx + half, cy + dy);
  }
  cairo_stroke(cr);

  std::string title = clean_text(spec.title.substr(0, MediaStore::kMaxCardText));
  if (title.find_first_not_of(" \n") == std::string::npos) title = url_host(spec.url);
  if (title.empty()) title = clean_text(spec.url.substr(0, MediaStore::kMaxCardText));
  if (title.empty()) title = "(no link)";
  std::replace(title.begin(), title.end(), '\n', ' ');
  std::string url = clean_text(spec.url.substr(0, MediaStore::kMaxCardText));
  std::replace(url.begin(), url.end(), '\n', ' ');

  const double x = 190, max_w = W - x - 24;
  set_font(cr, 34, true);
  cairo_set_source_rgba(cr, 1, 1, 1, 1);
  cairo_move_to(cr, x, 82);
  cairo_show_text(cr, fit(cr, title, max_w).c_str());
  set_font(cr, 18);
  cairo_set_source_rgba(cr, 0.78, 0.8, 0.84, 1);
  cairo_move_to(cr, x, 122);
  cairo_show_text(cr, fit(cr, url, max_w).c_str());
  set_font(cr, 15);
  cairo_set_source_rgba(cr, 0.45, 0.7, 1.0, 1);
  cairo_move_to(cr, x, 164);
  cairo_show_text(cr, "click to open");
  return canvas.to_bgra();
}

// Exact, so two styles that differ in the last bit are different cards.
std::string key_number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

size_t card_bytes(const MediaContent& card) {
  const cv::Size s = card.size();
  return static_cast<size_t>(s.area()) * 4;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// MediaStore

MediaStore::MediaStore(StoreMode mode) : mode_(mode) {}
MediaStore::~MediaStore() = default;

std::shared_ptr<MediaContent> MediaStore::image(const std::string& path, std::string* error) {
  {
    std::lock_guard lock(mutex_);
    if (auto it = images_.find(path); it != images_.end())
      if (std::shared_ptr<MediaContent> held = it->second.lock()) {
        if (error) error->clear();
        return held;
      }
  }
  // Decoded without the lock: a large image must not stall the cards.
  LoadedImage loaded = load_image(path, cv::IMREAD_UNCHANGED, kMaxMediaPixels);
  if (!loaded.ok()) {
    if (error) *error = loaded.error;
    return nullptr;
  }
  std::shared_ptr<MediaContent> content = std::make_shared<StillContent>(to_bgr8(loaded.image));
  std::lock_guard lock(mutex_);
  std::weak_ptr<MediaContent>& slot = images_[path];
  if (std::shared_ptr<MediaContent> raced = slot.lock()) content = std::move(raced);  // decoded twice: keep one
  else slot = content;
  if (error) error->clear();
  return content;
}

std::shared_ptr<VideoContent> MediaStore::video(const std::string& path, bool loop, std::string* error) {
  return VideoPlayer::open(path, loop, mode_, error);
}

std::shared_ptr<MediaContent> MediaStore::text_card(const MediaSpec& spec) {
  std::string key = "text\x1f";
  key += key_number(spec.font_px);
  for (int i = 0; i < 4; ++i) {
    key += ',';
    key += key_number(spec.colour[i]);
    key += ',';
    key += key_number(spec.background[i]);
  }
  key += '\x1f';
  key += spec.text;
  if (auto card = cached_card(key)) return card;
  return remember_card(key, std::make_shared<StillContent>(draw_text_card(spec)));
}

std::shared_ptr<MediaContent> MediaStore::web_card(const MediaSpec& spec) {
  const std::string key = "web\x1f" + spec.title + "\x1f" + spec.url;
  if (auto card = cached_card(key)) return card;
  return remember_card(key, std::make_shared<StillContent>(draw_web_card(spec)));
}

std::shared_ptr<MediaContent> MediaStore::cached_card(const std::string& key) {
  std::lock_guard lock(mutex_);
  auto it = cards_.find(key);
  if (it == cards_.end()) return nullptr;
  // Most recently asked for goes last, so a card shown every frame is never the one dropped.
  if (card_order_.back() != key) {
    card_order_.remove(key);
    card_order_.push_back(key);
  }
  return it->second;
}

std::shared_ptr<MediaContent> MediaStore::remember_card(const std::string& key, std::shared_ptr<MediaContent> card) {
  std::lock_guard lock(mutex_);
  auto [it, inserted] = cards_.try_emplace(key, card);
  if (!inserted) return it->second;  // drawn by another thread meanwhile
  card_order_.push_back(key);
  card_bytes_ += card_bytes(*card);
  evict_cards();
  return card;
}

void MediaStore::evict_cards() {
  const auto over = [&] { return cards_.size() > kMaxCards || card_bytes_ > kMaxCardBytes; };
  // First the least recently asked for that no one holds, then, if still over, the least recently asked for.
  for (int pass = 0; pass < 2 && over(); ++pass) {
    for (auto key = card_order_.begin(); key != card_order_.end() && over();) {
      auto it = cards_.find(*key);
      if (pass == 0 && it->second.use_count() > 1) {
        ++key;
        continue;
      }
      card_bytes_ -= card_bytes(*it->second);
      cards_.erase(it);
      key = card_order_.erase(key);
    }
  }
}

void MediaStore::trim() {
  std::lock_guard lock(mutex_);
  std::erase_if(images_, [](const auto& entry) { return entry.second.expired(); });
  for (auto key = card_order_.begin(); key != card_order_.end();) {
    auto it = cards_.find(*key);
    if (it->second.use_count() > 1) {
      ++key;
      continue;
    }
    card_bytes_ -= card_bytes(*it->second);
    cards_.erase(it);
    key = card_order_.erase(key);
  }
}

}  // namespace arwb::media
