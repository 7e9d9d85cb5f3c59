// AVX2 kernels, with POPCNT (built with -mavx2 -mpopcnt): see kernels.hpp for what each does. Each gives plain's
// bits; a row's tail shorter than a vector is finished by the level below's kernel.
#include "detect/kernels/levels.hpp"

#include <immintrin.h>

// Highway's AVX2 target as this file's flags give it: AVX2, without the FMA, BMI2, F16C, PCLMUL and AES that
// Highway's own AVX2 target also assumes (none of its ops used here needs them).
#define HWY_DISABLE_BMI2_FMA
#define HWY_DISABLE_F16C
#define HWY_DISABLE_PCLMUL_AES
#include <hwy/highway.h>

#include <cstring>

namespace arwb::kernels::avx2 {
namespace {

#include "detect/kernels/code_scan.inl"
#include "detect/kernels/runs.inl"
#include "detect/kernels/small_regions.inl"
#include "detect/kernels/hwy_rows.inl"
static_assert(HWY_STATIC_TARGET == HWY_AVX2, "Highway compiles for AVX2 here");

// box_mean's words, 16 a vector (box_mean.inl).
struct Words16 {
  using V = __m256i;
  static constexpr int kLanes = 16;
  static V load(const uint16_t* at) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(at)); }
  static void store(uint16_t* at, V v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(at), v); }
  static V add(V a, V b) { return _mm256_add_epi16(a, b); }
  static V sub(V a, V b) { return _mm256_sub_epi16(a, b); }
  static V splat(uint16_t v) { return _mm256_set1_epi16(short(v)); }
  static void widen(const uint8_t* in, uint16_t* out) {
    store(out, _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in))));
  }
  static void means(V sum, V half, V mul, int shift, uint8_t* out) {
    const __m256i mean =
        _mm256_srl_epi16(_mm256_mulhi_epu16(_mm256_add_epi16(sum, half), mul), _mm_cvtsi32_si128(shift));
    const __m256i packed = _mm256_permute4x64_epi64(_mm256_packus_epi16(mean, mean), 0x08);   // qwords 0, 2
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm256_castsi256_si128(packed));
  }
};

#include "detect/kernels/box_mean.inl"

template <bool Light>
int row_masks_k(const uint8_t* row, int w, uint64_t* out) {
  const __m256i zero = _mm256_setzero_si256();
  int c = 0;
  for (; 64 * c + 64 <= w; ++c) {
    const __m256i lo = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + 64 * c));
    const __m256i hi = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + 64 * c + 32));
    const uint64_t off = uint32_t(_mm256_movemask_epi8(_mm256_cmpeq_epi8(lo, zero))) |
                         uint64_t(uint32_t(_mm256_movemask_epi8(_mm256_cmpeq_epi8(hi, zero)))) << 32;
    out[c] = Light ? off : ~off;
  }
  return c;
}

// farthest_point's scan four points at a time with AVX2: each point a 64-bit lane (x low, y high), the measure in
// 64-bit integers from pmuldq, and per lane the first largest with its index. Returns how many points it did (a
// multiple of 4) and leaves `best`, `at` as the scan one at a time would.
template <bool Line>
int farthest_scan(const Point* c, int n, Point p0, Point dir, int64_t* best, int* at) {
  if (n < 8) return 0;
  const __m256i origin = _mm256_set1_epi64x(int64_t(uint64_t(uint32_t(p0.y)) << 32 | uint32_t(p0.x)));
  const __m256i ix = _mm256_set1_epi64x(dir.x), iy = _mm256_set1_epi64x(dir.y), zero = _mm256_setzero_si256();
  __m256i top = _mm256_set1_epi64x(-1), where = _mm256_set1_epi64x(-1);
  __m256i index = _mm256_setr_epi64x(0, 1, 2, 3);
  const __m256i four = _mm256_set1_epi64x(4);
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    const __m256i d = _mm256_sub_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + k)), origin);
    const __m256i dy = _mm256_srli_epi64(d, 32);
    __m256i m;
    if constexpr (Line) {
      const __m256i cross = _mm256_sub_epi64(_mm256_mul_epi32(dy, ix), _mm256_mul_epi32(d, iy));
      m = _mm256_blendv_epi8(cross, _mm256_sub_epi64(zero, cross), _mm256_cmpgt_epi64(zero, cross));
    } else {
      m = _mm256_add_epi64(_mm256_mul_epi32(d, d), _mm256_mul_epi32(dy, dy));
    }
    const __m256i more = _mm256_cmpgt_epi64(m, top);
    top = _mm256_blendv_epi8(top, m, more);
    where = _mm256_blendv_epi8(where, index, more);
    index = _mm256_add_epi64(index, four);
  }
  alignas(32) int64_t tops[4], wheres[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(tops), top);
  _mm256_store_si256(reinterpret_cast<__m256i*>(wheres), where);
  // The first of the largest: the largest of the lanes, the lowest index among equals.
  for (int l = 0; l < 4; ++l)
    if (tops[l] > *best || (tops[l] == *best && tops[l] >= 0 && wheres[l] < *at)) *best = tops[l], *at = int(wheres[l]);
  return k;
}

