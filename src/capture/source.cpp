#include "capture/source.hpp"

#include "capture/image_io.hpp"
#include "capture/opencv_error.hpp"
#include "capture/pixels.hpp"
#include "capture/video_reader.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <optional>

namespace arwb {

namespace {

std::string file_name(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  if (name.empty()) name = std::filesystem::path(path).parent_path().filename().string();  // "dir/"
  return name.empty() ? path : name;
}

// Speeds outside 0.1 .. 8 (and NaN) are not playback speeds.
Playback clamped(Playback p) {
  p.speed = std::isfinite(p.speed) ? std::clamp(p.speed, 0.1, 8.0) : 1.0;
  return p;
}

bool parse_int(std::string_view s, int* v) {
  if (s.empty()) return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), *v);
  return ec == std::errc() && end == s.data() + s.size();
}

// [SECTION] camera

class CameraSource : public FrameSource {
 public:
  CameraSource(int device, cv::VideoCapture cap) : device_(device), cap_(std::move(cap)) {}
  SourceStatus next(double, cv::Mat& out) override {
    if (gone_) return {FrameStatus::gone, name() + ": no frame (unplugged?)"};
    try {
      if (cap_.read(frame_) && !frame_.empty()) {
        to_bgr8(frame_).copyTo(out);  // copied: the next read decodes into frame_
        size_ = out.size();
        return {};
      }
    } catch (const std::exception&) {
    }
    gone_ = true;
    cap_.release();
    return {FrameStatus::gone, name() + ": no frame (unplugged?)"};
  }
  SourceInfo info() const override {
    SourceInfo i;
    i.kind = SourceKind::camera;
    i.name = name();
    i.size = size_;
    i.native_fps = fps_;
    return i;
  }
  void set_nominal(cv::Size size, double fps) { size_ = size, fps_ = fps; }

 private:
  std::string name() const { return "camera:" + std::to_string(device_); }
  int device_;
  cv::VideoCapture cap_;
  cv::Mat frame_;
  cv::Size size_{};
  double fps_ = 0;
  bool gone_ = false;
};

// [SECTION] video

// Plays in the caller's time: a fractional frame clock advances by elapsed time x fps x speed, and each call
// shows the frame under the clock, skipping past the ones in between. So a caller slower than the video skips
// frames instead of slowing it down.
class VideoSource : public FrameSource {
 public:
  VideoSource(VideoReader reader, cv::Mat first)
      : name_(file_name(reader.path())), reader_(std::move(reader)), frame_(std::move(first)) {}

  SourceStatus next(double now_s, cv::Mat& out) override {
    try {
      return advance(now_s, out);
    } catch (const std::exception& e) {
      return {FrameStatus::error, name_ + ": frame " + std::to_string(pos_ + 1) + ": " + one_line_reason(e)};
    }
  }

  SourceInfo info() const override {
    SourceInfo i;
    i.kind = SourceKind::video;
    i.name = name_;
    i.size = reader_.size();
    i.native_fps = reader_.fps();
    i.position = pos_;
    i.count = int(reader_.frame_count());
    return i;
  }

  void set_playback(const Playback& p) override {
    if (p.playing && !pb_.playing) have_last_ = false;   // a pause ends where it began: its time is not played
    pb_ = clamped(p);
  }
  void step(int delta) override {
    pb_.playing = false;
    want_ = std::max(0, want_.value_or(pos_) + delta);
  }
  void seek(int position) override { want_ = std::max(0, position); }

 private:
  double rate() const { return (reader_.fps() > 0 ? reader_.fps() : 25.0) * pb_.speed; }

  SourceStatus advance(double now_s, cv::Mat& out) {
    const double dt = have_last_ && std::isfinite(now_s) ? std::max(0.0, now_s - last_now_) : 0.0;
    if (std::isfinite(now_s)) last_now_ = now_s, have_last_ = true;
    if (!shown_) {  // the first frame, read when opening
      shown_ = true;
      frame_.copyTo(out);
      return {};
    }
    if (want_) {  // a step or seek: show that frame, and play on from it if playing
      int target = *want_;
      want_.reset();
      const int64_t count = reader_.frame_count();
      if (count > 0 && target >= count) {  // past the end: wrap when looping
        if (!pb_.loop) return {FrameStatus::end, {}};
        target = 0;
      }
      const SourceStatus s = go_to(target, out);
      clock_ = pos_;
      return s;
    }
    if (!pb_.playing) return {FrameStatus::same, {}};
    if (at_end_) {
      if (!pb_.loop) return {FrameStatus::end, {}};
      at_end_ = false;
      clock_ = 0;
      return go_to(0, out);
    }
    clock_ += dt * rate();
    const int target = int(std::floor(clock_ + 1e-6));   // a frame due exactly now is shown despite rounding
    if (target <= pos_) return {FrameStatus::same, {}};
    return go_to(target, out);
  }

