// WebAssembly SIMD128 kernels (built with -msimd128, in the web core only): see kernels.hpp for what each does.
// Each gives plain's bits; a row's tail shorter than a vector is finished by plain's kernel. OpenCV's universal
// intrinsics, which plain uses, emulate on WebAssembly the dot products, narrowings and pairwise additions that
// SIMD128 has as single instructions: these are the stages' hot rows written with them.
#include "detect/kernels/levels.hpp"

#include <wasm_simd128.h>

#include <hwy/highway.h>

#include <cstdlib>
#include <cstring>

namespace arwb::kernels::simd128 {
namespace {

#include "detect/kernels/small_regions.inl"
#include "detect/kernels/hwy_rows.inl"
static_assert(HWY_STATIC_TARGET == HWY_WASM, "Highway compiles for WebAssembly SIMD128 here");

// box_mean's words, 8 a vector (box_mean.inl).
struct Words8 {
  using V = v128_t;
  static constexpr int kLanes = 8;
  static V load(const uint16_t* at) { return wasm_v128_load(at); }
  static void store(uint16_t* at, V v) { wasm_v128_store(at, v); }
  static V add(V a, V b) { return wasm_i16x8_add(a, b); }
  static V sub(V a, V b) { return wasm_i16x8_sub(a, b); }
  static V splat(uint16_t v) { return wasm_i16x8_splat(int16_t(v)); }
  static void widen(const uint8_t* in, uint16_t* out) { store(out, wasm_u16x8_load8x8(in)); }
  static void means(V sum, V half, V mul, int shift, uint8_t* out) {
    const V x = wasm_i16x8_add(sum, half);
    // The high halves of the 32-bit products, lanes in order.
    const V lo = wasm_u32x4_extmul_low_u16x8(x, mul), hi = wasm_u32x4_extmul_high_u16x8(x, mul);
    const V mean = wasm_u16x8_shr(wasm_i16x8_shuffle(lo, hi, 1, 3, 5, 7, 9, 11, 13, 15), uint32_t(shift));
    wasm_v128_store64_lane(out, wasm_u8x16_narrow_i16x8(mean, mean), 0);
  }
};

#include "detect/kernels/box_mean.inl"

// Four pixels of four bytes each, the fourth's weight 0, to their grey levels: one dot product per two channels,
// the pairs added.
inline v128_t grey4(v128_t px, v128_t weights, v128_t round) {
  const v128_t lo = wasm_i32x4_dot_i16x8(wasm_u16x8_extend_low_u8x16(px), weights);
  const v128_t hi = wasm_i32x4_dot_i16x8(wasm_u16x8_extend_high_u8x16(px), weights);
  const v128_t sum = wasm_i32x4_add(wasm_i32x4_shuffle(lo, hi, 0, 2, 4, 6), wasm_i32x4_shuffle(lo, hi, 1, 3, 5, 7));
  return wasm_i32x4_shr(wasm_i32x4_add(sum, round), kGreyShift);
}

// Sixteen grey levels from four vectors of four pixels each.
inline void store_grey16(uint8_t* o, v128_t a, v128_t b, v128_t c, v128_t d) {
  wasm_v128_store(o, wasm_u8x16_narrow_i16x8(wasm_i16x8_narrow_i32x4(a, b), wasm_i16x8_narrow_i32x4(c, d)));
}

inline v128_t grey_weights(bool rgb) {
  return rgb ? wasm_i16x8_make(kGreyR, kGreyG, kGreyB, 0, kGreyR, kGreyG, kGreyB, 0)
             : wasm_i16x8_make(kGreyB, kGreyG, kGreyR, 0, kGreyB, kGreyG, kGreyR, 0);
}

}  // namespace

// 16 pixels (48 bytes) a step: each run of four pixels' 12 bytes shuffled to the front of a vector (its last four
// lanes whatever follows: their weight is 0).
void grey_row(const uint8_t* s, uint8_t* o, int n) {
  const v128_t w = grey_weights(false), round = wasm_i32x4_splat(1 << (kGreyShift - 1));
  int x = 0;
  for (; x + 16 <= n; x += 16) {
    const v128_t v0 = wasm_v128_load(s + 3 * x), v1 = wasm_v128_load(s + 3 * x + 16),
                 v2 = wasm_v128_load(s + 3 * x + 32);
    const v128_t p0 = v0;
    const v128_t p1 = wasm_i8x16_shuffle(v0, v1, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 0, 0, 0, 0);
    const v128_t p2 = wasm_i8x16_shuffle(v1, v2, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 0, 0, 0, 0);
    const v128_t p3 = wasm_i8x16_shuffle(v2, v2, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 0, 0, 0, 0);
    auto spread = [](v128_t p) {   // bytes 0..11 as four pixels of four bytes
      return wasm_i8x16_shuffle(p, p, 0, 1, 2, 0, 3, 4, 5, 0, 6, 7, 8, 0, 9, 10, 11, 0);
    };
    store_grey16(o + x, grey4(spread(p0), w, round), grey4(spread(p1), w, round), grey4(spread(p2), w, round),
                 grey4(spread(p3), w, round));
  }
  plain::grey_row(s + 3 * x, o + x, n - x);
}

// 16 pixels a step, four a dot product pair: each pixel's first two bytes as one pair of 16-bit lanes, its third
// byte with the constant 1 as another, so the second product's second weight adds the rounding (the fourth byte
// is not read).
void grey_row4(const uint8_t* s, uint8_t* o, int n, bool rgba) {
  const int w0 = rgba ? kGreyR : kGreyB, w2 = rgba ? kGreyB : kGreyR;
  const v128_t w01 = wasm_i16x8_make(w0, kGreyG, w0, kGreyG, w0, kGreyG, w0, kGreyG);
  const v128_t w2_round = wasm_i16x8_make(w2, 1 << (kGreyShift - 1), w2, 1 << (kGreyShift - 1), w2,
                                          1 << (kGreyShift - 1), w2, 1 << (kGreyShift - 1));
  const v128_t first = wasm_i8x16_const(0, -1, 1, -1, 4, -1, 5, -1, 8, -1, 9, -1, 12, -1, 13, -1);
  const v128_t third = wasm_i8x16_const(2, -1, -1, -1, 6, -1, -1, -1, 10, -1, -1, -1, 14, -1, -1, -1);
  const v128_t one = wasm_i32x4_const_splat(1 << 16);
  const auto four = [&](const uint8_t* p) {
    const v128_t px = wasm_v128_load(p);
    const v128_t a = wasm_i32x4_dot_i16x8(wasm_i8x16_swizzle(px, first), w01);
    const v128_t b = wasm_i32x4_dot_i16x8(wasm_v128_or(wasm_i8x16_swizzle(px, third), one), w2_round);
    return wasm_u32x4_shr(wasm_i32x4_add(a, b), kGreyShift);
  };
  int x = 0;
  for (; x + 16 <= n; x += 16) {
    const uint8_t* p = s + 4 * x;
    store_grey16(o + x, four(p), four(p + 16), four(p + 32), four(p + 48));
  }
  plain::grey_row4(s + 4 * x, o + x, n - x, rgba);
}

// 16 block means a step: each row's byte pairs added by one pairwise addition, the rows added, rounded.
void halve_rows(const uint8_t* a, const uint8_t* b, uint8_t* o, int n) {
  const v128_t two = wasm_i16x8_splat(2);
  int x = 0;
  auto eight = [&](int at) {
    const v128_t sum = wasm_i16x8_add(wasm_u16x8_extadd_pairwise_u8x16(wasm_v128_load(a + at)),
                                      wasm_u16x8_extadd_pairwise_u8x16(wasm_v128_load(b + at)));
    return wasm_u16x8_shr(wasm_i16x8_add(sum, two), 2);
  };
  for (; x + 16 <= n; x += 16) wasm_v128_store(o + x, wasm_u8x16_narrow_i16x8(eight(2 * x), eight(2 * x + 16)));
  plain::halve_rows(a + 2 * x, b + 2 * x, o + x, n - x);
}

bool box_mean(const uint8_t* src, size_t src_step, int w, int h, int k, uint8_t* dst, size_t dst_step,
              uint16_t* scratch) {
  return box_mean_words<Words8>(src, src_step, w, h, k, dst, dst_step, scratch);
}

void blend_row(const uint8_t* near, const uint8_t* far, uint16_t* v, int n) {
  const int i = blend_row_hwy(near, far, v, n);
  plain::blend_row(near + i, far + i, v + i, n - i);
}

// 16 pixels (8 block means) a step, plain's arithmetic: the means of the even and odd pixels interleaved, the
// lifted levels (added with saturation) compared with them.
void threshold_row(const uint16_t* v, int mw, const uint8_t* g, uint8_t* b, int offset) {
  const v128_t lift = wasm_i8x16_splat(int8_t(offset)), round = wasm_i16x8_splat(8);
  int i = 0;
  for (; i + 8 <= mw; i += 8) {
    const v128_t c = wasm_v128_load(v + i);
    const v128_t c3 = wasm_i16x8_add(wasm_i16x8_add(wasm_i16x8_shl(c, 1), c), round);
    const v128_t even = wasm_u16x8_shr(wasm_i16x8_add(c3, wasm_v128_load(v + i - 1)), 4);
    const v128_t odd = wasm_u16x8_shr(wasm_i16x8_add(c3, wasm_v128_load(v + i + 1)), 4);
    const v128_t mean = wasm_u8x16_narrow_i16x8(wasm_i16x8_shuffle(even, odd, 0, 8, 1, 9, 2, 10, 3, 11),
                                                wasm_i16x8_shuffle(even, odd, 4, 12, 5, 13, 6, 14, 7, 15));
    wasm_v128_store(b + 2 * i, wasm_u8x16_le(wasm_u8x16_add_sat(wasm_v128_load(g + 2 * i), lift), mean));
  }
  plain::threshold_row(v + i, mw - i, g + 2 * i, b + 2 * i, offset);
}

// 64 pixels a word: each 16's comparison with zero, its lanes' top bits by one bitmask.
void row_masks(const uint8_t* row, int w, int words, uint64_t* out, bool light) {
  const v128_t zero = wasm_i8x16_splat(0);
  int c = 0;
  for (; c < words && 64 * c + 64 <= w; ++c) {
    uint64_t off = 0;
    for (int q = 0; q < 4; ++q)
      off |= uint64_t(wasm_i8x16_bitmask(wasm_i8x16_eq(wasm_v128_load(row + 64 * c + 16 * q), zero))) << (16 * q);
    out[c] = light ? off : ~off;
  }
  plain::row_masks(row + 64 * c, w - 64 * c, words - c, out + c, light);
}

int drop_specks(const BitRows& bits, uint64_t* scratch, bool count) {
  return drop_specks_of<VectorWords<2>>(bits, scratch, count);
}

int drop_small_regions(const BitRows& bits, int k, bool count, uint64_t* scratch) {
  return drop_small_regions_of<VectorWords<2>>(bits, k, count, scratch);
}

// Four points a step in 32-bit lanes: x and y gathered by two shuffles, the measure in 32-bit integers, per lane
// the first largest with its index. Exact while every coordinate lies within +-kFarthestReach (each lane's
// measure then fits: 2 * 32766^2 < 2^31, as do the cross products); a point or argument beyond it leaves the whole
// search to plain, which works in 64 bits. Merged as plain finds them: the largest, the lowest index among equals.
Farthest farthest_point(const Point* c, int n, Point p0, Point dir, bool from_line) {
  constexpr int kFarthestReach = 16383;
  const auto near = [](Point p) { return std::abs(p.x) <= kFarthestReach && std::abs(p.y) <= kFarthestReach; };
  if (n < 8 || !near(p0) || !near(dir)) return plain::farthest_point(c, n, p0, dir, from_line);
  const v128_t ox = wasm_i32x4_splat(p0.x), oy = wasm_i32x4_splat(p0.y);
  const v128_t ix = wasm_i32x4_splat(dir.x), iy = wasm_i32x4_splat(dir.y), reach = wasm_i32x4_splat(kFarthestReach);
  v128_t top = wasm_i32x4_splat(-1), where = wasm_i32x4_splat(-1), index = wasm_i32x4_make(0, 1, 2, 3);
  v128_t beyond = wasm_i32x4_splat(0);
  const v128_t four = wasm_i32x4_splat(4);
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    const v128_t a = wasm_v128_load(c + k), b = wasm_v128_load(c + k + 2);
    beyond = wasm_v128_or(beyond, wasm_v128_or(wasm_i32x4_gt(wasm_i32x4_abs(a), reach),
                                               wasm_i32x4_gt(wasm_i32x4_abs(b), reach)));
    const v128_t dx = wasm_i32x4_sub(wasm_i32x4_shuffle(a, b, 0, 2, 4, 6), ox);
    const v128_t dy = wasm_i32x4_sub(wasm_i32x4_shuffle(a, b, 1, 3, 5, 7), oy);
    const v128_t m = from_line ? wasm_i32x4_abs(wasm_i32x4_sub(wasm_i32x4_mul(dy, ix), wasm_i32x4_mul(dx, iy)))
                               : wasm_i32x4_add(wasm_i32x4_mul(dx, dx), wasm_i32x4_mul(dy, dy));
    const v128_t more = wasm_i32x4_gt(m, top);
    top = wasm_v128_bitselect(m, top, more);
    where = wasm_v128_bitselect(index, where, more);
    index = wasm_i32x4_add(index, four);
  }
  if (wasm_v128_any_true(beyond)) return plain::farthest_point(c, n, p0, dir, from_line);
  Farthest f;
  int32_t tops[4], wheres[4];
  wasm_v128_store(tops, top);
  wasm_v128_store(wheres, where);
  for (int l = 0; l < 4; ++l)
    if (tops[l] > f.measure || (tops[l] == f.measure && tops[l] >= 0 && wheres[l] < f.at)) f = {tops[l], wheres[l]};
  const Farthest rest = plain::farthest_point(c + k, n - k, p0, dir, from_line);
  if (rest.measure > f.measure) f = {rest.measure, k + rest.at};
  return f;
}

}  // namespace arwb::kernels::simd128