// bilinear_q8 at eight points (qx, qy in 1/256 pixel) with AVX2: each point's two pixel pairs gathered as dwords
// (so a point must lie 3 pixels inside its row's end), each pair weighed by pmaddwd, the rows blended as
// top * 256 + (bottom - top) * fy: the same integers as bilinear_q8.
inline __m256i bilinear_q8(const uint8_t* data, size_t stride, __m256i qx, __m256i qy) {
  const __m256i low = _mm256_set1_epi32(255), full = _mm256_set1_epi32(256);
  // Bytes 0 and 1 of each dword as two 16-bit lanes.
  const __m256i pair = _mm256_setr_epi8(0, -1, 1, -1, 4, -1, 5, -1, 8, -1, 9, -1, 12, -1, 13, -1, 0, -1, 1, -1, 4, -1,
                                        5, -1, 8, -1, 9, -1, 12, -1, 13, -1);
  const __m256i fx = _mm256_and_si256(qx, low), fy = _mm256_and_si256(qy, low);
  const __m256i at = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_srai_epi32(qy, 8), _mm256_set1_epi32(int(stride))),
                                      _mm256_srai_epi32(qx, 8));
  const __m256i top_pair = _mm256_shuffle_epi8(_mm256_i32gather_epi32(reinterpret_cast<const int*>(data), at, 1), pair);
  const __m256i bottom_pair =
      _mm256_shuffle_epi8(_mm256_i32gather_epi32(reinterpret_cast<const int*>(data + stride), at, 1), pair);
  const __m256i weights = _mm256_or_si256(_mm256_sub_epi32(full, fx), _mm256_slli_epi32(fx, 16));
  const __m256i top = _mm256_madd_epi16(top_pair, weights), bottom = _mm256_madd_epi16(bottom_pair, weights);
  return _mm256_add_epi32(_mm256_slli_epi32(top, 8), _mm256_mullo_epi32(_mm256_sub_epi32(bottom, top), fy));
}

}  // namespace

// AVX2: as SSSE3, four pixels a 128-bit lane: a dword permutation puts bytes 12..27 of a 32-byte load in its high
// lane, where the same shuffles find them; the packed results come out with the lanes' dwords interleaved, and one
// more permutation puts them in order.
void grey_row(const uint8_t* s, uint8_t* o, int n) {
  const __m256i bg = _mm256_broadcastsi128_si256(
      _mm_setr_epi8(0, -128, 1, -128, 3, -128, 4, -128, 6, -128, 7, -128, 9, -128, 10, -128));
  const __m256i r = _mm256_broadcastsi128_si256(
      _mm_setr_epi8(2, -128, -128, -128, 5, -128, -128, -128, 8, -128, -128, -128, 11, -128, -128, -128));
  const __m256i one = _mm256_set1_epi32(1 << 16);
  const __m256i w_bg = _mm256_set1_epi32((kGreyG << 16) | kGreyB);
  const __m256i w_r = _mm256_set1_epi32((1 << (kGreyShift - 1) << 16) | kGreyR);
  const __m256i spread = _mm256_setr_epi32(0, 1, 2, 3, 3, 4, 5, 6), order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
  int x = 0;
  // 32 pixels from four 32-byte loads 24 bytes apart: the last one reads 8 bytes past them, kept inside the row.
  for (; 3 * x + 104 <= 3 * n; x += 32) {
    __m256i sum[4];   // sum[q]: pixels 8q..8q+3 in the low lane, 8q+4..8q+7 in the high one
    for (int q = 0; q < 4; ++q) {
      const __m256i v =
          _mm256_permutevar8x32_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(s + 3 * x + 24 * q)), spread);
      const __m256i pairs_bg = _mm256_shuffle_epi8(v, bg);
      const __m256i pairs_r = _mm256_or_si256(_mm256_shuffle_epi8(v, r), one);
      sum[q] = _mm256_srli_epi32(_mm256_add_epi32(_mm256_madd_epi16(pairs_bg, w_bg), _mm256_madd_epi16(pairs_r, w_r)),
                                 kGreyShift);
    }
    const __m256i packed = _mm256_packus_epi16(_mm256_packs_epi32(sum[0], sum[1]), _mm256_packs_epi32(sum[2], sum[3]));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(o + x), _mm256_permutevar8x32_epi32(packed, order));
  }
  ssse3::grey_row(s + 3 * x, o + x, n - x);
}

