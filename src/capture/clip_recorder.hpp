// Recording a clip of a source's frames as they are taken: the Lab workspace's Record (arwb lab --videos films the
// paper's clips with it). The engine's worker hands over every new frame with push(), which never waits: the frame
// is queued and a thread of the recorder's own encodes it, so capture and detection keep their pace. A frame that
// finds the queue full (the disk slower than the camera) is dropped and counted, never silently lost: the clip's
// summary says how many.
//
// The file is lossless (FFV1 in Matroska): what arwb lab --videos reads back is what the camera gave, not what an
// encoder kept of it. Frames must keep the first one's size; one that does not ends the clip with a message, and
// the frames before it stay in the file.
#pragma once

#include "base/result.hpp"

#include <opencv2/core.hpp>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>

namespace arwb {

struct ClipSummary {
  std::string path;
  int64_t frames = 0;    // written to the file
  int64_t dropped = 0;   // taken while the queue was full: not in the file
  double seconds = 0;    // from start() to stop()
  std::string error;     // "" or why the clip ended early (the frames before it are in the file)
};

class ClipRecorder {
 public:
  // Frames waiting for the encoder, at most: 1.4 s of a 1080p camera at 30 fps, 9 s of a 640x480 one.
  static constexpr size_t kQueueBytes = size_t{256} << 20;

  explicit ClipRecorder(size_t queue_bytes = kQueueBytes) : queue_limit_(queue_bytes) {}
  ~ClipRecorder();
  ClipRecorder(const ClipRecorder&) = delete;
  ClipRecorder& operator=(const ClipRecorder&) = delete;

  // Creates `path` (its folder too) for frames of `size` at `fps` (the rate a player shows them at; 30 when the
  // source gives none). Refuses a path that exists (a clip is never overwritten) or cannot be written, naming it.
  Status start(const std::string& path, cv::Size size, double fps);
  // Queues a copy of an 8-bit BGR or grey frame; false when not recording (never started, stopped, or ended).
  bool push(const cv::Mat& frame);
  // Encodes what is queued, closes the file and says what it holds. Recording can start again after it.
  ClipSummary stop();

  bool recording() const { return recording_.load(); }
  ClipSummary progress() const;   // so far, while recording; the last clip's after stop()

 private:
  mutable std::mutex m_;
  std::condition_variable wake_;
  std::deque<cv::Mat> queue_;
  size_t queued_bytes_ = 0;
  const size_t queue_limit_;
  std::thread thread_;
  std::atomic<bool> recording_{false};
  bool closing_ = false;
  cv::Size size_;
  double started_ = 0;
  ClipSummary summary_;
};

}  // namespace arwb
