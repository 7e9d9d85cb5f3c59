// AVX-512 F, BW and VL kernels (built with -mavx512f -mavx512bw -mavx512vl -mpopcnt): see kernels.hpp for what each
// does. Each gives plain's bits; a row's tail shorter than a vector is finished by the level below's kernel.
#include "detect/kernels/levels.hpp"

#include <immintrin.h>

#include <climits>

// GCC 12's AVX-512 shifts, conversions and reductions start from _mm512_undefined_epi32(), which it then calls maybe
// uninitialised (a known false warning) in every function that uses them.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#endif

namespace arwb::kernels::avx512 {
namespace {

// A row's whole words of masks: AVX-512's byte test gives a word in one instruction. Returns the words done.
template <bool Light>
int row_masks_k(const uint8_t* row, int w, uint64_t* out) {
  int c = 0;
  for (; 64 * c + 64 <= w; ++c) {
    const __m512i v = _mm512_loadu_si512(row + 64 * c);
    out[c] = Light ? _mm512_testn_epi8_mask(v, v) : _mm512_test_epi8_mask(v, v);
  }
  return c;
}

// Sixteen points a step in two vectors of eight, each keeping its lanes' first largest; vpabsq for the line's
// distance.
template <bool Line>
Farthest farthest_scan(const Point* c, int n, Point p0, Point dir) {
  const __m512i origin = _mm512_set1_epi64(int64_t(uint64_t(uint32_t(p0.y)) << 32 | uint32_t(p0.x)));
  const __m512i ix = _mm512_set1_epi64(dir.x), iy = _mm512_set1_epi64(dir.y);
  __m512i top[2] = {_mm512_set1_epi64(-1), _mm512_set1_epi64(-1)}, where[2] = {top[0], top[0]};
  __m512i index[2] = {_mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7), _mm512_setr_epi64(8, 9, 10, 11, 12, 13, 14, 15)};
  const __m512i sixteen = _mm512_set1_epi64(16);
  for (int k = 0; k < n; k += 16)
    for (int h = 0; h < 2; ++h) {
      // The points left from k + 8h, at most eight: a masked load, so a piece of any length takes this path.
      const int left = n - k - 8 * h < 0 ? 0 : n - k - 8 * h > 8 ? 8 : n - k - 8 * h;
      const __mmask8 valid = __mmask8((1u << left) - 1);
      const __m512i d = _mm512_sub_epi32(_mm512_maskz_loadu_epi64(valid, c + (k + 8 * h < n ? k + 8 * h : n)), origin);
      const __m512i dy = _mm512_srli_epi64(d, 32);
      const __m512i m = Line ? _mm512_abs_epi64(_mm512_sub_epi64(_mm512_mul_epi32(dy, ix), _mm512_mul_epi32(d, iy)))
                             : _mm512_add_epi64(_mm512_mul_epi32(d, d), _mm512_mul_epi32(dy, dy));
      const __mmask8 more = _mm512_mask_cmpgt_epi64_mask(valid, m, top[h]);
      top[h] = _mm512_mask_mov_epi64(top[h], more, m);
      where[h] = _mm512_mask_mov_epi64(where[h], more, index[h]);
      index[h] = _mm512_add_epi64(index[h], sixteen);
    }
  // The first of the largest: the largest of the lanes, the lowest index among the lanes that have it (a
  // reduction in the vectors, where a loop over the sixteen lanes branched on each).
  const int64_t best = _mm512_reduce_max_epi64(_mm512_max_epi64(top[0], top[1]));
  const __m512i all = _mm512_set1_epi64(best);
  const __m512i first = _mm512_min_epi64(
      _mm512_mask_mov_epi64(_mm512_set1_epi64(INT64_MAX), _mm512_cmpeq_epi64_mask(top[0], all), where[0]),
      _mm512_mask_mov_epi64(_mm512_set1_epi64(INT64_MAX), _mm512_cmpeq_epi64_mask(top[1], all), where[1]));
  return {best, best < 0 ? -1 : int(_mm512_reduce_min_epi64(first))};
}

}  // namespace