// Two grey rows' 2x2 block means, 16 a step: each row's byte pairs summed by pmaddubsw with ones, the two rows
// added, rounded.
void halve_rows(const uint8_t* a, const uint8_t* b, uint8_t* o, int n) {
  const __m256i ones = _mm256_set1_epi8(1), two = _mm256_set1_epi16(2);
  int x = 0;
  for (; x + 16 <= n; x += 16) {
    const __m256i pa = _mm256_maddubs_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + 2 * x)), ones);
    const __m256i pb = _mm256_maddubs_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + 2 * x)), ones);
    const __m256i mean = _mm256_srli_epi16(_mm256_add_epi16(_mm256_add_epi16(pa, pb), two), 2);
    const __m256i packed = _mm256_permute4x64_epi64(_mm256_packus_epi16(mean, mean), 0x08);   // qwords 0, 2
    _mm_storeu_si128(reinterpret_cast<__m128i*>(o + x), _mm256_castsi256_si128(packed));
  }
  plain::halve_rows(a + 2 * x, b + 2 * x, o + x, n - x);
}


bool box_mean(const uint8_t* src, size_t src_step, int w, int h, int k, uint8_t* dst, size_t dst_step,
              uint16_t* scratch) {
  return box_mean_words<Words16>(src, src_step, w, h, k, dst, dst_step, scratch);
}

// 32 pixels (16 block means) at a time, the same arithmetic as plain's: the unpacks and packs work within each
// 128-bit lane, and the means of lane k are pixels 16k..16k+15, so the bytes come out in order.
void threshold_row(const uint16_t* v, int mw, const uint8_t* g, uint8_t* b, int offset) {
  const __m256i lift = _mm256_set1_epi8(char(offset)), round = _mm256_set1_epi16(8);
  int i = 0;
  for (; i + 16 <= mw; i += 16) {
    const __m256i c = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v + i));
    const __m256i c3 = _mm256_add_epi16(_mm256_add_epi16(_mm256_slli_epi16(c, 1), c), round);
    const __m256i even = _mm256_srli_epi16(
        _mm256_add_epi16(c3, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v + i - 1))), 4);
    const __m256i odd = _mm256_srli_epi16(
        _mm256_add_epi16(c3, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(v + i + 1))), 4);
    const __m256i mean = _mm256_packus_epi16(_mm256_unpacklo_epi16(even, odd), _mm256_unpackhi_epi16(even, odd));
    const __m256i lifted = _mm256_adds_epu8(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(g + 2 * i)), lift);
    // lifted <= mean: their maximum is the mean.
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(b + 2 * i),
                        _mm256_cmpeq_epi8(_mm256_max_epu8(lifted, mean), mean));
  }
  plain::threshold_row(v + i, mw - i, g + 2 * i, b + 2 * i, offset);
}


void blend_row(const uint8_t* near, const uint8_t* far, uint16_t* v, int n) {
  const int i = blend_row_hwy(near, far, v, n);
  plain::blend_row(near + i, far + i, v + i, n - i);
}

void row_masks(const uint8_t* row, int w, int words, uint64_t* out, bool light) {
  const int c = light ? row_masks_k<true>(row, w, out) : row_masks_k<false>(row, w, out);
  plain::row_masks(row + 64 * c, w - 64 * c, words - c, out + c, light);
}

int find_edges(const uint64_t* masks, int words, EdgeWords out) { return find_edges_body(masks, words, out); }

void join_row(EdgeWords above, int above_begin, const int* ends, int begin, int n, int* parent) {
  join_row_body(above, above_begin, ends, begin, n, parent);
}

