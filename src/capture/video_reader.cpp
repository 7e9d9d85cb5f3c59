#include "capture/video_reader.hpp"

#include "base/files.hpp"
#include "capture/library_output.hpp"
#include "capture/pixels.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio/registry.hpp>

#include <algorithm>
#include <cmath>

namespace arwb {

namespace {

// "9000x9000 pixels, more than 40000000", or "" when a frame of that size is allowed.
std::string too_large(double w, double h, int64_t max_pixels) {
  const std::string size = std::to_string(std::llround(w)) + "x" + std::to_string(std::llround(h)) + " pixels, ";
  if (w * h > static_cast<double>(max_pixels)) return size + "more than " + std::to_string(max_pixels);
  if (w > kMaxImageSide || h > kMaxImageSide) return size + "a side longer than " + std::to_string(kMaxImageSide);
  return {};
}

bool is_avi_reader_line(std::string_view line) {
  for (std::string_view start : {"Unexpected element", "Unexpected list type", "Unexpected end of file",
                                 "Failed to parse avi", "Failed to seek in AVI", "Failed to determine AVI",
                                 "Frame offset points outside"})
    if (line.substr(0, start.size()) == start) return true;
  return false;
}

}  // namespace

bool VideoReader::open_capture() {
  // FFmpeg first: it seeks by frame and reads every container here. Then the other backends that read files,
  // by name: CAP_ANY would also try camera backends (gphoto2 scans the USB bus) and CAP_IMAGES (one still).
  for (const cv::VideoCaptureAPIs api : {cv::CAP_FFMPEG, cv::CAP_GSTREAMER, cv::CAP_OPENCV_MJPEG}) {
    if (!cv::videoio_registry::hasBackend(api)) continue;
    bool opened = false;
    const auto open = [&] {
      try {
        opened = cap_.open(path_, api) && cap_.isOpened();
      } catch (const cv::Exception&) {
      }
    };
    // OpenCV's own AVI reader prints what it finds wrong in a file straight to stderr ("Unexpected element.
    // Expected: LIST. Got: ."), past every log level; our message names the file instead.
    if (api == cv::CAP_OPENCV_MJPEG) without_library_lines(open, is_avi_reader_line);
    else open();
    if (opened) return true;
  }
  return false;
}

Result<VideoReader> VideoReader::open(const std::string& path, cv::Mat* first, int64_t max_pixels) {
  if (Status st = check_input_file(path, kVideoFile); !st) return fail(st.error());
  keep_opencv_quiet();
  VideoReader r(path);
  if (!r.open_capture()) return fail(path + ": cannot open the video");
  const double fps = r.cap_.get(cv::CAP_PROP_FPS);
  if (std::isfinite(fps) && fps >= 0.1 && fps <= 1000) r.fps_ = fps;
  const double count = r.cap_.get(cv::CAP_PROP_FRAME_COUNT);
  if (std::isfinite(count) && count >= 1 && count < 1e9) r.frame_count_ = std::llround(count);
  // Refused before any frame is decoded, as an image is by its header.
  const double w = r.cap_.get(cv::CAP_PROP_FRAME_WIDTH), h = r.cap_.get(cv::CAP_PROP_FRAME_HEIGHT);
  if (std::isfinite(w) && std::isfinite(h))
    if (std::string reason = too_large(w, h, max_pixels); !reason.empty()) return fail(path + ": frames of " + reason);

  // The first frame proves the video has frames, and gives the size when the properties do not.
  cv::Mat f;
  bool ok = false;
  try {
    ok = r.cap_.read(f) && !f.empty();
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) return fail(path + ": has no frames that can be decoded");
  if (std::string reason = too_large(f.cols, f.rows, max_pixels); !reason.empty())
    return fail(path + ": frames of " + reason);
  r.size_ = f.size();
  r.next_ = 1;
  if (first) to_bgr8(f).copyTo(*first);
  return r;
}

VideoReader::Read VideoReader::read(cv::Mat* out) {
  cv::Mat f;
  bool ok = false;
  if (cap_.isOpened()) {
    try {
      ok = out ? cap_.read(f) && !f.empty() : cap_.grab();
    } catch (const cv::Exception&) {
      ok = false;
    }
  }
  if (ok) {
    ++next_;
    if (out) {
      const cv::Mat bgr = to_bgr8(f);
      // A stream that changes resolution midway keeps the size the consumer was told. Copied: a backend's own
      // buffer would be overwritten by the next frame.
      if (bgr.size() != size_) cv::resize(bgr, *out, size_, 0, 0, cv::INTER_AREA);
      else bgr.copyTo(*out);
    }
    return Read::frame;
  }
  if (next_ == 0) {  // after reopening: the file changed or vanished since it was opened
    if (error_.empty()) error_ = path_ + ": cannot decode the first frame any more";
    return Read::damaged;
  }
  // No frame at next_. One frame of slack: containers often count one frame more than they hold.
  Read result = Read::end;
  if (frame_count_ > 0 && next_ + 1 < frame_count_ && error_.empty()) {
    error_ = path_ + ": cannot decode frame " + std::to_string(next_) + " of " + std::to_string(frame_count_) +
             " (damaged or truncated file); the video ends at frame " + std::to_string(next_ - 1);
    result = Read::damaged;
  }
  if (frame_count_ == 0 || next_ < frame_count_) frame_count_ = std::max<int64_t>(next_, 1);
  return result;
}

bool VideoReader::seek(int64_t index) {
  if (!cap_.isOpened()) return false;
  index = std::max<int64_t>(index, 0);
  if (index > 0 && seek_ok_) {
    bool ok = false;
    try {
      ok = cap_.set(cv::CAP_PROP_POS_FRAMES, static_cast<double>(index));
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (ok) {
      next_ = index;
      return true;
    }
    seek_ok_ = false;  // from now on: reopen and decode forward
  }
  if (index >= next_) return true;  // forward without seeking: the caller reads up to it
  cap_.release();
  if (!open_capture()) {
    if (error_.empty()) error_ = path_ + ": cannot reopen the video";
    return false;
  }
  next_ = 0;
  return true;
}

}  // namespace arwb
