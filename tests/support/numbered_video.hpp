// Videos whose frames carry their own number, for tests that must know which frame they are shown: frame i has
// stripe b white when bit b of i is set, which survives lossy codecs and any resize. Header-only: the test
// executables that use it link OpenCV's video I/O through capture/, the support library does not.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include <string>

namespace arwb::test {

inline constexpr int kNumberBits = 6;   // frames 0 to 63

// Writes `frames` numbered frames of `size` at `fps` with FFmpeg's `fourcc` ("MJPG" for .avi, "mp4v" for .mp4);
// false when this OpenCV has no such writer.
inline bool write_numbered_video(const std::string& path, const char (&fourcc)[5], int frames, cv::Size size,
                                 double fps) {
  cv::VideoWriter w(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]), fps,
                    size);
  if (!w.isOpened()) return false;
  const int stripe = size.width / (kNumberBits + 1);
  for (int i = 0; i < frames; ++i) {
    cv::Mat m(size, CV_8UC3, cv::Scalar::all(0));
    for (int bit = 0; bit < kNumberBits; ++bit)
      if (i >> bit & 1) m(cv::Rect(bit * stripe, 0, stripe, size.height)).setTo(cv::Scalar::all(255));
    w.write(m);
  }
  return true;
}

// The number a frame of write_numbered_video carries, at whatever size it is shown.
inline int numbered_frame(const cv::Mat& m) {
  const double stripe = double(m.cols) / (kNumberBits + 1);
  int i = 0;
  for (int bit = 0; bit < kNumberBits; ++bit) {
    const cv::Rect inner(int(bit * stripe + stripe * 0.3), m.rows / 6, int(stripe * 0.4), m.rows * 2 / 3);
    if (cv::mean(m(inner))[0] > 128) i |= 1 << bit;
  }
  return i;
}

}  // namespace arwb::test
