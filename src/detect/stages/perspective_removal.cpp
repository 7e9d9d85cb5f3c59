// perspective_removal: the quad seen from the front, cells of warp_cell_px pixels (a multiple for a large quad),
// bilinear.
#include "detect/pipeline.hpp"

#include "detect/kernels/kernels.hpp"
#include "detect/stages/sampling.hpp"

#include <cmath>

namespace arwb::stages {

int view_scale(const Quad& quad, int cells, const DetectorParams& p) {
  if (p.warp_max_step_px <= 0) return 1;
  double longest = 0;
  for (size_t k = 0; k < 4; ++k) longest = std::max(longest, double(cv::norm(quad[(k + 1) % 4] - quad[k])));
  const double step = longest / (cells * p.warp_cell_px);
  const int most = std::max(1, std::min(4, 16 / p.warp_cell_px));
  return std::clamp(static_cast<int>(std::ceil(step / p.warp_max_step_px)), 1, most);
}

cv::Mat remove_perspective(const cv::Mat& grey, const Quad& quad, int cells, const DetectorParams& p) {
  const int side = cells * p.warp_cell_px * view_scale(quad, cells, p);
  const cv::Matx33d H = square_to_quad(quad, side);
  cv::Mat warp(side, side, CV_8UC1);
  // A sample inside the image (nearly all) is interpolated by bilinear_q8, in integers; one outside it, or of a quad
  // refinement bent out of shape, by sample_bilinear's clamped doubles.
  const double xmax = grey.cols - 1.001, ymax = grey.rows - 1.001;
  const uchar* data = grey.data;
  const size_t stride = grey.step;
  // Eight samples at a time where the level has a kernel for it: the same doubles and integers.
  const auto warp_row = kernels::kernels().warp_row;
  const bool vector = grey.cols < 16384 && grey.rows < 16384 && double(grey.step) * grey.rows < 2e9;
  thread_local std::vector<uint8_t> done;
  done.assign(size_t(side / 8), 0);
  for (int v = 0; v < side; ++v) {
    uint8_t* row = warp.ptr<uint8_t>(v);
    const double y = v + 0.5;
    const bool groups = vector && warp_row(H.val, y, side, data, stride, grey.cols - 4.0, ymax, row, done.data());
    for (int u = 0; u < side; ++u) {
      if (groups && u / 8 < int(done.size()) && done[size_t(u / 8)]) {
        u += 7;
        continue;
      }
      const double x = u + 0.5;
      const double inv_w = 1.0 / (H(2, 0) * x + H(2, 1) * y + H(2, 2));
      const double px = (H(0, 0) * x + H(0, 1) * y + H(0, 2)) * inv_w;
      const double py = (H(1, 0) * x + H(1, 1) * y + H(1, 2)) * inv_w;
      if (!(px >= 0 && py >= 0 && px < xmax && py < ymax)) {   // also false for NaN
        row[u] = static_cast<uint8_t>(sample_bilinear(grey, px, py) + 0.5);
        continue;
      }
      row[u] = static_cast<uint8_t>((bilinear_q8(data, stride, int(px * 256), int(py * 256)) + 32768) >> 16);
    }
  }
  return warp;
}

}  // namespace arwb::stages