  // Shows frame `target`: read on when it is ahead (seek when far ahead), seek back otherwise. On failure the
  // frame shown stays the last good one.
  SourceStatus go_to(int target, cv::Mat& out) {
    if (target == pos_) {
      frame_.copyTo(out);
      return {};
    }
    if (target < reader_.next_index() || target - reader_.next_index() > 64)
      if (!reader_.seek(target)) return {FrameStatus::gone, reader_.error()};
    while (reader_.next_index() < target)  // skipping decodes less than reading; these frames are not shown
      if (const VideoReader::Read r = reader_.read(nullptr); r != VideoReader::Read::frame) return ended(r);
    if (const VideoReader::Read r = reader_.read(&frame_); r != VideoReader::Read::frame) return ended(r);
    pos_ = target;
    at_end_ = false;
    frame_.copyTo(out);
    return {};
  }

  // No frame where one was asked for: the end of the video, or (reported once) a truncated or corrupt file that
  // ends there from now on, or a file that can no longer be read at all.
  SourceStatus ended(VideoReader::Read r) {
    at_end_ = true;
    clock_ = pos_;
    if (reader_.next_index() == 0) return {FrameStatus::gone, reader_.error()};
    if (r == VideoReader::Read::damaged) return {FrameStatus::error, reader_.error()};
    if (pb_.loop && pb_.playing) return {FrameStatus::same, {}};   // wraps on the next call
    return {FrameStatus::end, {}};
  }

  std::string name_;
  VideoReader reader_;
  cv::Mat frame_;             // the frame shown, index pos_
  int pos_ = 0;
  std::optional<int> want_;   // a step or seek to do on the next call
  double clock_ = 0, last_now_ = 0;
  bool have_last_ = false, shown_ = false, at_end_ = false;
  Playback pb_;
};

// [SECTION] image

class ImageSource : public FrameSource {
 public:
  ImageSource(std::string path, cv::Mat image) : name_(file_name(path)), image_(std::move(image)) {}
  SourceStatus next(double, cv::Mat& out) override {
    if (shown_) return {FrameStatus::same, {}};
    shown_ = true;
    image_.copyTo(out);
    return {};
  }
  SourceInfo info() const override {
    SourceInfo i;
    i.kind = SourceKind::image;
    i.name = name_;
    i.size = image_.size();
    i.count = 1;
    return i;
  }

 private:
  std::string name_;
  cv::Mat image_;
  bool shown_ = false;
};

// [SECTION] folder

// One image at a time; step moves by images, and while playing it moves on by one image a second (times speed).
class FolderSource : public FrameSource {
 public:
  FolderSource(std::string folder, std::vector<std::string> files)
      : folder_(std::move(folder)), name_(file_name(folder_)), files_(std::move(files)) {}

  SourceStatus next(double now_s, cv::Mat& out) override {
    try {
      return advance(now_s, out);
    } catch (const std::exception& e) {
      return {FrameStatus::error, files_[size_t(pos_)] + ": " + one_line_reason(e)};
    }
  }
  SourceInfo info() const override {
    SourceInfo i;
    i.kind = SourceKind::folder;
    i.name = name_;
    i.size = size_;
    i.position = pos_;
    i.count = int(files_.size());
    i.item = file_name(files_[size_t(pos_)]);
    return i;
  }
  void set_playback(const Playback& p) override {
    if (p.playing && !pb_.playing) have_last_ = false;   // a pause ends where it began: its time is not played
    pb_ = clamped(p);
  }
  void step(int delta) override { want_ = want_.value_or(pos_) + delta; }
  void seek(int position) override { want_ = std::clamp(position, 0, int(files_.size()) - 1); }

