#include "capture/pixels.hpp"

#include <opencv2/imgproc.hpp>

#include <vector>

namespace arwb {

cv::Mat to_8bit(const cv::Mat& in) {
  if (in.empty() || in.depth() == CV_8U) return in;
  double scale = 1.0;
  if (in.depth() == CV_16U) scale = 1.0 / 257.0;
  else if (in.depth() == CV_32F || in.depth() == CV_64F) scale = 255.0;
  cv::Mat out;
  in.convertTo(out, CV_8U, scale);
  return out;
}

cv::Mat to_bgr8(const cv::Mat& in, Alpha alpha) {
  const cv::Mat m = to_8bit(in);
  if (m.empty()) return m;
  const bool keep = alpha == Alpha::keep;
  cv::Mat out;
  switch (m.channels()) {
    case 1: cv::cvtColor(m, out, cv::COLOR_GRAY2BGR); break;
    case 2: {  // grey and alpha
      std::vector<cv::Mat> ga;
      cv::split(m, ga);
      if (keep) cv::merge(std::vector<cv::Mat>{ga[0], ga[0], ga[0], ga[1]}, out);
      else cv::cvtColor(ga[0], out, cv::COLOR_GRAY2BGR);
      break;
    }
    case 3: out = m; break;
    case 4:
      if (keep) out = m;
      else cv::cvtColor(m, out, cv::COLOR_BGRA2BGR);
      break;
    default: {  // more channels than any format here gives: keep the first three
      std::vector<cv::Mat> ch;
      cv::split(m, ch);
      cv::merge(std::vector<cv::Mat>{ch[0], ch[1], ch[2]}, out);
    }
  }
  return out;
}

}  // namespace arwb
