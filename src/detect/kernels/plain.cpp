// The plain kernels: the reference every level is checked against, C++ at the compiler's baseline. Where OpenCV's
// universal intrinsics pay they are used (128 bits here: SSE2 on x86-64, NEON on ARM, SIMD128 in WebAssembly; the
// scalar loops alone where the target has none), and those loops end in the same scalar code as their tails. This
// file is built with the project's own flags only, so it may use anything.
#include "detect/kernels/levels.hpp"

#include <opencv2/core.hpp>   // what intrin.hpp uses and does not include (CV_DbgAssert, isAligned)
#include <opencv2/core/hal/intrin.hpp>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace arwb::kernels::plain {
namespace {

// drop_small_regions' words, one at a time (small_regions.inl).
struct Scalar {
  using V = uint64_t;
  static constexpr int kWords = 1;
  static V load(const uint64_t* at) { return *at; }
  static void store(uint64_t* at, V v) { *at = v; }
  template <int S> static V left(V v) { return v << S; }
  template <int S> static V right(V v) { return v >> S; }
  static int bits(V v) { return __builtin_popcountll(v); }
};

#include "detect/kernels/code_scan.inl"
#include "detect/kernels/runs.inl"
#include "detect/kernels/small_regions.inl"

// One row of block means: the block's rows summed first, then each block's columns, rounded to the nearest. F is a
// template argument for the factors the parameters allow, so the division by the block's area is a constant's.
// For 3 and 4 both sums are vectorised (the 3x3 sum, at most 2295, divided by 9 as a 16-bit multiply-high by 7282:
// exact for every sum, checked over all of them by the tests' decimation case). F = 0 takes `factor` at run time.
template <int F>
void decimate_rows(const uint8_t* grey, size_t step, int factor, uint8_t* out, size_t out_step, int out_cols,
                   int out_rows) {
  const int f = F > 0 ? F : factor;
  const int cols = out_cols * f;
  thread_local std::vector<uint16_t> sum_buf;
  sum_buf.resize(static_cast<size_t>(cols));
  uint16_t* sum = sum_buf.data();
  const uint32_t area = uint32_t(f * f);
  auto row = [&](int y) { return grey + size_t(y) * step; };
  for (int y = 0; y < out_rows; ++y) {
    int x = 0;
#if CV_SIMD128
    for (; x + 8 <= cols; x += 8) {
      cv::v_uint16x8 acc = cv::v_load_expand(row(y * f) + x);
      for (int k = 1; k < f; ++k) acc += cv::v_load_expand(row(y * f + k) + x);
      cv::v_store(sum + x, acc);
    }
#endif
    for (; x < cols; ++x) {
      uint16_t acc = 0;
      for (int k = 0; k < f; ++k) acc = uint16_t(acc + row(y * f + k)[x]);
      sum[x] = acc;
    }
    uint8_t* o = out + size_t(y) * out_step;
    int ox = 0;
#if CV_SIMD128
    if constexpr (F == 3) {
      for (; ox + 8 <= out_cols; ox += 8) {
        cv::v_uint16x8 a, b, c;
        cv::v_load_deinterleave(sum + 3 * ox, a, b, c);
        cv::v_pack_store(o + ox, cv::v_mul_hi(a + b + c + cv::v_setall_u16(4), cv::v_setall_u16(7282)));
      }
    } else if constexpr (F == 4) {
      for (; ox + 8 <= out_cols; ox += 8) {
        cv::v_uint16x8 a, b, c, d;
        cv::v_load_deinterleave(sum + 4 * ox, a, b, c, d);
        cv::v_pack_store(o + ox, (a + b + c + d + cv::v_setall_u16(8)) >> 4);
      }
    }
#endif
    for (; ox < out_cols; ++ox) {
      uint32_t block = 0;
      for (int k = 0; k < f; ++k) block += sum[size_t(ox * f + k)];
      o[ox] = uint8_t((block + area / 2) / area);
    }
  }
}

// n pixels of C channels (B, G, R first, or R, G, B when rgb) to grey. The vector loop takes cvtColor's sum as two
// 16-bit dot products per pixel, (c0, c1) . (w0, wG) + (c2, 1) . (w2, 2^14), which is exact in 32 bits.
template <int C>
void grey_pixels(const uint8_t* px, uint8_t* grey, int n, bool rgb) {
  const int w0 = rgb ? kGreyR : kGreyB, w2 = rgb ? kGreyB : kGreyR;
  int x = 0;
#if CV_SIMD128
  static_assert(kGreyG < 32768 && (1 << (kGreyShift - 1)) < 32768, "the weights are 16-bit lanes");
  const cv::v_int16x8 w01 = cv::v_reinterpret_as_s16(cv::v_setall_u32(uint32_t(w0) | uint32_t(kGreyG) << 16));
  const cv::v_int16x8 w2h =
      cv::v_reinterpret_as_s16(cv::v_setall_u32(uint32_t(w2) | uint32_t(1 << (kGreyShift - 1)) << 16));
  const cv::v_int16x8 one = cv::v_setall_s16(1);
  auto eight = [&](const cv::v_uint16x8& c0, const cv::v_uint16x8& c1, const cv::v_uint16x8& c2) {
    cv::v_int16x8 p0, p1, q0, q1;
    cv::v_zip(cv::v_reinterpret_as_s16(c0), cv::v_reinterpret_as_s16(c1), p0, p1);
    cv::v_zip(cv::v_reinterpret_as_s16(c2), one, q0, q1);
    const cv::v_int32x4 lo = cv::v_dotprod(p0, w01) + cv::v_dotprod(q0, w2h);
    const cv::v_int32x4 hi = cv::v_dotprod(p1, w01) + cv::v_dotprod(q1, w2h);
    return cv::v_pack(lo >> kGreyShift, hi >> kGreyShift);
  };
  for (; x + 16 <= n; x += 16) {
    cv::v_uint8x16 c0, c1, c2, c3;
    if constexpr (C == 3) cv::v_load_deinterleave(px + 3 * x, c0, c1, c2);
    else cv::v_load_deinterleave(px + 4 * x, c0, c1, c2, c3);
    cv::v_uint16x8 a0, a1, b0, b1, d0, d1;
    cv::v_expand(c0, a0, a1);
    cv::v_expand(c1, b0, b1);
    cv::v_expand(c2, d0, d1);
    cv::v_store(grey + x, cv::v_pack_u(eight(a0, b0, d0), eight(a1, b1, d1)));
  }
#endif
  for (; x < n; ++x) {
    const uint8_t* s = px + C * x;
    grey[x] = uint8_t((w0 * s[0] + kGreyG * s[1] + w2 * s[2] + (1 << (kGreyShift - 1))) >> kGreyShift);
  }
}

// Bit k set where pixel x + k of the row is on (nonzero; zero when Light), for the up to 64 pixels from x; none
// past w.
template <bool Light>
uint64_t row_mask(const uint8_t* row, int x, int w) {
  uint64_t m = 0;
  int k = 0;
#if CV_SIMD128
  // Compared with zero, a lane is all ones where its pixel is nonzero: the sign bits are the mask, 16 pixels at a
  // time while they are inside the row (a row's last word too: coarse_search's rows can end half-way through one).
  const cv::v_uint8x16 zero = cv::v_setzero_u8();
  for (; k < 64 && x + k + 16 <= w; k += 16)
    m |= uint64_t(uint32_t(cv::v_signmask(cv::v_load(row + x + k) > zero))) << k;
  if (Light) m = ~m & (k == 64 ? ~uint64_t(0) : (uint64_t(1) << k) - 1);
#endif
  for (; k < 64 && x + k < w; ++k) m |= uint64_t((row[x + k] != 0) != Light) << k;
  return m;
}

}  // namespace

