// Each level's own kernels, as its file defines them (kernels.hpp says what each does). dispatch.cpp puts them in
// the tables; a level's kernel may finish a row with the level below's (a tail shorter than its vectors). Only
// plain's exist in a build with ARWB_PLAIN_KERNELS.
#pragma once

#include "detect/kernels/types.hpp"

#include <cstddef>
#include <cstdint>

namespace arwb::kernels {

namespace plain {
void grey_row(const uint8_t* bgr, uint8_t* grey, int n);
void grey_row4(const uint8_t* px, uint8_t* grey, int n, bool rgba);
void halve_rows(const uint8_t* a, const uint8_t* b, uint8_t* out, int n);
void decimate(const uint8_t* grey, size_t step, int factor, uint8_t* out, size_t out_step, int out_cols,
              int out_rows);
bool box_mean(const uint8_t* src, size_t src_step, int w, int h, int k, uint8_t* dst, size_t dst_step,
              uint16_t* scratch);
void blend_row(const uint8_t* near, const uint8_t* far, uint16_t* v, int n);
void threshold_row(const uint16_t* v, int mw, const uint8_t* grey, uint8_t* binary, int offset);
void row_masks(const uint8_t* row, int w, int words, uint64_t* out, bool light);
int find_edges(const uint64_t* masks, int words, EdgeWords out);
int row_edges(const uint64_t* edge_bits, int words, int* out);
void join_row(EdgeWords above, int above_begin, const int* ends, int begin, int n, int* parent);
int drop_specks(const BitRows& bits, uint64_t* scratch, bool count);
int drop_small_regions(const BitRows& bits, int k, bool count, uint64_t* scratch);
Farthest farthest_point(const Point* c, int n, Point p0, Point dir, bool from_line);
bool warp_row(const double* h, double y, int side, const uint8_t* data, size_t stride, double xlimit, double ymax,
              uint8_t* row, uint8_t* done);
int sample_line(const uint8_t* data, size_t stride, int x, int y, int dx, int dy, int n, int* out);
void profile_edges(const int* profiles, const int* first, int samples, int* spread, double* wsum, double* jsum,
                   int* scratch);
CodeMatch nearest_code(const uint64_t* codes, int n, uint64_t code);
void nearest_per_rotation(const uint64_t* codes, int n, uint64_t code, CodeMatch* out4);
}  // namespace plain

namespace ssse3 {
void grey_row(const uint8_t* bgr, uint8_t* grey, int n);
}  // namespace ssse3

// WebAssembly SIMD128 (the web core's only level above plain).
namespace simd128 {
void grey_row(const uint8_t* bgr, uint8_t* grey, int n);
void grey_row4(const uint8_t* px, uint8_t* grey, int n, bool rgba);
void halve_rows(const uint8_t* a, const uint8_t* b, uint8_t* out, int n);
bool box_mean(const uint8_t* src, size_t src_step, int w, int h, int k, uint8_t* dst, size_t dst_step,
              uint16_t* scratch);
void blend_row(const uint8_t* near, const uint8_t* far, uint16_t* v, int n);   // Highway's (hwy_rows.inl)
void threshold_row(const uint16_t* v, int mw, const uint8_t* grey, uint8_t* binary, int offset);
void row_masks(const uint8_t* row, int w, int words, uint64_t* out, bool light);
int drop_specks(const BitRows& bits, uint64_t* scratch, bool count);
int drop_small_regions(const BitRows& bits, int k, bool count, uint64_t* scratch);
Farthest farthest_point(const Point* c, int n, Point p0, Point dir, bool from_line);
}  // namespace simd128

// AVX2 with POPCNT.
namespace avx2 {
void grey_row(const uint8_t* bgr, uint8_t* grey, int n);
void halve_rows(const uint8_t* a, const uint8_t* b, uint8_t* out, int n);
bool box_mean(const uint8_t* src, size_t src_step, int w, int h, int k, uint8_t* dst, size_t dst_step,
              uint16_t* scratch);
void blend_row(const uint8_t* near, const uint8_t* far, uint16_t* v, int n);   // Highway's (hwy_rows.inl)
void threshold_row(const uint16_t* v, int mw, const uint8_t* grey, uint8_t* binary, int offset);
void row_masks(const uint8_t* row, int w, int words, uint64_t* out, bool light);
int find_edges(const uint64_t* masks, int words, EdgeWords out);
void join_row(EdgeWords above, int above_begin, const int* ends, int begin, int n, int* parent);
int drop_specks(const BitRows& bits, uint64_t* scratch, bool count);
int drop_small_regions(const BitRows& bits, int k, bool count, uint64_t* scratch);
Farthest farthest_point(const Point* c, int n, Point p0, Point dir, bool from_line);
bool warp_row(const double* h, double y, int side, const uint8_t* data, size_t stride, double xlimit, double ymax,
              uint8_t* row, uint8_t* done);
int sample_line(const uint8_t* data, size_t stride, int x, int y, int dx, int dy, int n, int* out);
void profile_edges(const int* profiles, const int* first, int samples, int* spread, double* wsum, double* jsum,
                   int* scratch);
CodeMatch nearest_code(const uint64_t* codes, int n, uint64_t code);
void nearest_per_rotation(const uint64_t* codes, int n, uint64_t code, CodeMatch* out4);
}  // namespace avx2

// AVX-512 F, BW and VL.
namespace avx512 {
void halve_rows(const uint8_t* a, const uint8_t* b, uint8_t* out, int n);
void blend_row(const uint8_t* near, const uint8_t* far, uint16_t* v, int n);
void threshold_row(const uint16_t* v, int mw, const uint8_t* grey, uint8_t* binary, int offset);
void row_masks(const uint8_t* row, int w, int words, uint64_t* out, bool light);
int row_edges(const uint64_t* edge_bits, int words, int* out);
Farthest farthest_point(const Point* c, int n, Point p0, Point dir, bool from_line);
}  // namespace avx512

// And VBMI, VNNI and VPOPCNTDQ.
namespace avx512vbmi {
void grey_row(const uint8_t* bgr, uint8_t* grey, int n);
CodeMatch nearest_code(const uint64_t* codes, int n, uint64_t code);
}  // namespace avx512vbmi

}  // namespace arwb::kernels