 private:
  SourceStatus advance(double now_s, cv::Mat& out) {
    const double dt = have_last_ && std::isfinite(now_s) ? std::max(0.0, now_s - last_now_) : 0.0;
    if (std::isfinite(now_s)) last_now_ = now_s, have_last_ = true;
    const int n = int(files_.size());
    if (!shown_) {
      shown_ = true;
      return show(pos_, out);
    }
    if (want_) {  // step or seek; stepping past either end wraps only when looping
      int target = *want_;
      want_.reset();
      if (target >= n || target < 0) {
        if (!pb_.loop) {
          if (target >= n) return {FrameStatus::end, {}};
          target = 0;
        } else {
          target = ((target % n) + n) % n;
        }
      }
      elapsed_ = 0;
      return show(target, out);
    }
    if (!pb_.playing) return {FrameStatus::same, {}};
    elapsed_ += dt * pb_.speed;
    if (elapsed_ < 1.0) return {FrameStatus::same, {}};
    elapsed_ = 0;
    if (pos_ + 1 >= n && !pb_.loop) return {FrameStatus::end, {}};
    return show((pos_ + 1) % n, out);
  }

  SourceStatus show(int index, cv::Mat& out) {
    pos_ = index;
    const std::string& path = files_[size_t(index)];
    if (classify_path(folder_) != PathKind::folder) return {FrameStatus::gone, folder_ + ": folder is gone"};
    LoadedImage img = load_image(path);
    if (!img.ok()) return {FrameStatus::error, img.error};
    to_bgr8(img.image).copyTo(out);
    size_ = out.size();
    return {};
  }

  std::string folder_, name_;
  std::vector<std::string> files_;
  int pos_ = 0;
  std::optional<int> want_;   // a step or seek to do on the next call
  double elapsed_ = 0, last_now_ = 0;
  bool have_last_ = false, shown_ = false;
  cv::Size size_{};
  Playback pb_;
};

std::unique_ptr<FrameSource> open_camera(const SourceSpec& spec, std::string* error) {
  const std::string name = "camera:" + std::to_string(spec.device);
  cv::VideoCapture cap;
  if (spec.device < 0 || !cap.open(spec.device, cv::CAP_V4L2) || !cap.isOpened()) {
    *error = name + ": cannot open /dev/video" + std::to_string(spec.device);
    return nullptr;
  }
  if (spec.resolution.width > 0 && spec.resolution.height > 0) {
    cap.set(cv::CAP_PROP_FRAME_WIDTH, spec.resolution.width);
    cap.set(cv::CAP_PROP_FRAME_HEIGHT, spec.resolution.height);
  }
  const cv::Size size(int(cap.get(cv::CAP_PROP_FRAME_WIDTH)), int(cap.get(cv::CAP_PROP_FRAME_HEIGHT)));
  const double fps = cap.get(cv::CAP_PROP_FPS);
  auto src = std::make_unique<CameraSource>(spec.device, std::move(cap));
  src->set_nominal(size, std::isfinite(fps) && fps > 0 && fps < 1000 ? fps : 0);
  return src;
}

std::unique_ptr<FrameSource> open_video(const SourceSpec& spec, std::string* error) {
  cv::Mat first;
  Result<VideoReader> reader = VideoReader::open(spec.path, &first);
  if (!reader) {
    *error = reader.error();
    return nullptr;
  }
  return std::make_unique<VideoSource>(std::move(*reader), std::move(first));
}
std::unique_ptr<FrameSource> open_image(const SourceSpec& spec, std::string* error) {
  LoadedImage img = load_image(spec.path);
  if (!img.ok()) {
    *error = img.error;
    return nullptr;
  }
  return std::make_unique<ImageSource>(spec.path, to_bgr8(img.image));
}

std::unique_ptr<FrameSource> open_folder(const SourceSpec& spec, std::string* error) {
  std::string err;
  std::vector<std::string> files = list_images(spec.path, nullptr, &err);
  if (!err.empty()) {
    *error = err;
    return nullptr;
  }
  if (files.empty()) {
    *error = spec.path + ": no images in the folder";
    return nullptr;
  }
  return std::make_unique<FolderSource>(spec.path, std::move(files));
}

}  // namespace