int drop_specks(const BitRows& bits, uint64_t* scratch, bool count) {
  return drop_specks_of<VectorWords<4>>(bits, scratch, count);
}

int drop_small_regions(const BitRows& bits, int k, bool count, uint64_t* scratch) {
  return drop_small_regions_of<VectorWords<4>>(bits, k, count, scratch);
}

Farthest farthest_point(const Point* c, int n, Point p0, Point dir, bool from_line) {
  int64_t best = -1;
  int at = -1;
  const int k = from_line ? farthest_scan<true>(c, n, p0, dir, &best, &at)
                          : farthest_scan<false>(c, n, p0, dir, &best, &at);
  Farthest f{best, at};
  const Farthest rest = plain::farthest_point(c + k, n - k, p0, dir, from_line);
  if (rest.measure > f.measure) f = {rest.measure, k + rest.at};
  return f;
}

// One row of remove_perspective, eight pixels a step with AVX2: the homography in the same double operations in the
// same order (four at a time; no fused multiply-add: this target has none), truncated to 1/256 pixel, and
// bilinear_q8, rounded as the scalar loop rounds. A group with a sample outside the image, or within 3 pixels
// of its last column (the gathers read 4 bytes), is left to the scalar loop: done[g] says whether group g (pixels
// 8g..8g+7) was done here.
bool warp_row(const double* hm, double y, int side, const uint8_t* data, size_t stride, double xlimit, double ymax,
              uint8_t* row, uint8_t* done) {
  auto H = [hm](int r, int c) { return hm[3 * r + c]; };
  const __m256d h00 = _mm256_set1_pd(H(0, 0)), h01y = _mm256_set1_pd(H(0, 1) * y), h02 = _mm256_set1_pd(H(0, 2));
  const __m256d h10 = _mm256_set1_pd(H(1, 0)), h11y = _mm256_set1_pd(H(1, 1) * y), h12 = _mm256_set1_pd(H(1, 2));
  const __m256d h20 = _mm256_set1_pd(H(2, 0)), h21y = _mm256_set1_pd(H(2, 1) * y), h22 = _mm256_set1_pd(H(2, 2));
  const __m256d one = _mm256_set1_pd(1.0), zero = _mm256_setzero_pd(), q8 = _mm256_set1_pd(256.0);
  const __m256d xmax = _mm256_set1_pd(xlimit), ymaxv = _mm256_set1_pd(ymax);
  const __m256i round = _mm256_set1_epi32(32768);
  const __m256i bytes = _mm256_setr_epi8(0, 4, 8, 12, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 4, 8, 12, -1,
                                         -1, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
  for (int u = 0, g = 0; u + 8 <= side; u += 8, ++g) {
    __m128i qx[2], qy[2];
    int inside = 0xFF;
    for (int h = 0; h < 2; ++h) {
      const double x0 = u + 4 * h + 0.5;
      const __m256d x = _mm256_setr_pd(x0, x0 + 1, x0 + 2, x0 + 3);
      // As the scalar loop: H(r,0) * x + H(r,1) * y + H(r,2), left to right.
      const __m256d w = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(h20, x), h21y), h22);
      const __m256d inv_w = _mm256_div_pd(one, w);
      const __m256d px = _mm256_mul_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(h00, x), h01y), h02), inv_w);
      const __m256d py = _mm256_mul_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(h10, x), h11y), h12), inv_w);
      const __m256d in = _mm256_and_pd(
          _mm256_and_pd(_mm256_cmp_pd(px, zero, _CMP_GE_OQ), _mm256_cmp_pd(py, zero, _CMP_GE_OQ)),
          _mm256_and_pd(_mm256_cmp_pd(px, xmax, _CMP_LT_OQ), _mm256_cmp_pd(py, ymaxv, _CMP_LT_OQ)));
      inside &= _mm256_movemask_pd(in) << (4 * h) | (h == 0 ? 0xF0 : 0x0F);
      qx[h] = _mm256_cvttpd_epi32(_mm256_mul_pd(px, q8));
      qy[h] = _mm256_cvttpd_epi32(_mm256_mul_pd(py, q8));
    }
    done[g] = inside == 0xFF;
    if (!done[g]) continue;
    const __m256i value = bilinear_q8(data, stride, _mm256_set_m128i(qx[1], qx[0]), _mm256_set_m128i(qy[1], qy[0]));
    const __m256i level = _mm256_shuffle_epi8(_mm256_srli_epi32(_mm256_add_epi32(value, round), 16), bytes);
    const int lo = _mm256_cvtsi256_si32(level), hi = _mm256_extract_epi32(level, 4);
    std::memcpy(row + u, &lo, 4);
    std::memcpy(row + u + 4, &hi, 4);
  }
  return true;
}

