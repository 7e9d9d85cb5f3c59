// adaptive_threshold: 255 where a pixel is darker than its window mean by more than threshold_offset.
#include "detect/pipeline.hpp"

#include "detect/kernels/kernels.hpp"

#include <opencv2/imgproc.hpp>

namespace arwb::stages {
namespace {

// The window's mean: the level's kernel where it has one for k, else cv::boxFilter (the same bits).
void box_mean(const kernels::Kernels& k, const cv::Mat& src, cv::Mat& dst, int window) {
  dst.create(src.size(), CV_8UC1);
  thread_local std::vector<uint16_t> scratch;
  const size_t need = kernels::box_mean_scratch(src.cols, window);
  if (scratch.size() < need) scratch.resize(need);
  if (k.box_mean(src.data, src.step, src.cols, src.rows, window, dst.data, dst.step, scratch.data())) return;
  cv::boxFilter(src, dst, CV_8U, cv::Size(window, window), cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
}

}  // namespace

cv::Mat adaptive_threshold(const cv::Mat& grey, const DetectorParams& p, cv::Mat* block_means) {
  cv::Mat binary;
  if (block_means) block_means->release();
  const int window = p.threshold_window_px | 1;  // the mean needs an odd window
  if (window < 9 || grey.cols < 32 || grey.rows < 32) {
    cv::adaptiveThreshold(grey, binary, 255, cv::ADAPTIVE_THRESH_MEAN_C, cv::THRESH_BINARY_INV, window,
                          p.threshold_offset);
    return binary;
  }
  // A window of 9 pixels or more: its mean is taken over the image's 2x2 block means, a window half as wide, and
  // brought back to every pixel bilinearly. The mean of a wide window hardly changes from one pixel to the next,
  // so this is as good for the threshold and a third of the work; the block means also calm sensor noise in the
  // mean (more markers found in dim scenes). Each pixel itself is compared at full resolution: small markers keep
  // their quiet zones.
  // The blocks are the whole 2x2 blocks, decimate(grey, 2): cv::resize's INTER_AREA to the level (an odd side had
  // sent that to its general path, many times slower), by our own halving. An odd last column or row takes the mean
  // of the blocks beside it.
  const cv::Size whole(grey.cols / 2, grey.rows / 2);
  cv::Mat mean;
  const cv::Mat blocks = decimate(grey, 2);
  const int half = (window / 2) | 1;
  const kernels::Kernels& k = kernels::kernels();
  box_mean(k, blocks, mean, half);
  if (block_means) *block_means = blocks;
  // Brought back to the full size bilinearly and compared there, in one pass: black where grey + offset <= mean
  // (saturating, as cv::add would). At twice the size, bilinear weighs the two nearest block means 3:1 along each
  // axis (OpenCV's INTER_LINEAR, clamped at the edges the same way; here exact, where its fixed point may round a
  // level apart), so no full-size mean is written and read back (cv::resize's upsizing had been most of the
  // stage). An odd last row or column takes the mean of the one before it.
  binary.create(grey.size(), CV_8UC1);
  const int offset = cv::saturate_cast<uint8_t>(p.threshold_offset);
  const int mw = mean.cols, mh = mean.rows;
  thread_local std::vector<uint16_t> vbuf;   // one row of vertically blended means, clamped one past each end
  vbuf.resize(size_t(mw) + 2);
  uint16_t* v = vbuf.data() + 1;
  for (int y = 0; y < grey.rows; ++y) {
    const int yy = std::min(y, 2 * mh - 1);   // an odd last row: the row before it
    const int j = yy / 2;
    const int far = std::clamp(yy % 2 ? j + 1 : j - 1, 0, mh - 1);
    k.blend_row(mean.ptr<uint8_t>(j), mean.ptr<uint8_t>(far), v, mw);
    v[-1] = v[0];
    v[mw] = v[mw - 1];
    const uint8_t* g = grey.ptr<uint8_t>(y);
    uint8_t* b = binary.ptr<uint8_t>(y);
    k.threshold_row(v, mw, g, b, offset);
    if (grey.cols % 2)   // the odd last column: the last mean's right half
      b[grey.cols - 1] = std::min(g[grey.cols - 1] + offset, 255) <= (3 * v[mw - 1] + v[mw] + 8) >> 4 ? 255 : 0;
  }
  return binary;
}

}  // namespace arwb::stages
