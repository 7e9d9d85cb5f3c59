#include "capture/acquisition.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <exception>

namespace arwb {

cv::Size acquisition_size(cv::Size in, const AcquisitionSettings& s) {
  if (!s.resize || in.width <= 0 || in.height <= 0 || s.size.width < 0 || s.size.height < 0) return in;
  int w = s.size.width, h = s.size.height;
  if (w == 0 && h == 0) return in;
  if (w == 0) w = static_cast<int>(std::lround(in.width * double(h) / in.height));
  if (h == 0) h = static_cast<int>(std::lround(in.height * double(w) / in.width));
  return {std::max(w, 1), std::max(h, 1)};
}

void acquire(const cv::Mat& in, const AcquisitionSettings& s, cv::Mat& out) {
  try {
    if (in.empty()) {
      out.release();
      return;
    }
    const cv::Size size = acquisition_size(in.size(), s);
    if (size == in.size()) {
      if (&in != &out) in.copyTo(out);
      return;
    }
    const bool shrink = size.width <= in.cols && size.height <= in.rows;
    cv::resize(in, out, size, 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
  } catch (const std::exception&) {
    out.release();
  }
}

}  // namespace arwb
