// Frame sources: where frames come from (camera, video file, image, folder of images, the synthetic source). The
// paper's acquisition step that follows is capture/acquisition.hpp.
//
// A source is pulled by one thread (the workbench's worker). It never throws: a failure is returned as a
// SourceStatus with a message naming the device, file or frame, and the caller decides what to do (the
// workbench logs it and falls back to the synthetic source when the source is gone).
#pragma once

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace arwb {

// `lab`: a cell of the recognition lab's plan (lab/cell_source.hpp), opened from the Lab workspace, not by a spec.
enum class SourceKind { synthetic, camera, video, image, folder, lab };
std::string_view source_kind_name(SourceKind k);

// What `--source` and the UI's source box accept: "synthetic", "camera:N" (V4L2 device N; "camera:N@WxH" also
// requests a capture size), or a path to a video, an image or a folder of images. The path's kind is decided by its content (magic bytes), not its name.
struct SourceSpec {
  SourceKind kind = SourceKind::synthetic;
  int device = 0;         // camera
  std::string path;       // video, image, folder
  cv::Size resolution{};  // camera: requested capture size; 0x0 = the device's default
  std::string text() const;  // back to the --source form
  bool operator==(const SourceSpec&) const = default;
};
// False and a one-line message naming the argument when it names nothing usable (missing path, bad device).
bool parse_source_spec(const std::string& text, SourceSpec* out, std::string* error);
// parse_source_spec, where an empty `text` means the first camera that exists, else the synthetic source (what
// the workbench and the player open when no --source is given).
bool parse_source_or_default(const std::string& text, SourceSpec* out, std::string* error);

enum class FrameStatus {
  ok,         // a new frame
  same,       // no new frame yet (still image, paused video): the previous frame stands
  end,        // a video or folder reached its end and does not loop
  error,      // this frame failed (corrupt image in a folder); the next may be fine
  gone,       // the source is no longer usable (camera unplugged, file vanished)
};

struct SourceStatus {
  FrameStatus status = FrameStatus::ok;
  std::string message;    // for error and gone: names the device, file or frame
};

// Playback controls. Video: play/pause, step, seek, loop, speed. Folder: next/previous (step by +1/-1), loop,
// and while playing one image a second (times speed). Image and camera ignore what does not apply.
struct Playback {
  bool playing = true;
  bool loop = true;
  double speed = 1.0;     // video and folder: 0.1 .. 8
  bool operator==(const Playback&) const = default;
};

struct SourceInfo {
  SourceKind kind = SourceKind::synthetic;
  std::string name;       // "synthetic", "camera:0", or the file name
  cv::Size size{};        // native frame size
  double native_fps = 0;  // video's or camera's nominal rate; 0 unknown
  int position = 0;       // frame index (video) or image index (folder)
  int count = 0;          // frames in the video or images in the folder; 0 unknown/live
  std::string item;       // folder: the current file's name
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The next frame into `out` (BGR, 8 bit). `now_s` is the caller's clock, for sources that play in time.
  virtual SourceStatus next(double now_s, cv::Mat& out) = 0;
  virtual SourceInfo info() const = 0;
  // Playback; sources without a timeline ignore these.
  virtual void set_playback(const Playback&) {}
  virtual void step(int /*delta*/) {}          // one frame or image forward (+1) or back (-1); pauses a video
  virtual void seek(int /*position*/) {}       // frame index or image index
};

// Opens a camera, video, image or folder source. Null and a one-line message when it cannot be opened (no such
// camera, unreadable video...). The synthetic source is synth's (synth/synthetic_source.hpp: open_source opens
// every kind).
std::unique_ptr<FrameSource> open_capture_source(const SourceSpec& spec, std::string* error);

// V4L2 devices that exist (/dev/videoN), for the UI's camera list.
std::vector<int> list_cameras();

}  // namespace arwb