// sample_line's samples 8 at a time along a line (x, y, dx, dy in 1/65536 pixel, as int32) with AVX2. Returns how
// many it did (a multiple of 8).
int sample_line(const uint8_t* data, size_t stride, int x, int y, int dx, int dy, int n, int* out) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  __m256i vx = _mm256_add_epi32(_mm256_set1_epi32(x), _mm256_mullo_epi32(lane, _mm256_set1_epi32(dx)));
  __m256i vy = _mm256_add_epi32(_mm256_set1_epi32(y), _mm256_mullo_epi32(lane, _mm256_set1_epi32(dy)));
  const __m256i step_x = _mm256_set1_epi32(8 * dx), step_y = _mm256_set1_epi32(8 * dy);
  int j = 0;
  for (; j + 8 <= n; j += 8) {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + j),
                        bilinear_q8(data, stride, _mm256_srai_epi32(vx, 8), _mm256_srai_epi32(vy, 8)));
    vx = _mm256_add_epi32(vx, step_x);
    vy = _mm256_add_epi32(vy, step_y);
  }
  return j;
}

// The eight profiles in the lanes of AVX2 vectors, sample j of each gathered at once; as the plain loop lane by lane
// (AVX2 without FMA: w * j is rounded before it is added, as there).
void profile_edges(const int* profiles, const int* first, int samples, int* spread, double* wsum, double* jsum,
                   int* steps) {
  const __m256i at = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(first));
  // steps: next - now for each j, eight at a time, kept for the second pass
  __m256i now = _mm256_i32gather_epi32(profiles, at, 4), peak = _mm256_setzero_si256(), lo = now, hi = now;
  for (int j = 0; j + 1 < samples; ++j) {
    const __m256i next = _mm256_i32gather_epi32(profiles + j + 1, at, 4);
    const __m256i step = _mm256_sub_epi32(next, now);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(steps + 8 * j), step);
    peak = _mm256_max_epi32(peak, step);
    lo = _mm256_min_epi32(lo, now);
    hi = _mm256_max_epi32(hi, now);
    now = next;
  }
  const __m256d fifth = _mm256_set1_pd(0.2), zero = _mm256_setzero_pd();
  const __m256d floor0 = _mm256_mul_pd(fifth, _mm256_cvtepi32_pd(_mm256_castsi256_si128(peak)));
  const __m256d floor1 = _mm256_mul_pd(fifth, _mm256_cvtepi32_pd(_mm256_extracti128_si256(peak, 1)));
  __m256d ws0 = zero, ws1 = zero, js0 = zero, js1 = zero;
  for (int j = 0; j + 1 < samples; ++j) {
    const __m256i step = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(steps + 8 * j));
    const __m256d w0 = _mm256_max_pd(_mm256_sub_pd(_mm256_cvtepi32_pd(_mm256_castsi256_si128(step)), floor0), zero);
    const __m256d w1 =
        _mm256_max_pd(_mm256_sub_pd(_mm256_cvtepi32_pd(_mm256_extracti128_si256(step, 1)), floor1), zero);
    const __m256d jj = _mm256_set1_pd(double(j));
    ws0 = _mm256_add_pd(ws0, w0);
    ws1 = _mm256_add_pd(ws1, w1);
    js0 = _mm256_add_pd(js0, _mm256_mul_pd(w0, jj));
    js1 = _mm256_add_pd(js1, _mm256_mul_pd(w1, jj));
  }
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(spread), _mm256_sub_epi32(hi, lo));
  _mm256_storeu_pd(wsum, ws0);
  _mm256_storeu_pd(wsum + 4, ws1);
  _mm256_storeu_pd(jsum, js0);
  _mm256_storeu_pd(jsum + 4, js1);
}

CodeMatch nearest_code(const uint64_t* codes, int n, uint64_t code) { return scan_nearest(codes, n, code); }

void nearest_per_rotation(const uint64_t* codes, int n, uint64_t code, CodeMatch* out4) {
  scan_per_rotation(codes, n, code, out4);
}

}  // namespace arwb::kernels::avx2