// 32 block means a step, made as AVX2's and narrowed by vpmovwb.
void halve_rows(const uint8_t* a, const uint8_t* b, uint8_t* o, int n) {
  const __m512i ones = _mm512_set1_epi8(1), two = _mm512_set1_epi16(2);
  int x = 0;
  for (; x + 32 <= n; x += 32) {
    const __m512i pa = _mm512_maddubs_epi16(_mm512_loadu_si512(a + 2 * x), ones);
    const __m512i pb = _mm512_maddubs_epi16(_mm512_loadu_si512(b + 2 * x), ones);
    const __m512i mean = _mm512_srli_epi16(_mm512_add_epi16(_mm512_add_epi16(pa, pb), two), 2);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(o + x), _mm512_cvtepi16_epi8(mean));
  }
  avx2::halve_rows(a + 2 * x, b + 2 * x, o + x, n - x);
}

// AVX2's 16 block means a step as 32 (a 128-bit lane's means still make its 16 pixels), the comparison into a mask
// register and out as bytes.
void threshold_row(const uint16_t* v, int mw, const uint8_t* g, uint8_t* b, int offset) {
  const __m512i lift = _mm512_set1_epi8(char(offset)), round = _mm512_set1_epi16(8);
  int i = 0;
  for (; i + 32 <= mw; i += 32) {
    const __m512i c = _mm512_loadu_si512(v + i);
    const __m512i c3 = _mm512_add_epi16(_mm512_add_epi16(_mm512_slli_epi16(c, 1), c), round);
    const __m512i even = _mm512_srli_epi16(_mm512_add_epi16(c3, _mm512_loadu_si512(v + i - 1)), 4);
    const __m512i odd = _mm512_srli_epi16(_mm512_add_epi16(c3, _mm512_loadu_si512(v + i + 1)), 4);
    const __m512i mean = _mm512_packus_epi16(_mm512_unpacklo_epi16(even, odd), _mm512_unpackhi_epi16(even, odd));
    const __m512i lifted = _mm512_adds_epu8(_mm512_loadu_si512(g + 2 * i), lift);
    _mm512_storeu_si512(b + 2 * i, _mm512_movm_epi8(_mm512_cmple_epu8_mask(lifted, mean)));
  }
  avx2::threshold_row(v + i, mw - i, g + 2 * i, b + 2 * i, offset);
}

// 32 a step.
void blend_row(const uint8_t* near, const uint8_t* far, uint16_t* v, int mw) {
  int i = 0;
  for (; i + 32 <= mw; i += 32) {
    const __m512i n = _mm512_cvtepu8_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(near + i)));
    const __m512i f = _mm512_cvtepu8_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(far + i)));
    _mm512_storeu_si512(v + i, _mm512_add_epi16(_mm512_add_epi16(_mm512_slli_epi16(n, 1), n), f));
  }
  avx2::blend_row(near + i, far + i, v + i, mw - i);
}

void row_masks(const uint8_t* row, int w, int words, uint64_t* out, bool light) {
  const int c = light ? row_masks_k<true>(row, w, out) : row_masks_k<false>(row, w, out);
  plain::row_masks(row + 64 * c, w - 64 * c, words - c, out + c, light);
}

// The pixels of each 16 edge bits compressed at once, with no branch.
int row_edges(const uint64_t* edge_bits, int words, int* out) {
  int n = 0;
  const __m512i sixteen = _mm512_set1_epi32(16);
  __m512i x = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  for (int c = 0; c < words; ++c) {
    const uint64_t e = edge_bits[c];
    if (e == 0) {   // no edge (most words): nothing to compress
      x = _mm512_add_epi32(x, _mm512_set1_epi32(64));
      continue;
    }
    // Where each 16 bits' pixels go, from the edges before them in the word (no chain of counts through the
    // stores).
    const int at[4] = {n, n + __builtin_popcountll(e & 0xFFFF), n + __builtin_popcountll(e & 0xFFFFFFFF),
                       n + __builtin_popcountll(e & 0xFFFFFFFFFFFF)};
    for (int q = 0; q < 4; ++q) {
      _mm512_storeu_si512(out + at[q], _mm512_maskz_compress_epi32(__mmask16(e >> (16 * q)), x));
      x = _mm512_add_epi32(x, sixteen);
    }
    n += __builtin_popcountll(e);
  }
  return n;
}

Farthest farthest_point(const Point* c, int n, Point p0, Point dir, bool from_line) {
  return from_line ? farthest_scan<true>(c, n, p0, dir) : farthest_scan<false>(c, n, p0, dir);
}

}  // namespace arwb::kernels::avx512