std::string_view source_kind_name(SourceKind k) {
  switch (k) {
    case SourceKind::synthetic: return "synthetic";
    case SourceKind::camera: return "camera";
    case SourceKind::video: return "video";
    case SourceKind::image: return "image";
    case SourceKind::folder: return "folder";
    case SourceKind::lab: return "lab";
  }
  return "unknown";
}

std::string SourceSpec::text() const {
  switch (kind) {
    case SourceKind::synthetic: return "synthetic";
    case SourceKind::camera: {
      // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string temporaries here.
      std::string s = "camera:";
      s += std::to_string(device);
      if (resolution.width > 0 && resolution.height > 0) {
        s += '@';
        s += std::to_string(resolution.width);
        s += 'x';
        s += std::to_string(resolution.height);
      }
      return s;
    }
    default: return path;
  }
}

bool parse_source_spec(const std::string& text, SourceSpec* out, std::string* error) {
  std::string ignored;
  if (!error) error = &ignored;
  try {
    SourceSpec spec;
    if (text.empty()) {
      *error = "empty source (expected synthetic, camera:N or a path)";
      return false;
    }
    if (text == "synthetic") {
      spec.kind = SourceKind::synthetic;
    } else if (text.rfind("camera:", 0) == 0) {
      // camera:N or camera:N@WxH
      std::string_view rest = std::string_view(text).substr(7);
      std::string_view dev = rest.substr(0, rest.find('@'));
      if (!parse_int(dev, &spec.device) || spec.device < 0) {
        *error = text + ": the camera must be a device number (camera:N or camera:N@WxH)";
        return false;
      }
      if (const size_t at = rest.find('@'); at != std::string_view::npos) {
        std::string_view res = rest.substr(at + 1);
        const size_t x = res.find('x');
        int w = 0, h = 0;
        if (x == std::string_view::npos || !parse_int(res.substr(0, x), &w) || !parse_int(res.substr(x + 1), &h) ||
            w <= 0 || h <= 0 || w > 16384 || h > 16384) {
          *error = text + ": the resolution must be WxH (camera:N@1280x720)";
          return false;
        }
        spec.resolution = {w, h};
      }
      spec.kind = SourceKind::camera;
    } else {
      spec.path = text;
      switch (classify_path(text)) {
        case PathKind::missing: *error = text + ": no such file or folder"; return false;
        case PathKind::other: *error = text + ": not a video, an image or a folder"; return false;
        case PathKind::video: spec.kind = SourceKind::video; break;
        case PathKind::image: spec.kind = SourceKind::image; break;
        case PathKind::folder: spec.kind = SourceKind::folder; break;
      }
    }
    if (out) *out = spec;
    return true;
  } catch (const std::exception& e) {
    *error = text + ": " + one_line_reason(e);
    return false;
  }
}

std::unique_ptr<FrameSource> open_capture_source(const SourceSpec& spec, std::string* error) {
  std::string ignored;
  if (!error) error = &ignored;
  error->clear();
  try {
    switch (spec.kind) {
      case SourceKind::synthetic: *error = "synthetic: opened by synth/synthetic_source.hpp, not by capture"; return nullptr;
      case SourceKind::camera: return open_camera(spec, error);
      case SourceKind::video: return open_video(spec, error);
      case SourceKind::image: return open_image(spec, error);
      case SourceKind::folder: return open_folder(spec, error);
      case SourceKind::lab: *error = spec.text() + ": a lab cell is opened from the Lab workspace"; return nullptr;
    }
    *error = spec.text() + ": unknown source kind";
  } catch (const std::exception& e) {
    *error = spec.text() + ": " + one_line_reason(e);
  } catch (...) {
    *error = spec.text() + ": cannot open";
  }
  return nullptr;
}

std::vector<int> list_cameras() {
  std::vector<int> devices;
  std::error_code ec;
  for (std::filesystem::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    int n = 0;
    if (name.rfind("video", 0) == 0 && parse_int(std::string_view(name).substr(5), &n)) devices.push_back(n);
  }
  std::sort(devices.begin(), devices.end());
  return devices;
}

bool parse_source_or_default(const std::string& text, SourceSpec* out, std::string* error) {
  if (!text.empty()) return parse_source_spec(text, out, error);
  const std::vector<int> cameras = list_cameras();
  return parse_source_spec(cameras.empty() ? "synthetic" : "camera:" + std::to_string(cameras.front()), out, error);
}

}  // namespace arwb