void grey_row(const uint8_t* bgr, uint8_t* grey, int n) { grey_pixels<3>(bgr, grey, n, false); }

void grey_row4(const uint8_t* px, uint8_t* grey, int n, bool rgba) { grey_pixels<4>(px, grey, n, rgba); }

void halve_rows(const uint8_t* a, const uint8_t* b, uint8_t* out, int n) {
  for (int x = 0; x < n; ++x) out[x] = uint8_t((a[2 * x] + a[2 * x + 1] + b[2 * x] + b[2 * x + 1] + 2) >> 2);
}

void decimate(const uint8_t* grey, size_t step, int factor, uint8_t* out, size_t out_step, int out_cols,
              int out_rows) {
  switch (factor) {
    case 3: decimate_rows<3>(grey, step, factor, out, out_step, out_cols, out_rows); break;
    case 4: decimate_rows<4>(grey, step, factor, out, out_step, out_cols, out_rows); break;
    case 5: decimate_rows<5>(grey, step, factor, out, out_step, out_cols, out_rows); break;
    case 6: decimate_rows<6>(grey, step, factor, out, out_step, out_cols, out_rows); break;
    default: decimate_rows<0>(grey, step, factor, out, out_step, out_cols, out_rows); break;
  }
}

bool box_mean(const uint8_t*, size_t, int, int, int, uint8_t*, size_t, uint16_t*) { return false; }

void blend_row(const uint8_t* near, const uint8_t* far, uint16_t* v, int n) {
  int i = 0;
#if CV_SIMD
  for (; i + cv::v_uint16::nlanes <= n; i += cv::v_uint16::nlanes) {
    const cv::v_uint16 a = cv::vx_load_expand(near + i), f = cv::vx_load_expand(far + i);
    cv::v_store(v + i, (a << 1) + a + f);
  }
#endif
  for (; i < n; ++i) v[i] = uint16_t(3 * near[i] + far[i]);
}

