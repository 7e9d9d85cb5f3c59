// The one video reader: a file decoded frame by frame, for the video source (capture/source.hpp) and the media
// store's players (media/media_store.hpp), so both open, seek and end on a damaged file the same way.
//
// Input is untrusted: the file may not be a video, may declare absurd frame sizes or rates, or may be cut short
// (a download that stopped). Opening decodes the first frame, so a reader that opens has at least one picture.
// A file that ends before the frame count its container promised says so once, in error(), and from then on its
// frame count is what could really be decoded.
#pragma once

#include "base/files.hpp"
#include "base/result.hpp"
#include "capture/image_io.hpp"

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include <cstdint>
#include <string>

namespace arwb {

// Videos are streamed, never held whole, so their limit only says what a video file can plausibly be; the check
// that matters is that the path is a regular file (FFmpeg would wait forever on a FIFO, read /dev/zero forever).
inline constexpr FileLimit kVideoFile{"a video", std::uintmax_t{1} << 40};

class VideoReader {
 public:
  // Opens `path` (FFmpeg first, then the other backends that read files) and decodes its first frame into
  // *first (8-bit BGR). Fails, with the message "<path>: <reason>", when the path fails check_input_file (not a
  // regular file, larger than kVideoFile), when the file "cannot open the video", "has
  // no frames that can be decoded", or has "frames of 9000x9000 pixels, more than 40000000" (max_pixels; a side
  // longer than kMaxImageSide is refused too), the last checked before any frame is decoded when the container
  // tells the size.
  static Result<VideoReader> open(const std::string& path, cv::Mat* first, int64_t max_pixels = kDefaultMaxPixels);

  const std::string& path() const { return path_; }
  cv::Size size() const { return size_; }   // the first frame's; every frame read has it
  // The container's frame rate; 0 when it gives none or an absurd one (outside 0.1 .. 1000: some containers
  // report their time base, 90000).
  double fps() const { return fps_; }
  // Frames in the file: the container's count, until decoding ends before it; then the frames really decoded.
  // 0 while unknown.
  int64_t frame_count() const { return frame_count_; }
  int64_t next_index() const { return next_; }   // the frame the next read returns
  bool can_seek() const { return seek_ok_; }     // false once the backend refused a seek: seek() reopens instead
  // The one message about a file that ended early, "" if none: "<path>: cannot decode frame 18 of 40 (damaged
  // or truncated file); the video ends at frame 17".
  const std::string& error() const { return error_; }

  enum class Read {
    frame,     // decoded (or skipped), and next_index() moved on
    end,       // no frame at next_index(): the end of the video
    damaged,   // no frame at next_index(), well before the container's count (or frame 0 after reopening):
               // error() says so (once)
  };
  // The frame at next_index() into *out (8-bit BGR of size(), never sharing the decoder's buffer), or only
  // skipped over when out is null, which is cheaper. At the end, next_index() stays where the frames stop.
  Read read(cv::Mat* out);

  // Makes the next read return frame `index`, by seeking (CAP_PROP_POS_FRAMES); when the backend cannot seek,
  // going back reopens the file and going forward is left to reads: next_index() then says where the reader
  // is, and the caller skips forward with read(nullptr). False when the file cannot be reopened (error() then
  // says "<path>: cannot reopen the video", and the reader stays unusable).
  bool seek(int64_t index);

 private:
  explicit VideoReader(std::string path) : path_(std::move(path)) {}
  bool open_capture();

  std::string path_;
  cv::VideoCapture cap_;
  cv::Size size_;
  double fps_ = 0;
  int64_t frame_count_ = 0;
  int64_t next_ = 0;
  bool seek_ok_ = true;   // the backend accepted CAP_PROP_POS_FRAMES so far
  std::string error_;
};

}  // namespace arwb
