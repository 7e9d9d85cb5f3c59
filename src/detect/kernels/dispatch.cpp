// The kernel tables (kernels.hpp), one per Simd level, each the level below it with the entries its own file has
// (levels.hpp). Constant-initialised: a stage may ask for them while other files' statics start.
#include "detect/kernels/kernels.hpp"

#include "detect/kernels/levels.hpp"

#include <iterator>

namespace arwb::kernels {
namespace {

constexpr Kernels kPlain{
    .level = Simd::none,
    .grey_row = plain::grey_row,
    .grey_row4 = plain::grey_row4,
    .halve_rows = plain::halve_rows,
    .decimate = plain::decimate,
    .box_mean = plain::box_mean,
    .blend_row = plain::blend_row,
    .threshold_row = plain::threshold_row,
    .row_masks = plain::row_masks,
    .find_edges = plain::find_edges,
    .row_edges = plain::row_edges,
    .join_row = plain::join_row,
    .drop_specks = plain::drop_specks,
    .drop_small_regions = plain::drop_small_regions,
    .farthest_point = plain::farthest_point,
    .warp_row = plain::warp_row,
    .sample_line = plain::sample_line,
    .profile_edges = plain::profile_edges,
    .nearest_code = plain::nearest_code,
    .nearest_per_rotation = plain::nearest_per_rotation,
};

#if defined(ARWB_PLAIN_KERNELS)
constexpr const Kernels* kTables[] = {&kPlain, &kPlain, &kPlain, &kPlain, &kPlain};
#elif defined(__wasm_simd128__)
constexpr Kernels simd128_table() {
  Kernels k = kPlain;
  k.level = Simd::simd128;
  k.grey_row = simd128::grey_row;
  k.grey_row4 = simd128::grey_row4;
  k.halve_rows = simd128::halve_rows;
  k.box_mean = simd128::box_mean;
  k.blend_row = simd128::blend_row;
  k.threshold_row = simd128::threshold_row;
  k.row_masks = simd128::row_masks;
  k.drop_specks = simd128::drop_specks;
  k.drop_small_regions = simd128::drop_small_regions;
  k.farthest_point = simd128::farthest_point;
  return k;
}
constexpr Kernels kSimd128 = simd128_table();
// One level above plain; the x86 levels' slots take it too, so that no cap or lookup can reach a missing table.
constexpr const Kernels* kTables[] = {&kPlain, &kSimd128, &kSimd128, &kSimd128, &kSimd128};
#else
constexpr Kernels ssse3_table() {
  Kernels k = kPlain;
  k.level = Simd::ssse3;
  k.grey_row = ssse3::grey_row;
  return k;
}
constexpr Kernels kSsse3 = ssse3_table();

constexpr Kernels avx2_table() {
  Kernels k = kSsse3;
  k.level = Simd::avx2;
  k.grey_row = avx2::grey_row;
  k.halve_rows = avx2::halve_rows;
  k.box_mean = avx2::box_mean;
  k.blend_row = avx2::blend_row;
  k.threshold_row = avx2::threshold_row;
  k.row_masks = avx2::row_masks;
  k.find_edges = avx2::find_edges;
  k.join_row = avx2::join_row;
  k.drop_specks = avx2::drop_specks;
  k.drop_small_regions = avx2::drop_small_regions;
  k.farthest_point = avx2::farthest_point;
  k.warp_row = avx2::warp_row;
  k.sample_line = avx2::sample_line;
  k.profile_edges = avx2::profile_edges;
  k.nearest_code = avx2::nearest_code;
  k.nearest_per_rotation = avx2::nearest_per_rotation;
  return k;
}
constexpr Kernels kAvx2 = avx2_table();

constexpr Kernels avx512_table() {
  Kernels k = kAvx2;
  k.level = Simd::avx512;
  k.halve_rows = avx512::halve_rows;
  k.blend_row = avx512::blend_row;
  k.threshold_row = avx512::threshold_row;
  k.row_masks = avx512::row_masks;
  k.row_edges = avx512::row_edges;
  k.farthest_point = avx512::farthest_point;
  return k;
}
constexpr Kernels kAvx512 = avx512_table();

constexpr Kernels avx512vbmi_table() {
  Kernels k = kAvx512;
  k.level = Simd::avx512_vbmi;
  k.grey_row = avx512vbmi::grey_row;
  k.nearest_code = avx512vbmi::nearest_code;
  return k;
}
constexpr Kernels kAvx512Vbmi = avx512vbmi_table();

constexpr const Kernels* kTables[] = {&kPlain, &kSsse3, &kAvx2, &kAvx512, &kAvx512Vbmi};
#endif
static_assert(std::size(kTables) == size_t(Simd::avx512_vbmi) + 1, "a table per level");

}  // namespace

const Kernels* const detail::tables[5] = {kTables[0], kTables[1], kTables[2], kTables[3], kTables[4]};

}  // namespace arwb::kernels
