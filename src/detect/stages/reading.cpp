// The reading stages, a quad's frontal view read as a marker: otsu, bit_grid, border_check and identification
// (each a [SECTION] below). The detector runs them after perspective_removal.
#include "detect/pipeline.hpp"

#include "detect/stages/sampling.hpp"

namespace arwb::stages {

// [SECTION] border_check's quiet zone

QuietZone quiet_zone(const cv::Mat& grey, const Quad& quad, int cells, const OtsuResult& otsu) {
  // The step from the border up to its quiet zone, pair by pair: a shadow or gradient across the marker darkens
  // both alike. A step under an eighth of the view's black-to-white gap (a quarter of black to the threshold) is
  // dark. (A quarter of the gap lost a grey-on-grey marker whose quiet zone lies in a shadow: hard image 50.)
  double black = 0, count = 0;
  for (int v = 0; v < otsu.threshold; ++v) {
    black += double(v) * otsu.histogram[size_t(v)];
    count += otsu.histogram[size_t(v)];
  }
  const double min_step = count > 0 ? 0.25 * (otsu.threshold - black / count) : 0;
  const cv::Matx33d H = square_to_quad(quad, cells);
  auto at = [&](double u, double v, double* value) {
    const cv::Vec3d px = H * cv::Vec3d(u, v, 1);
    const double x = px[0] / px[2], y = px[1] / px[2];
    if (!(x >= 0 && y >= 0 && x <= grey.cols - 1 && y <= grey.rows - 1)) return false;
    *value = sample_bilinear(grey, x, y);
    return true;
  };
  QuietZone worst;
  for (int side = 0; side < 4; ++side) {
    int dark = 0, seen = 0;
    for (int k = 0; k < cells; ++k) {
      const double t = k + 0.5;
      // (u, v) at depth d outside the side (negative: inside); side k runs from corner k to corner k + 1.
      auto cell = [&](double d, double* value) {
        switch (side) {
          case 0: return at(t, -d, value);
          case 1: return at(cells + d, t, value);
          case 2: return at(cells - t, cells + d, value);
          default: return at(-d, cells - t, value);
        }
      };
      double quiet = 0, border = 0;
      if (!cell(0.5, &quiet) || !cell(-0.5, &border)) continue;
      ++seen;
      if (quiet - border < min_step) ++dark;
    }
    const double share = seen > 0 ? double(dark) / seen : 0;
    if (share > worst.dark_share) worst = {share, side};
  }
  return worst;
}

// [SECTION] otsu: the threshold between the frontal view's two grey populations

OtsuResult otsu(const cv::Mat& warp) {
  OtsuResult r;
  // Four histograms, pixels taken in turn, added at the end: a frontal view is mostly two levels, and one
  // histogram's counts of the same level waited on each other (a store and a load a pixel).
  std::array<std::array<int, 256>, 4> part{};
  for (int y = 0; y < warp.rows; ++y) {
    const uint8_t* row = warp.ptr<uint8_t>(y);
    int x = 0;
    for (; x + 4 <= warp.cols; x += 4) {
      ++part[0][row[x]];
      ++part[1][row[x + 1]];
      ++part[2][row[x + 2]];
      ++part[3][row[x + 3]];
    }
    for (; x < warp.cols; ++x) ++part[0][row[x]];
  }
  for (size_t i = 0; i < 256; ++i) r.histogram[i] = part[0][i] + part[1][i] + part[2][i] + part[3][i];
  const double total = double(warp.total());
  double sum = 0, sum_sq = 0;
  for (int i = 0; i < 256; ++i) {
    sum += double(i) * r.histogram[size_t(i)];
    sum_sq += double(i) * i * r.histogram[size_t(i)];
  }
  const double mean = sum / total;
  r.stddev = std::sqrt(std::max(0.0, sum_sq / total - mean * mean));
  // Maximise the between-class variance w0 w1 (m0 - m1)^2.
  // Two-level images tie over a whole range of thresholds; the middle of the tie is the natural cut.
  double w0 = 0, sum0 = 0, best = -1;
  int last_best = 0;
  for (int t = 0; t < 256; ++t) {
    w0 += r.histogram[size_t(t)];
    sum0 += double(t) * r.histogram[size_t(t)];
    const double w1 = total - w0;
    if (w0 == 0) continue;
    if (w1 == 0) break;
    const double m0 = sum0 / w0, m1 = (sum - sum0) / w1;
    const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best * (1 + 1e-12)) {
      best = between;
      r.threshold = last_best = t;
    } else if (between >= best * (1 - 1e-12)) {
      last_best = t;
    }
  }
  r.threshold = (r.threshold + last_best) / 2;
  return r;
}

// [SECTION] bit_grid: one bit per cell

cv::Mat sample_bits(const cv::Mat& warp, int cells, int threshold, const DetectorParams& p) {
  const int cp = p.warp_cell_px;
  const int margin = std::min(static_cast<int>(p.warp_margin_rate * cp + 0.5), (cp - 1) / 2);
  cv::Mat bits(cells, cells, CV_8UC1);
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) {
      int white = 0, count = 0;
      for (int y = r * cp + margin; y < (r + 1) * cp - margin; ++y) {
        const uint8_t* row = warp.ptr<uint8_t>(y);
        for (int x = c * cp + margin; x < (c + 1) * cp - margin; ++x) {
          white += row[x] > threshold;
          ++count;
        }
      }
      bits.at<uint8_t>(r, c) = static_cast<uint8_t>(2 * white > count);
    }
  return bits;
}

// [SECTION] border_check: the outer ring of cells must be black (and its quiet zone light: quiet_zone above)

int border_errors(const cv::Mat& bits) {
  int errors = 0;
  const int n = bits.rows;
  for (int i = 0; i < n; ++i) {
    errors += bits.at<uint8_t>(0, i) + bits.at<uint8_t>(n - 1, i);
    if (i > 0 && i < n - 1) errors += bits.at<uint8_t>(i, 0) + bits.at<uint8_t>(i, n - 1);
  }
  return errors;
}

// [SECTION] identification: the inner bits against the dictionary

uint64_t inner_code(const cv::Mat& bits) {
  return Dictionary::pack(bits(cv::Rect(1, 1, bits.cols - 2, bits.rows - 2)).clone());
}

int correction_budget(const Dictionary& dict, const DetectorParams& p) {
  return static_cast<int>(dict.max_correction_bits() * p.error_correction_rate);
}

}  // namespace arwb::stages
