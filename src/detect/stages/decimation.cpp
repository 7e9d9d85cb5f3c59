// decimation: the search image, the grey image shrunk `factor` times, each pixel the mean of its block.
#include "detect/pipeline.hpp"

#include "detect/kernels/kernels.hpp"

namespace arwb::stages {

int decimation_used(cv::Size grey, const DetectorParams& p) {
  int f = p.decimation_factor > 0 ? p.decimation_factor : std::min(grey.width, grey.height) >= 720 ? 2 : 1;
  while (f > 1 && std::min(grey.width, grey.height) / f < 64) --f;
  return f;
}

cv::Mat decimate(const cv::Mat& grey, int factor) {
  if (factor <= 1) return grey;
  // The block mean: noise averages out, and a marker's dark frame stays dark.
  CV_Assert(grey.type() == CV_8UC1 && factor <= 16);  // a 16x16 block's sum fits 16 bits
  cv::Mat out(grey.rows / factor, grey.cols / factor, CV_8UC1);
  const kernels::Kernels& k = kernels::kernels();
  if (factor == 2) {  // cv::resize's INTER_AREA to the level (its halving path), exactly
    for (int y = 0; y < out.rows; ++y)
      k.halve_rows(grey.ptr<uint8_t>(2 * y), grey.ptr<uint8_t>(2 * y + 1), out.ptr<uint8_t>(y), out.cols);
    return out;
  }
  // Other factors: INTER_AREA takes its general path on the whole image, spreading the leftover columns over every
  // block. Here the leftover is dropped, as undecimate assumes.
  k.decimate(grey.data, grey.step, factor, out.data, out.step, out.cols, out.rows);
  return out;
}

cv::Mat search_image(GreyOnDemand& grey, const cv::Rect& region, int factor) {
  const cv::Mat& colour = grey.colour();
  if (factor == 2 && !colour.empty() && region == cv::Rect(0, 0, colour.cols, colour.rows))
    return grey.convert_all_and_halve();
  grey.need(region);
  return decimate(grey.image()(region), factor);
}

}  // namespace arwb::stages
