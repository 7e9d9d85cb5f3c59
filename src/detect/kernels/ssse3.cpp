// SSSE3 kernels (built with -mssse3): see kernels.hpp for what each does and levels.hpp for the level's list.
#include "detect/kernels/levels.hpp"

#include <immintrin.h>

namespace arwb::kernels::ssse3 {
// SSSE3: n pixels of a row, 16 from 48 bytes at a time. Four pixels (12 bytes, brought to a vector's start by
// palignr) at a time: one byte shuffle makes their B and G 16-bit pairs, another their R with a 1 beside it (the
// rounding's weight), and two pmaddwd sum the weighed pairs.
void grey_row(const uint8_t* s, uint8_t* o, int n) {
  const __m128i bg = _mm_setr_epi8(0, -128, 1, -128, 3, -128, 4, -128, 6, -128, 7, -128, 9, -128, 10, -128);
  const __m128i r = _mm_setr_epi8(2, -128, -128, -128, 5, -128, -128, -128, 8, -128, -128, -128, 11, -128, -128, -128);
  const __m128i one = _mm_set1_epi32(1 << 16);
  const __m128i w_bg = _mm_set1_epi32((kGreyG << 16) | kGreyB);
  const __m128i w_r = _mm_set1_epi32((1 << (kGreyShift - 1) << 16) | kGreyR);
  int x = 0;
  for (; x + 16 <= n; x += 16) {
    const uint8_t* p = s + 3 * x;
    const __m128i v0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p));
    const __m128i v1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16));
    const __m128i v2 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 32));
    const __m128i four[4] = {v0, _mm_alignr_epi8(v1, v0, 12), _mm_alignr_epi8(v2, v1, 8), _mm_srli_si128(v2, 4)};
    __m128i sum[4];
    for (int q = 0; q < 4; ++q) {
      const __m128i pairs_bg = _mm_shuffle_epi8(four[q], bg);
      const __m128i pairs_r = _mm_or_si128(_mm_shuffle_epi8(four[q], r), one);
      sum[q] = _mm_srli_epi32(_mm_add_epi32(_mm_madd_epi16(pairs_bg, w_bg), _mm_madd_epi16(pairs_r, w_r)), kGreyShift);
    }
    _mm_storeu_si128(reinterpret_cast<__m128i*>(o + x),
                     _mm_packus_epi16(_mm_packs_epi32(sum[0], sum[1]), _mm_packs_epi32(sum[2], sum[3])));
  }
  plain::grey_row(s + 3 * x, o + x, n - x);
}

}  // namespace arwb::kernels::ssse3
