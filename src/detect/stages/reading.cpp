// The reading stages, a quad's frontal view read as a marker: otsu, bit_grid, border_check and identification
// (each a [SECTION] below). The detector runs them after perspective_removal.
#include "detect/pipeline.hpp"

#include "detect/stages/sampling.hpp"

#include <algorithm>
#include <vector>

namespace arwb::stages {
namespace {

// The grey level at (u, v) of the view's cell grid (cells a side) of `quad`, or false off the image (or NaN).
bool grey_at(const cv::Mat& grey, const cv::Matx33d& H, double u, double v, double* value) {
  const cv::Vec3d px = H * cv::Vec3d(u, v, 1);
  const double x = px[0] / px[2], y = px[1] / px[2];
  if (!(x >= 0 && y >= 0 && x <= grey.cols - 1 && y <= grey.rows - 1)) return false;
  *value = sample_bilinear(grey, x, y);
  return true;
}

// The grid point at t along side `side` (from corner side to corner side + 1) and d outside it (negative: inside).
cv::Point2d beside_side(int side, int cells, double t, double d) {
  switch (side) {
    case 0: return {t, -d};
    case 1: return {cells + d, t};
    case 2: return {cells - t, cells + d};
    default: return {-d, cells - t};
  }
}

// A view's pixels a cell, and of each cell's edges those ignored when sampling its centre (warp_margin_rate): the
// margin of a warp_cell_px cell, times the view's scale, so that a denser view samples the same centre.
struct CellPixels {
  int px, margin;
};
CellPixels cell_pixels(const cv::Mat& warp, int cells, const DetectorParams& p) {
  const int px = warp.rows / cells, scale = std::max(1, px / p.warp_cell_px);
  const int margin = std::min(static_cast<int>(p.warp_margin_rate * p.warp_cell_px + 0.5), (p.warp_cell_px - 1) / 2);
  return {px, scale * margin};
}

// The mean grey level of cell (r, c)'s centre, the pixels its bit is read from.
double cell_mean(const cv::Mat& warp, const CellPixels& px, int r, int c) {
  const int side = px.px - 2 * px.margin;
  return cv::mean(warp(cv::Rect(c * px.px + px.margin, r * px.px + px.margin, side, side)))[0];
}

}  // namespace

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
  QuietZone worst;
  for (int side = 0; side < 4; ++side) {
    int dark = 0, seen = 0;
    for (int k = 0; k < cells; ++k) {
      const double t = k + 0.5;
      auto cell = [&](double d, double* value) {
        const cv::Point2d uv = beside_side(side, cells, t, d);
        return grey_at(grey, H, uv.x, uv.y, value);
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

namespace {

// Each cell the majority of its centre's pixels (margins ignored) against threshold_at(row, col).
template <class Threshold>
cv::Mat majority_bits(const cv::Mat& warp, int cells, const DetectorParams& p, Threshold&& threshold_at) {
  const auto [cp, margin] = cell_pixels(warp, cells, p);
  cv::Mat bits(cells, cells, CV_8UC1);
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) {
      const double threshold = threshold_at(r, c);
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

}  // namespace

cv::Mat sample_bits(const cv::Mat& warp, int cells, int threshold, const DetectorParams& p) {
  return majority_bits(warp, cells, p, [threshold](int, int) { return threshold; });
}

// [SECTION] bit_grid's local thresholds (local_thresholds)

LocalRead read_local(const cv::Mat& grey, const Quad& quad, const cv::Mat& warp, int cells, const DetectorParams& p) {
  LocalRead out;
  const int last = cells - 1;
  // The ring's cells: their means over the same centres the bits are read from, and the quiet zone beside each,
  // half a cell outside, three samples along the side (a corner cell has both sides' beside it).
  cv::Mat_<double> quiet(cells, cells, 0.0), seen(cells, cells, 0.0);
  const CellPixels px = cell_pixels(warp, cells, p);
  const cv::Matx33d H = square_to_quad(quad, cells);
  for (int side = 0; side < 4; ++side)
    for (int k = 0; k < cells; ++k) {
      // Side k runs from corner k to corner k + 1: its k-th cell, and the point (u, v) at t along it, 0.5 outside.
      const int r = side == 0 ? 0 : side == 1 ? k : side == 2 ? last : last - k;
      const int c = side == 0 ? k : side == 1 ? last : side == 2 ? last - k : 0;
      for (const double along : {0.3, 0.5, 0.7}) {
        const cv::Point2d uv = beside_side(side, cells, k + along, 0.5);
        double value = 0;
        if (!grey_at(grey, H, uv.x, uv.y, &value)) return out;
        quiet(r, c) += value;
        seen(r, c) += 1;
      }
    }
  // Light multiplies the print's black and white alike (and a camera's gamma keeps that so): the border is the same
  // share of its quiet zone all round. That share's median, and the steps' median.
  std::vector<double> shares, steps;
  shares.reserve(size_t(4 * last));
  steps.reserve(size_t(4 * last));
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) {
      if (seen(r, c) == 0) continue;
      quiet(r, c) /= seen(r, c);
      const double border = cell_mean(warp, px, r, c);
      shares.push_back(border / std::max(quiet(r, c), 1.0));
      steps.push_back(quiet(r, c) - border);
    }
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  out.median_step = median(steps);
  const double mid_share = 0.5 * (1 + median(shares));
  // The mid level at each ring cell is that share of its quiet zone, half way from the border's share to 1; a ring
  // cell's bit is read against it, so that a cell only part dark (the corner of an outlined frame) reads white.
  cv::Mat_<double> mid(cells, cells, 0.0);
  double low = 255, high = 0;
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c)
      if (seen(r, c) > 0) {
        mid(r, c) = mid_share * quiet(r, c);
        low = std::min(low, mid(r, c));
        high = std::max(high, mid(r, c));
      }
  // Light even enough for one threshold (mid levels within a quarter of a step of each other) is otsu's to read.
  if (out.median_step < p.otsu_min_stddev || high - low < 0.25 * out.median_step) return out;
  out.ok = true;
  // Inside, the ring's mid levels spread by Coons' patch (the sum of the two ways' linear blends less the corners'
  // bilinear one).
  auto threshold_at = [&](int r, int c) {
    if (seen(r, c) > 0) return mid(r, c);
    const double u = double(c) / last, v = double(r) / last;
    return (1 - v) * mid(0, c) + v * mid(last, c) + (1 - u) * mid(r, 0) + u * mid(r, last) -
           ((1 - u) * (1 - v) * mid(0, 0) + u * (1 - v) * mid(0, last) + (1 - u) * v * mid(last, 0) +
            u * v * mid(last, last));
  };
  out.bits = majority_bits(warp, cells, p, threshold_at);
  // A ramp or edge the patch does not follow leaves a stripe of cells parallel to a side: an inside of one row or
  // one column repeated (ARUCO_ORIGINAL 0 and 1023 on outlined frames and light lines in the lab's empty frames) is
  // no reading.
  out.stripe = inner_stripes(out.bits) != Stripes::none;
  return out;
}

Stripes inner_stripes(const cv::Mat& bits) {
  const cv::Mat inner = bits(cv::Rect(1, 1, bits.cols - 2, bits.rows - 2));
  bool rows_same = true, cols_same = true;
  for (int k = 1; k < inner.rows; ++k) {
    rows_same = rows_same && cv::countNonZero(inner.row(k) != inner.row(0)) == 0;
    cols_same = cols_same && cv::countNonZero(inner.col(k) != inner.col(0)) == 0;
  }
  return rows_same ? Stripes::rows : cols_same ? Stripes::columns : Stripes::none;
}

// [SECTION] bit_grid's shading planes (local_thresholds)

cv::Mat read_shaded(const cv::Mat& warp, int cells, const cv::Mat& bits, const DetectorParams& p) {
  const CellPixels px = cell_pixels(warp, cells, p);
  cv::Mat_<double> mean(cells, cells);
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) mean(r, c) = cell_mean(warp, px, r, c);
  auto ring = [cells](int r, int c) { return r == 0 || c == 0 || r == cells - 1 || c == cells - 1; };
  cv::Mat cls = bits.clone();
  cv::Matx31d black, white;
  for (int round = 0; round < 3; ++round) {
    // Least squares planes a + b c + d r through the black cells (the ring always among them) and the white ones.
    cv::Matx33d nb = cv::Matx33d::zeros(), nw = cv::Matx33d::zeros();
    cv::Matx31d rb = cv::Matx31d::zeros(), rw = cv::Matx31d::zeros();
    for (int r = 0; r < cells; ++r)
      for (int c = 0; c < cells; ++c) {
        const cv::Matx31d x(1, c, r);
        const bool is_white = !ring(r, c) && cls.at<uint8_t>(r, c);
        (is_white ? nw : nb) += x * x.t();
        (is_white ? rw : rb) += x * mean(r, c);
      }
    if (!cv::solve(nb, rb, black, cv::DECOMP_LU) || !cv::solve(nw, rw, white, cv::DECOMP_LU)) return {};
    bool apart = true;
    auto level = [](const cv::Matx31d& f, int r, int c) { return f(0) + f(1) * c + f(2) * r; };
    for (int r = 0; r < cells && apart; ++r)
      for (int c = 0; c < cells && apart; ++c) apart = level(white, r, c) - level(black, r, c) >= p.otsu_min_stddev;
    if (!apart) return {};
    cv::Mat next = majority_bits(warp, cells, p, [&](int r, int c) {
      return 0.5 * (level(black, r, c) + level(white, r, c));
    });
    const bool same = cv::countNonZero(next != cls) == 0;
    cls = next;
    if (same) break;
  }
  return cls;
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
