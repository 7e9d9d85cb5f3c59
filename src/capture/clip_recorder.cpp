#include "capture/clip_recorder.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <chrono>
#include <filesystem>
#include <system_error>

namespace arwb {

namespace {

namespace fs = std::filesystem;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

ClipRecorder::~ClipRecorder() { stop(); }

Status ClipRecorder::start(const std::string& path, cv::Size size, double fps) {
  stop();
  if (size.width <= 0 || size.height <= 0) return fail(path + ": no frame to take the clip's size from");
  std::error_code ec;
  if (fs::exists(path, ec)) return fail(path + ": exists (a recorded clip is never overwritten)");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::create_directories(parent, ec) && ec)
    return fail(parent.string() + ": cannot create the folder (" + ec.message() + ")");
  auto writer = std::make_shared<cv::VideoWriter>();
  const double rate = fps > 0 && fps <= 1000 ? fps : 30.0;
  if (!writer->open(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), rate, size, true)) {
    fs::remove(path, ec);
    return fail(path + ": cannot be written as a lossless video (FFV1 in Matroska: is the name's end .mkv?)");
  }
  {
    std::lock_guard<std::mutex> lock(m_);
    queue_.clear();
    queued_bytes_ = 0;
    closing_ = false;
    size_ = size;
    started_ = now_s();
    summary_ = ClipSummary{path, 0, 0, 0, ""};
  }
  recording_ = true;
  thread_ = std::thread([this, writer] {
    std::unique_lock<std::mutex> lock(m_);
    for (;;) {
      wake_.wait(lock, [&] { return closing_ || !queue_.empty(); });
      if (queue_.empty()) break;   // closing, and everything queued is written
      cv::Mat f = std::move(queue_.front());
      queue_.pop_front();
      queued_bytes_ -= f.total() * f.elemSize();
      lock.unlock();
      writer->write(f);
      lock.lock();
      ++summary_.frames;
    }
    writer->release();
  });
  return {};
}

bool ClipRecorder::push(const cv::Mat& frame) {
  if (!recording_) return false;
  std::lock_guard<std::mutex> lock(m_);
  if (closing_) return false;
  if (frame.size() != size_ || frame.depth() != CV_8U || (frame.channels() != 3 && frame.channels() != 1)) {
    summary_.error = "the source's frames changed from " + std::to_string(size_.width) + "x" +
                     std::to_string(size_.height) + " to " + std::to_string(frame.cols) + "x" +
                     std::to_string(frame.rows) + " (or their type); the clip ends before that frame";
    recording_ = false;
    return false;
  }
  const size_t bytes = frame.total() * 3;
  if (queued_bytes_ + bytes > queue_limit_) {
    ++summary_.dropped;
    return true;
  }
  cv::Mat copy;
  if (frame.channels() == 1) cv::cvtColor(frame, copy, cv::COLOR_GRAY2BGR);
  else copy = frame.clone();
  queue_.push_back(std::move(copy));
  queued_bytes_ += bytes;
  wake_.notify_one();
  return true;
}

ClipSummary ClipRecorder::stop() {
  if (!thread_.joinable()) return progress();
  {
    std::lock_guard<std::mutex> lock(m_);
    closing_ = true;
    summary_.seconds = now_s() - started_;
  }
  recording_ = false;
  wake_.notify_one();
  thread_.join();
  return progress();
}

ClipSummary ClipRecorder::progress() const {
  std::lock_guard<std::mutex> lock(m_);
  ClipSummary s = summary_;
  if (thread_.joinable() && !closing_) s.seconds = now_s() - started_;
  return s;
}

}  // namespace arwb
