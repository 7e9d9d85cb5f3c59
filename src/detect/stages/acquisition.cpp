// acquisition: the frame resized as acquisition says and made grey, where the stages look (GreyOnDemand).
#include "detect/pipeline.hpp"

#include "detect/kernels/kernels.hpp"

#include <opencv2/imgproc.hpp>

namespace arwb::stages {
namespace {

// Whether the kernels convert these 8-bit colour pixels: BGR, BGRA and RGBA (RGB goes through cvtColor).
bool kernels_convert(const cv::Mat& colour, bool rgb) {
  return colour.depth() == CV_8U && (colour.channels() == 4 || (colour.channels() == 3 && !rgb));
}

// One row of kernels_convert's pixels to grey: cvtColor's levels exactly.
void grey_row(const kernels::Kernels& k, const uint8_t* px, uint8_t* grey, int n, int channels, bool rgb) {
  if (channels == 3) k.grey_row(px, grey, n);
  else k.grey_row4(px, grey, n, rgb);
}

// A colour image (or a view of one) into `grey`, allocated to its size unless it already has it (a view is written
// in place).
void colour_to_grey(const cv::Mat& colour, cv::Mat& grey, bool rgb) {
  grey.create(colour.size(), CV_8UC1);
  if (!kernels_convert(colour, rgb)) {
    const int code = colour.channels() == 3 ? (rgb ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY)
                                            : (rgb ? cv::COLOR_RGBA2GRAY : cv::COLOR_BGRA2GRAY);
    cv::Mat levels;
    cv::cvtColor(colour, levels, code);
    levels.convertTo(grey, CV_8U);
    return;
  }
  const kernels::Kernels& k = kernels::kernels();
  for (int y = 0; y < grey.rows; ++y)
    grey_row(k, colour.ptr<uint8_t>(y), grey.ptr<uint8_t>(y), grey.cols, colour.channels(), rgb);
}

// colour_to_grey, and the grey image's 2x2 block means (its whole blocks) into `half` as each pair of rows is done,
// while they are in the cache: decimate(grey, 2) exactly, (a + b + c + d + 2) / 4.
void colour_to_grey_and_half(const cv::Mat& colour, cv::Mat& grey, cv::Mat& half, bool rgb) {
  grey.create(colour.size(), CV_8UC1);
  half.create(colour.rows / 2, colour.cols / 2, CV_8UC1);
  const kernels::Kernels& k = kernels::kernels();
  for (int y = 0; y < colour.rows; y += 2) {
    const int rows = std::min(2, colour.rows - y);
    for (int r = y; r < y + rows; ++r)
      grey_row(k, colour.ptr<uint8_t>(r), grey.ptr<uint8_t>(r), grey.cols, colour.channels(), rgb);
    if (rows < 2) break;
    k.halve_rows(grey.ptr<uint8_t>(y), grey.ptr<uint8_t>(y + 1), half.ptr<uint8_t>(y / 2), half.cols);
  }
}

cv::Mat to_grey(const cv::Mat& input, bool rgb) {
  cv::Mat grey;
  if (input.channels() == 3 || input.channels() == 4) colour_to_grey(input, grey, rgb);
  else grey = input;
  if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U);
  return grey;
}

}  // namespace

GreyOnDemand::GreyOnDemand(const cv::Mat& frame, bool rgb) : rgb_(rgb) {
  if (!kernels_convert(frame, rgb)) {
    grey_ = frame.empty() ? cv::Mat() : to_grey(frame, rgb);
    return;
  }
  colour_ = frame;
  grey_.create(frame.size(), CV_8UC1);
  tiles_x_ = (frame.cols + kTile - 1) / kTile;
  done_.assign(size_t(tiles_x_) * size_t((frame.rows + kTile - 1) / kTile), 0);
}

cv::Mat GreyOnDemand::convert_all_and_halve() {
  cv::Mat half;
  colour_to_grey_and_half(colour_, grey_, half, rgb_);
  std::fill(done_.begin(), done_.end(), uint8_t(1));
  return half;
}

void GreyOnDemand::need(const cv::Rect& r) {
  if (colour_.empty()) return;
  const cv::Rect frame(0, 0, grey_.cols, grey_.rows);
  const cv::Rect in = r & frame;
  if (in.empty()) return;
  const int tx0 = in.x / kTile, tx1 = (in.x + in.width - 1) / kTile;
  const int ty0 = in.y / kTile, ty1 = (in.y + in.height - 1) / kTile;
  // Tiles [x0, x1] x [y0, y1] converted in one call (a call has a fixed cost: a block at once) and marked.
  auto convert = [&](int x0, int y0, int x1, int y1) {
    const cv::Rect px = cv::Rect(x0 * kTile, y0 * kTile, (x1 - x0 + 1) * kTile, (y1 - y0 + 1) * kTile) & frame;
    cv::Mat out = grey_(px);   // converted in place: a destination of the right size is kept
    colour_to_grey(colour_(px), out, rgb_);
    for (int ty = y0; ty <= y1; ++ty)
      std::fill_n(done_.begin() + ptrdiff_t(ty) * tiles_x_ + x0, x1 - x0 + 1, uint8_t(1));
  };
  auto done = [&](int tx, int ty) { return done_[size_t(ty) * size_t(tiles_x_) + size_t(tx)] != 0; };
  bool fresh = true;   // none of r's tiles converted yet: all at once
  for (int ty = ty0; ty <= ty1 && fresh; ++ty)
    for (int tx = tx0; tx <= tx1 && fresh; ++tx) fresh = !done(tx, ty);
  if (fresh) return convert(tx0, ty0, tx1, ty1);
  for (int ty = ty0; ty <= ty1; ++ty)   // else each row's runs of tiles not yet converted
    for (int tx = tx0; tx <= tx1;) {
      if (done(tx, ty)) {
        ++tx;
        continue;
      }
      int end = tx;
      while (end + 1 <= tx1 && !done(end + 1, ty)) ++end;
      convert(tx, ty, end, ty);
      tx = end + 1;
    }
}

GreyOnDemand acquire_on_demand(const cv::Mat& input, const AcquisitionSettings& a, double* scale_x,
                               double* scale_y, cv::Mat* acquired) {
  const cv::Size size = acquisition_size(input.size(), a);
  *scale_x = double(input.cols) / size.width;
  *scale_y = double(input.rows) / size.height;
  if (acquired) {
    arwb::acquire(input, a, *acquired);
    return GreyOnDemand(*acquired, a.rgb);
  }
  if (size == input.size()) return GreyOnDemand(input, a.rgb);
  // Nobody shows the resized colour frame: resizing the grey one is the same step with a third of the work.
  cv::Mat grey = to_grey(input, a.rgb);
  arwb::acquire(grey, a, grey);
  return GreyOnDemand(grey);
}

cv::Mat acquire(const cv::Mat& input, const AcquisitionSettings& a, double* scale_x, double* scale_y,
                cv::Mat* acquired) {
  GreyOnDemand grey = acquire_on_demand(input, a, scale_x, scale_y, acquired);
  grey.need_all();
  return grey.image();
}

}  // namespace arwb::stages
