// AVX-512 kernels with VBMI, VNNI and VPOPCNTDQ (built with -mavx512f -mavx512bw -mavx512vl -mavx512vbmi
// -mavx512vnni -mavx512vpopcntdq -mpopcnt): see kernels.hpp for what each does. Each gives plain's bits.
#include "detect/kernels/levels.hpp"

#include <immintrin.h>

// As in avx512.cpp: GCC 12's false "maybe uninitialised" on its own AVX-512 intrinsics.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace arwb::kernels::avx512vbmi {
namespace {

// grey_row's byte permutations. [0]: B and G of pixel k to bytes 4k and 4k + 2; [1]: R to 4k; [2] and [3] the same
// from 16 bytes further into the vector.
struct GreyIndex {
  alignas(64) uint8_t ix[4][64];
};
constexpr GreyIndex grey_index() {
  GreyIndex g{};
  for (int shift = 0; shift <= 16; shift += 16)
    for (int k = 0; k < 16; ++k) {
      g.ix[shift / 8][4 * k] = uint8_t(shift + 3 * k);
      g.ix[shift / 8][4 * k + 2] = uint8_t(shift + 3 * k + 1);
      g.ix[shift / 8 + 1][4 * k] = uint8_t(shift + 3 * k + 2);
    }
  return g;
}
constexpr GreyIndex kIndex = grey_index();

}  // namespace

// 16 pixels a 512-bit vector, 64 a step. vpermb takes each pixel's B and G, and its R, to the 16-bit halves of its
// own dword from anywhere in the vector, zeroing the bytes between (a zeroing mask), so the shuffles are two a 16
// pixels, not the three a 8 of AVX2's; vpdpwssd weighs and sums the pairs onto the rounding.
void grey_row(const uint8_t* s, uint8_t* o, int n) {
  const __m512i take_bg = _mm512_load_si512(kIndex.ix[0]), take_r = _mm512_load_si512(kIndex.ix[1]);
  const __mmask64 bytes_bg = 0x5555555555555555ull, bytes_r = 0x1111111111111111ull;
  const __m512i w_bg = _mm512_set1_epi32((kGreyG << 16) | kGreyB), w_r = _mm512_set1_epi32(kGreyR);
  const __m512i round = _mm512_set1_epi32(1 << (kGreyShift - 1));
  // After the packs, 128-bit lane L holds pixels 4L..4L+3 of each 16 in turn: dword 4L + q goes to 4q + L.
  const __m512i order = _mm512_setr_epi32(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15);
  int x = 0;
  // Four 64-byte loads 48 bytes apart: the last reads 16 bytes past the 64 pixels while that is inside the row;
  // the row's last 64 pixels take their last 48 bytes from a load that ends with them.
  const __m512i take_bg_end = _mm512_load_si512(kIndex.ix[2]), take_r_end = _mm512_load_si512(kIndex.ix[3]);
  for (; 3 * x + 192 <= 3 * n; x += 64) {
    const bool inside = 3 * x + 208 <= 3 * n;
    __m512i sum[4];
    for (int q = 0; q < 4; ++q) {
      const bool end = q == 3 && !inside;
      const __m512i v = _mm512_loadu_si512(s + 3 * x + 48 * q - (end ? 16 : 0));
      const __m512i bg = _mm512_maskz_permutexvar_epi8(bytes_bg, end ? take_bg_end : take_bg, v);
      const __m512i r = _mm512_maskz_permutexvar_epi8(bytes_r, end ? take_r_end : take_r, v);
      sum[q] = _mm512_srli_epi32(_mm512_dpwssd_epi32(_mm512_dpwssd_epi32(round, bg, w_bg), r, w_r), kGreyShift);
    }
    const __m512i packed = _mm512_packus_epi16(_mm512_packs_epi32(sum[0], sum[1]), _mm512_packs_epi32(sum[2], sum[3]));
    _mm512_storeu_si512(o + x, _mm512_permutexvar_epi32(order, packed));
  }
  avx2::grey_row(s + 3 * x, o + x, n - x);
}

// scan_nearest eight codes a step with vpopcntq: the lanes keep their first nearest, the lowest index among equals
// wins, and the first exact match returns at once, as there.
CodeMatch nearest_code(const uint64_t* flat, int ids, uint64_t code) {
  const int n = ids * 4;
  const __m512i target = _mm512_set1_epi64(int64_t(code)), zero = _mm512_setzero_si512(), eight = _mm512_set1_epi64(8);
  __m512i best = _mm512_set1_epi64(65), where = _mm512_set1_epi64(-1);
  __m512i index = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
  int i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m512i d = _mm512_popcnt_epi64(_mm512_xor_si512(_mm512_loadu_si512(flat + i), target));
    if (const __mmask8 exact = _mm512_cmpeq_epi64_mask(d, zero)) {
      const int at = i + __builtin_ctz(unsigned(exact));
      return {at / 4, at % 4, 0};
    }
    const __mmask8 nearer = _mm512_cmplt_epi64_mask(d, best);
    best = _mm512_mask_mov_epi64(best, nearer, d);
    where = _mm512_mask_mov_epi64(where, nearer, index);
    index = _mm512_add_epi64(index, eight);
  }
  alignas(64) int64_t bests[8], wheres[8];
  _mm512_store_si512(bests, best);
  _mm512_store_si512(wheres, where);
  int64_t hamming = 65, at = -1;
  for (int l = 0; l < 8; ++l)
    if (bests[l] < hamming || (bests[l] == hamming && wheres[l] < at)) hamming = bests[l], at = wheres[l];
  CodeMatch m{-1, 0, 65};
  if (at >= 0) m = {int(at / 4), int(at % 4), int(hamming)};
  for (; i < n; ++i) {   // the rest, one at a time (ids come in fours: none, unless the list is empty)
    const int d = __builtin_popcountll(code ^ flat[i]);
    if (d < m.hamming) m = {i / 4, i % 4, d};
  }
  return m;
}

}  // namespace arwb::kernels::avx512vbmi
