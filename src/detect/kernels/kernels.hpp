// The detector's vector kernels: one table of functions per instruction-set level, the one place the stages reach
// vector code through. A stage takes kernels() once per call and calls its entries; it holds no intrinsics and no
// #if on instruction sets. Each level's table is the level below it with the entries that level's own file
// (kernels/LEVEL.cpp, built with that level's flags) does faster; plain.cpp's are the reference, C++ at the
// compiler's baseline (with OpenCV's universal intrinsics where they pay: SSE2 on x86-64, NEON on ARM). A level's
// kernels are hand-written intrinsics, or written once with Highway (hwy_rows.inl) where that measured as fast.
//
// Every entry gives the same bits at every level: the detect tests run each stage under SimdCap at every level the
// processor has and compare it with the plain table's (kernels_test and the Stages tests).
#pragma once

#include "detect/kernels/simd.hpp"
#include "detect/kernels/types.hpp"

#include <cstddef>
#include <cstdint>

namespace arwb::kernels {

struct Kernels {
  Simd level;

  // [acquisition] n BGR pixels to grey: cvtColor's (3735 B + 19235 G + 9798 R + 2^14) >> 15, exactly.
  void (*grey_row)(const uint8_t* bgr, uint8_t* grey, int n);
  // [acquisition] n pixels of 4 channels, B, G, R, A (or R, G, B, A when rgba), to grey as grey_row does.
  void (*grey_row4)(const uint8_t* px, uint8_t* grey, int n, bool rgba);

  // [decimation] Two grey rows' 2x2 block means, n of them: (a + b + c + d + 2) / 4, as cv::resize's INTER_AREA
  // halves. Also adaptive_threshold's block means.
  void (*halve_rows)(const uint8_t* a, const uint8_t* b, uint8_t* out, int n);
  // [decimation] out_rows x out_cols block means of factor x factor pixels (factor 3 to 16), rounded to the nearest.
  void (*decimate)(const uint8_t* grey, size_t step, int factor, uint8_t* out, size_t out_step, int out_cols,
                   int out_rows);

  // [adaptive_threshold] The k x k mean (k odd, border replicated) of a w x h image into dst, rounded to the
  // nearest as cv::boxFilter's; false when this level has no path for k and w (the stage then calls boxFilter).
  // `scratch`: box_mean_scratch(w, k) 16-bit words.
  bool (*box_mean)(const uint8_t* src, size_t src_step, int w, int h, int k, uint8_t* dst, size_t dst_step,
                   uint16_t* scratch);
  // [adaptive_threshold] A row of vertically blended block means: v[i] = 3 near[i] + far[i].
  void (*blend_row)(const uint8_t* near, const uint8_t* far, uint16_t* v, int n);
  // [adaptive_threshold] Pixels 2i and 2i + 1 of the row (i < mw) against the means (3 v[i] + v[i -+ 1] + 8) >> 4,
  // 255 where grey + offset (saturated) <= the mean, else 0. v[-1] and v[mw] are read.
  void (*threshold_row)(const uint16_t* v, int mw, const uint8_t* grey, uint8_t* binary, int offset);

  // [contours] A row's bit masks, `words` words (bit k of word c: pixel 64c + k is nonzero, or zero when `light`;
  // none past w).
  void (*row_masks)(const uint8_t* row, int w, int words, uint64_t* out, bool light);
  // [contours] A row's edge words from its masks (`words` of them and the end word after them, words + 1 written);
  // returns the number of edges.
  int (*find_edges)(const uint64_t* masks, int words, EdgeWords out);
  // [contours] The pixels where the row's runs begin and end, from its `words` edge words, in order into `out`,
  // which has room for 16 past the last; returns how many.
  int (*row_edges)(const uint64_t* edge_bits, int words, int* out);
  // [contours] Joins each of a row's n runs (`ends`: their ends in turn, the first of them run `begin`) to the runs
  // it touches (8-connected) in the row above (from run above_begin, with its edges `above`), in the union-find
  // `parent` (a run's parent never after it).
  void (*join_row)(EdgeWords above, int above_begin, const int* ends, int begin, int n, int* parent);
  // [contours] Takes the specks (pixels with none of their eight neighbours on) out of `bits`; their number when
  // `count`, else 0. `scratch`: bits.size() words.
  int (*drop_specks)(const BitRows& bits, uint64_t* scratch, bool count);
  // [contours] Takes out every region that fits a k x k window (k 3 or 5) with an empty ring around it; their
  // number when `count` (k 3 only), else 0. `scratch`: 3 bits.size() words.
  int (*drop_small_regions)(const BitRows& bits, int k, bool count, uint64_t* scratch);

  // [quad_fit] The first of the points c[0, n) farthest from p0, or when `from_line` from the line through p0 along
  // dir (as |cross product|), in integers.
  Farthest (*farthest_point)(const Point* c, int n, Point p0, Point dir, bool from_line);

  // [perspective_removal] One row of the frontal view, eight pixels a group, where every sample of a group lies
  // inside [0, xlimit) x [0, ymax): the homography `h` (row-major 3x3) in the scalar loop's double operations and
  // order, bilinear in 1/256 pixel. done[g] says whether group g was done here; false when this level does no
  // group (the stage's scalar loop does the row).
  bool (*warp_row)(const double* h, double y, int side, const uint8_t* data, size_t stride, double xlimit,
                   double ymax, uint8_t* row, uint8_t* done);

  // [corner_refinement] Samples of a line from (x, y) in steps (dx, dy), all in 1/65536 pixel, bilinear in 1/256
  // pixel, times 65536: how many of the n it did from the start (the stage does the rest). The line stays 3 pixels
  // inside the row's end.
  int (*sample_line)(const uint8_t* data, size_t stride, int x, int y, int dx, int dy, int n, int* out);
  // [corner_refinement] Eight profiles (profile q: samples [first[q], first[q] + samples) of `profiles`): each
  // one's spread (its highest sample but the last less its lowest), and the sums for the centroid of its rising
  // steps above a fifth of the highest step. `scratch`: 8 samples ints.
  void (*profile_edges)(const int* profiles, const int* first, int samples, int* spread, double* wsum, double* jsum,
                        int* scratch);

  // [identification] The nearest of n codes in their four rotations (codes[4 id + k]): the first exact match, or
  // the lowest id, then rotation, at the smallest distance.
  CodeMatch (*nearest_code)(const uint64_t* codes, int n, uint64_t code);
  // [identification] For each rotation k, the nearest id read as the marker turned k quarter-turns.
  void (*nearest_per_rotation)(const uint64_t* codes, int n, uint64_t code, CodeMatch* out4);
};

// The 16-bit words box_mean's scratch needs for a w-pixel row and a k-pixel window.
inline size_t box_mean_scratch(int w, int k) { return size_t(w) * size_t(k + 3) + size_t(k); }

namespace detail {
extern const Kernels* const tables[5];   // per Simd level (dispatch.cpp)
}  // namespace detail

// The table for simd(): the processor's level, below the cap while a SimdCap lives.
inline const Kernels& kernels() { return *detail::tables[int(simd())]; }
// The plain table, whatever the level.
inline const Kernels& plain_kernels() { return *detail::tables[0]; }

}  // namespace arwb::kernels