void threshold_row(const uint16_t* v, int mw, const uint8_t* g, uint8_t* b, int offset) {
  int i = 0;
#if CV_SIMD
  // + on 8-bit lanes saturates, <= gives 0xFF or 0; v_pack saturates (the means are at most 255 anyway).
  const cv::v_uint8 lift = cv::vx_setall_u8(uint8_t(offset));
  const cv::v_uint16 round = cv::vx_setall_u16(8);
  for (; i + cv::v_uint16::nlanes <= mw; i += cv::v_uint16::nlanes) {
    const cv::v_uint16 c = cv::vx_load(v + i), c3 = (c << 1) + c + round;
    const cv::v_uint16 even = (c3 + cv::vx_load(v + i - 1)) >> 4, odd = (c3 + cv::vx_load(v + i + 1)) >> 4;
    cv::v_uint16 lo, hi;
    cv::v_zip(even, odd, lo, hi);
    cv::v_store(b + 2 * i, (cv::vx_load(g + 2 * i) + lift) <= cv::v_pack(lo, hi));
  }
#endif
  auto put = [&](int x, int m) { b[x] = std::min(g[x] + offset, 255) <= m ? 255 : 0; };
  for (; i < mw; ++i) {
    put(2 * i, (3 * v[i] + v[i - 1] + 8) >> 4);
    put(2 * i + 1, (3 * v[i] + v[i + 1] + 8) >> 4);
  }
}

void row_masks(const uint8_t* row, int w, int words, uint64_t* out, bool light) {
  for (int c = 0; c < words; ++c) out[c] = light ? row_mask<true>(row, 64 * c, w) : row_mask<false>(row, 64 * c, w);
}

int find_edges(const uint64_t* masks, int words, EdgeWords out) { return find_edges_body(masks, words, out); }

// Visiting the set bits by counting trailing zeros mispredicts once a word, when its bits run out (scanning byte by
// byte mispredicted at every edge).
int row_edges(const uint64_t* edge_bits, int words, int* out) {
  int n = 0;
  for (int c = 0, x = 0; c < words; ++c, x += 64)
    for (uint64_t e = edge_bits[c]; e; e &= e - 1) out[n++] = x + __builtin_ctzll(e);
  return n;
}

void join_row(EdgeWords above, int above_begin, const int* ends, int begin, int n, int* parent) {
  join_row_body(above, above_begin, ends, begin, n, parent);
}

int drop_specks(const BitRows& bits, uint64_t* scratch, bool count) {
  return drop_specks_of<Scalar>(bits, scratch, count);
}

int drop_small_regions(const BitRows& bits, int k, bool count, uint64_t* scratch) {
  return drop_small_regions_of<Scalar>(bits, k, count, scratch);
}

Farthest farthest_point(const Point* c, int n, Point p0, Point dir, bool from_line) {
  Farthest f;
  for (int k = 0; k < n; ++k) {
    const int64_t dx = c[k].x - p0.x, dy = c[k].y - p0.y;
    const int64_t m = from_line ? std::abs(dy * dir.x - dx * dir.y) : dx * dx + dy * dy;
    if (m > f.measure) f = {m, k};
  }
  return f;
}

bool warp_row(const double*, double, int, const uint8_t*, size_t, double, double, uint8_t*, uint8_t*) {
  return false;
}

int sample_line(const uint8_t*, size_t, int, int, int, int, int, int*) { return 0; }

// Each profile's sums are added in the order of its samples, a step at or below the floor adding +0.
void profile_edges(const int* profiles, const int* first, int samples, int* spread, double* wsum, double* jsum,
                   int*) {
  for (int q = 0; q < 8; ++q) {
    const int* v = profiles + first[q];
    int peak = 0, lo = v[0], hi = v[0];
    for (int j = 0; j + 1 < samples; ++j) {
      peak = std::max(peak, v[j + 1] - v[j]);
      lo = std::min(lo, v[j]);
      hi = std::max(hi, v[j]);
    }
    const double floor = 0.2 * peak;
    double ws = 0, js = 0;
    for (int j = 0; j + 1 < samples; ++j) {
      const double w = std::max(double(v[j + 1] - v[j]) - floor, 0.0);
      ws += w;
      js += w * j;
    }
    spread[q] = hi - lo;
    wsum[q] = ws;
    jsum[q] = js;
  }
}

CodeMatch nearest_code(const uint64_t* codes, int n, uint64_t code) { return scan_nearest(codes, n, code); }

void nearest_per_rotation(const uint64_t* codes, int n, uint64_t code, CodeMatch* out4) {
  scan_per_rotation(codes, n, code, out4);
}

}  // namespace arwb::kernels::plain
