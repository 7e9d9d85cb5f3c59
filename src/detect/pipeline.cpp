#include "detect/pipeline.hpp"

#include "detect/simd.hpp"

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <climits>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>

namespace arwb::stages {
namespace {

std::string fmt(const char* f, double a, double b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

Rejection reject(Stage s, std::string_view param, double value, double limit, std::string message) {
  return Rejection{s, param, value, limit, std::move(message)};
}

}  // namespace

// [SECTION] acquisition

namespace {

// cvtColor's BGR to grey, exactly: (3735 B + 19235 G + 9798 R + 2^14) >> 15 (checked against it over all 2^24
// colours by the tests).
constexpr int kGreyB = 3735, kGreyG = 19235, kGreyR = 9798, kGreyShift = 15;

inline uint8_t grey_of(const uint8_t* bgr) {
  return uint8_t((kGreyB * bgr[0] + kGreyG * bgr[1] + kGreyR * bgr[2] + (1 << (kGreyShift - 1))) >> kGreyShift);
}

#if defined(__x86_64__) || defined(__i386__)
// SSSE3: n pixels of a row, 16 from 48 bytes at a time. Four pixels (12 bytes, brought to a vector's start by
// palignr) at a time: one byte shuffle makes their B and G 16-bit pairs, another their R with a 1 beside it (the
// rounding's weight), and two pmaddwd sum the weighed pairs. 1.35-1.45x cvtColor's speed on the bench machine
// (1920x1080: 0.59 against 0.79 ms), which gathers the channels apart first.
__attribute__((target("ssse3"))) void grey_row_ssse3(const uint8_t* s, uint8_t* o, int n) {
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
  for (; x < n; ++x) o[x] = grey_of(s + 3 * x);
}

// AVX2: as SSSE3, four pixels a 128-bit lane: a dword permutation puts bytes 12..27 of a 32-byte load in its high
// lane, where the same shuffles find them; the packed results come out with the lanes' dwords interleaved, and one
// more permutation puts them in order. 1920x1080: 0.41 ms against SSSE3's 0.59.
__attribute__((target("avx2"))) void grey_row_avx2(const uint8_t* s, uint8_t* o, int n) {
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
  grey_row_ssse3(s + 3 * x, o + x, n - x);
}

// GCC 12's AVX-512 shifts and conversions start from _mm512_undefined_epi32(), which it then calls maybe
// uninitialised (a known false warning) in every function that uses them.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// AVX-512 (with VBMI and VNNI): 16 pixels a 512-bit vector, 64 a step. vpermb takes each pixel's B and G, and its R,
// to the 16-bit halves of its own dword from anywhere in the vector, zeroing the bytes between (a zeroing mask), so
// the shuffles are two a 16 pixels, not the three a 8 of AVX2's; vpdpwssd weighs and sums the pairs onto the
// rounding. On the bench machine (summary trace, standard set) the decimation stage at 640x480 0.069 -> 0.045 ms
// and, with halve_rows_avx512, at 1280x720 0.27 -> 0.16 ms.
__attribute__((target("avx512f,avx512bw,avx512vl,avx512vbmi,avx512vnni"))) void grey_row_avx512(const uint8_t* s,
                                                                                                uint8_t* o, int n) {
  // [0]: B and G of pixel k to bytes 4k and 4k + 2; [1]: R to 4k; [2] and [3] the same from 16 bytes further
  // into the vector.
  alignas(64) static constexpr auto index = [] {
    std::array<std::array<uint8_t, 64>, 4> ix{};
    for (int shift = 0; shift <= 16; shift += 16)
      for (int k = 0; k < 16; ++k) {
        ix[size_t(shift / 8)][size_t(4 * k)] = uint8_t(shift + 3 * k);
        ix[size_t(shift / 8)][size_t(4 * k + 2)] = uint8_t(shift + 3 * k + 1);
        ix[size_t(shift / 8 + 1)][size_t(4 * k)] = uint8_t(shift + 3 * k + 2);
      }
    return ix;
  }();
  const __m512i take_bg = _mm512_load_si512(index[0].data()), take_r = _mm512_load_si512(index[1].data());
  const __mmask64 bytes_bg = 0x5555555555555555ull, bytes_r = 0x1111111111111111ull;
  const __m512i w_bg = _mm512_set1_epi32((kGreyG << 16) | kGreyB), w_r = _mm512_set1_epi32(kGreyR);
  const __m512i round = _mm512_set1_epi32(1 << (kGreyShift - 1));
  // After the packs, 128-bit lane L holds pixels 4L..4L+3 of each 16 in turn: dword 4L + q goes to 4q + L.
  const __m512i order = _mm512_setr_epi32(0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15);
  int x = 0;
  // Four 64-byte loads 48 bytes apart: the last reads 16 bytes past the 64 pixels while that is inside the row;
  // the row's last 64 pixels take their last 48 bytes from a load that ends with them.
  const __m512i take_bg_end = _mm512_load_si512(index[2].data()), take_r_end = _mm512_load_si512(index[3].data());
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
  grey_row_avx2(s + 3 * x, o + x, n - x);
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif

// A BGR image (or a view of one) into `grey`, allocated to its size unless it already has it (a view is written in
// place).
void bgr_to_grey(const cv::Mat& bgr, cv::Mat& grey) {
  grey.create(bgr.size(), CV_8UC1);
  void (*row)(const uint8_t*, uint8_t*, int) = nullptr;
#if defined(__x86_64__) || defined(__i386__)
  const Simd level = simd();
  if (level >= Simd::avx512_vbmi) row = grey_row_avx512;
  else if (level >= Simd::avx2) row = grey_row_avx2;
  else if (level >= Simd::ssse3) row = grey_row_ssse3;
#endif
  for (int y = 0; y < grey.rows; ++y) {
    const uint8_t* s = bgr.ptr<uint8_t>(y);
    uint8_t* o = grey.ptr<uint8_t>(y);
    if (row) {
      row(s, o, grey.cols);
    } else {
      for (int x = 0; x < grey.cols; ++x) o[x] = grey_of(s + 3 * x);
    }
  }
}

#if defined(__x86_64__) || defined(__i386__)
// Two grey rows' 2x2 block means, 16 a step: each row's byte pairs summed by pmaddubsw with ones, the two rows
// added, rounded. Returns how many it did.
__attribute__((target("avx2"))) int halve_rows_avx2(const uint8_t* a, const uint8_t* b, uint8_t* o, int n) {
  const __m256i ones = _mm256_set1_epi8(1), two = _mm256_set1_epi16(2);
  int x = 0;
  for (; x + 16 <= n; x += 16) {
    const __m256i pa = _mm256_maddubs_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + 2 * x)), ones);
    const __m256i pb = _mm256_maddubs_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + 2 * x)), ones);
    const __m256i mean = _mm256_srli_epi16(_mm256_add_epi16(_mm256_add_epi16(pa, pb), two), 2);
    const __m256i packed = _mm256_permute4x64_epi64(_mm256_packus_epi16(mean, mean), 0x08);   // qwords 0, 2
    _mm_storeu_si128(reinterpret_cast<__m128i*>(o + x), _mm256_castsi256_si128(packed));
  }
  return x;
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"   // as grey_row_avx512's
#endif
// AVX-512: 32 block means a step, made as AVX2's and narrowed by vpmovwb.
__attribute__((target("avx512f,avx512bw,avx512vl"))) int halve_rows_avx512(const uint8_t* a, const uint8_t* b,
                                                                           uint8_t* o, int n) {
  const __m512i ones = _mm512_set1_epi8(1), two = _mm512_set1_epi16(2);
  int x = 0;
  for (; x + 32 <= n; x += 32) {
    const __m512i pa = _mm512_maddubs_epi16(_mm512_loadu_si512(a + 2 * x), ones);
    const __m512i pb = _mm512_maddubs_epi16(_mm512_loadu_si512(b + 2 * x), ones);
    const __m512i mean = _mm512_srli_epi16(_mm512_add_epi16(_mm512_add_epi16(pa, pb), two), 2);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(o + x), _mm512_cvtepi16_epi8(mean));
  }
  return x;
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif

// Two grey rows' 2x2 block means, n of them: (a + b + c + d + 2) / 4, as cv::resize's INTER_AREA halves.
void halve_rows(const uint8_t* a, const uint8_t* b, uint8_t* o, int n) {
  int x = 0;
#if defined(__x86_64__) || defined(__i386__)
  const Simd level = simd();
  if (level >= Simd::avx512) x = halve_rows_avx512(a, b, o, n);
  if (level >= Simd::avx2) x += halve_rows_avx2(a + 2 * x, b + 2 * x, o + x, n - x);
#endif
  for (; x < n; ++x) o[x] = uint8_t((a[2 * x] + a[2 * x + 1] + b[2 * x] + b[2 * x + 1] + 2) >> 2);
}

// bgr_to_grey, and the grey image's 2x2 block means (its whole blocks) into `half` as each pair of rows is done,
// while they are in the cache: decimate(grey, 2) exactly, (a + b + c + d + 2) / 4.
void bgr_to_grey_and_half(const cv::Mat& bgr, cv::Mat& grey, cv::Mat& half) {
  grey.create(bgr.size(), CV_8UC1);
  half.create(bgr.rows / 2, bgr.cols / 2, CV_8UC1);
  for (int y = 0; y < bgr.rows; y += 2) {
    const int rows = std::min(2, bgr.rows - y);
    cv::Mat strip = grey.rowRange(y, y + rows);
    bgr_to_grey(bgr.rowRange(y, y + rows), strip);
    if (rows < 2) break;
    halve_rows(grey.ptr<uint8_t>(y), grey.ptr<uint8_t>(y + 1), half.ptr<uint8_t>(y / 2), half.cols);
  }
}

cv::Mat to_grey(const cv::Mat& input) {
  cv::Mat grey;
  if (input.channels() == 3 && input.depth() == CV_8U) bgr_to_grey(input, grey);
  else if (input.channels() == 3) cv::cvtColor(input, grey, cv::COLOR_BGR2GRAY);
  else if (input.channels() == 4) cv::cvtColor(input, grey, cv::COLOR_BGRA2GRAY);
  else grey = input;
  if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U);
  return grey;
}
}  // namespace

GreyOnDemand::GreyOnDemand(const cv::Mat& frame) {
  if (frame.depth() != CV_8U || (frame.channels() != 3 && frame.channels() != 4)) {
    grey_ = frame.empty() ? cv::Mat() : to_grey(frame);
    return;
  }
  colour_ = frame;
  grey_.create(frame.size(), CV_8UC1);
  tiles_x_ = (frame.cols + kTile - 1) / kTile;
  done_.assign(size_t(tiles_x_) * size_t((frame.rows + kTile - 1) / kTile), 0);
}

cv::Mat GreyOnDemand::convert_all_and_halve() {
  cv::Mat half;
  if (colour_.type() != CV_8UC3) {
    need_all();
    return decimate(grey_, 2);
  }
  bgr_to_grey_and_half(colour_, grey_, half);
  std::fill(done_.begin(), done_.end(), uint8_t(1));
  return half;
}

void GreyOnDemand::need(const cv::Rect& r) {
  if (colour_.empty()) return;
  const cv::Rect frame(0, 0, grey_.cols, grey_.rows);
  const cv::Rect in = r & frame;
  if (in.empty()) return;
  const int tx0 = in.x / kTile, tx1 = (in.x + in.width - 1) / kTile;
  const int ty0 = in.y / kTile, ty1 = (in.y + in.height - 1) / kTile;
  // Tiles [x0, x1] x [y0, y1] converted in one call (a call has a fixed cost: a block at once) and marked.
  auto convert = [&](int x0, int y0, int x1, int y1) {
    const cv::Rect px = cv::Rect(x0 * kTile, y0 * kTile, (x1 - x0 + 1) * kTile, (y1 - y0 + 1) * kTile) & frame;
    cv::Mat out = grey_(px);   // converted in place: a destination of the right size is kept
    if (colour_.channels() == 3) bgr_to_grey(colour_(px), out);
    else cv::cvtColor(colour_(px), out, cv::COLOR_BGRA2GRAY);
    for (int ty = y0; ty <= y1; ++ty)
      std::fill_n(done_.begin() + ptrdiff_t(ty) * tiles_x_ + x0, x1 - x0 + 1, uint8_t(1));
  };
  auto done = [&](int tx, int ty) { return done_[size_t(ty) * size_t(tiles_x_) + size_t(tx)] != 0; };
  bool fresh = true;   // none of r's tiles converted yet: all at once
  for (int ty = ty0; ty <= ty1 && fresh; ++ty)
    for (int tx = tx0; tx <= tx1 && fresh; ++tx) fresh = !done(tx, ty);
  if (fresh) return convert(tx0, ty0, tx1, ty1);
  for (int ty = ty0; ty <= ty1; ++ty)   // else each row's runs of tiles not yet converted
    for (int tx = tx0; tx <= tx1;) {
      if (done(tx, ty)) {
        ++tx;
        continue;
      }
      int end = tx;
      while (end + 1 <= tx1 && !done(end + 1, ty)) ++end;
      convert(tx, ty, end, ty);
      tx = end + 1;
    }
}

GreyOnDemand acquire_on_demand(const cv::Mat& input, const AcquisitionSettings& a, double* scale_x,
                               double* scale_y, cv::Mat* acquired) {
  const cv::Size size = acquisition_size(input.size(), a);
  *scale_x = double(input.cols) / size.width;
  *scale_y = double(input.rows) / size.height;
  if (acquired) {
    arwb::acquire(input, a, *acquired);
    return GreyOnDemand(*acquired);
  }
  if (size == input.size()) return GreyOnDemand(input);
  // Nobody shows the resized colour frame: resizing the grey one is the same step with a third of the work.
  cv::Mat grey = to_grey(input);
  arwb::acquire(grey, a, grey);
  return GreyOnDemand(grey);
}

cv::Mat acquire(const cv::Mat& input, const AcquisitionSettings& a, double* scale_x, double* scale_y,
                cv::Mat* acquired) {
  GreyOnDemand grey = acquire_on_demand(input, a, scale_x, scale_y, acquired);
  grey.need_all();
  return grey.image();
}

// [SECTION] search_regions

void merge_overlapping(std::vector<cv::Rect>& rects) {
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t i = 0; i < rects.size() && !merged; ++i)
      for (size_t j = i + 1; j < rects.size() && !merged; ++j)
        if ((rects[i] & rects[j]).area() > 0) {
          rects[i] |= rects[j];
          rects.erase(rects.begin() + long(j));
          merged = true;
        }
  }
  std::sort(rects.begin(), rects.end(),
            [](const cv::Rect& a, const cv::Rect& b) { return a.y != b.y ? a.y < b.y : a.x < b.x; });
}
std::vector<cv::Rect> plan_fine_search(const std::vector<cv::Rect>& shapes, cv::Size grey, const DetectorParams& p) {
  std::vector<cv::Rect> regions;
  if (p.fine_max_side_px <= 0) return regions;
  const cv::Rect frame(0, 0, grey.width, grey.height);
  // Half a side of margin: a decimated shape may hold only part of a blurred marker. And at least half the
  // threshold's window and two pixels, so that the marker's quiet zone is thresholded against its surroundings.
  const int min_margin = p.threshold_window_px / 2 + 2;
  for (const cv::Rect& b : shapes) {
    const int longer = std::max(b.width, b.height), shorter = std::min(b.width, b.height);
    if (longer > p.fine_max_side_px || 3 * shorter < longer || 2.0 * (b.width + b.height) < 0.75 * p.min_perimeter_px)
      continue;
    const int m = std::max(longer / 2, min_margin);
    const cv::Rect r = cv::Rect(b.x - m, b.y - m, b.width + 2 * m, b.height + 2 * m) & frame;
    if (r.width >= 32 && r.height >= 32) regions.push_back(r);   // less is in the frame's corner: too little to search
  }
  merge_overlapping(regions);
  return regions;
}
SearchPlan plan_search(cv::Size grey, const std::vector<Quad>& known, const DetectorParams& p) {
  SearchPlan plan;
  const cv::Rect frame(0, 0, grey.width, grey.height);
  plan.factor = decimation_used(grey, p);
  plan.regions = {frame};
  if (known.empty() || frame.empty()) return plan;
  double smallest = 1e30;
  std::vector<cv::Rect> regions;
  for (const Quad& q : known) {
    const double side = quad_perimeter(q) / 4;
    if (!std::isfinite(side) || side <= 0) continue;
    smallest = std::min(smallest, side);
    const cv::Rect box = cv::boundingRect(std::vector<cv::Point2f>(q.begin(), q.end()));
    const int m = int(std::ceil(p.region_margin_rate * side));
    const cv::Rect r = cv::Rect(box.x - m, box.y - m, box.width + 2 * m, box.height + 2 * m) & frame;
    if (!r.empty()) regions.push_back(r);
  }
  if (regions.empty()) return plan;
  const int f = std::clamp(int(smallest / std::max(1.0, p.region_min_side_px)), 1, 4);
  // Whole decimated pixels, from the frame's origin, so that a region's blocks are the frame's blocks; and at least
  // 16 decimated pixels a side, enough for the threshold's window to see past a marker.
  const int min_side = 16 * f;
  for (cv::Rect& r : regions) {
    int x0 = r.x / f * f, y0 = r.y / f * f;
    int x1 = std::max(r.br().x, x0 + min_side), y1 = std::max(r.br().y, y0 + min_side);
    x1 = (x1 + f - 1) / f * f;
    y1 = (y1 + f - 1) / f * f;
    r = cv::Rect(cv::Point(x0, y0), cv::Point(x1, y1)) & frame;
  }
  merge_overlapping(regions);   // no contour is found twice
  double area = 0;
  for (const cv::Rect& r : regions) area += r.area();
  plan.whole = false;
  plan.factor = f;
  if (area > 0.7 * frame.area()) {
    plan.regions = {frame};   // most of the frame: one search over it costs less than several
  } else {
    plan.regions = std::move(regions);
  }
  return plan;
}

bool cut_by_region(const cv::Rect& box, const cv::Rect& region, cv::Size grey, int factor) {
  const int reach = factor;   // a contour's points are block centres: within a block of the edge touches it
  return (region.x > 0 && box.x - region.x < reach) || (region.y > 0 && box.y - region.y < reach) ||
         (region.br().x < grey.width && region.br().x - box.br().x < reach) ||
         (region.br().y < grey.height && region.br().y - box.br().y < reach);
}

// [SECTION] decimation

int decimation_used(cv::Size grey, const DetectorParams& p) {
  int f = p.decimation_factor > 0 ? p.decimation_factor : std::min(grey.width, grey.height) >= 720 ? 2 : 1;
  while (f > 1 && std::min(grey.width, grey.height) / f < 64) --f;
  return f;
}

namespace {
// One row of block means: the block's rows summed first, then each block's columns, rounded to the nearest. F is a
// template argument for the factors the parameters allow, so the division by the block's area is a constant's.
// For 3 and 4 both sums are vectorised with OpenCV's universal intrinsics (the 3x3 sum, at most 2295, divided by 9
// as a 16-bit multiply-high by 7282: exact for every sum, checked over all of them by the tests' decimation case);
// 640x480 at 3: 0.16 -> 0.03 ms on the bench machine, the division instruction per pixel was most of it. F = 0 takes
// `factor` at run time.
template <int F>
void decimate_rows(const cv::Mat& grey, cv::Mat& out, int factor) {
  const int f = F > 0 ? F : factor;
  const int cols = out.cols * f;
  thread_local std::vector<uint16_t> sum_buf;
  sum_buf.resize(static_cast<size_t>(cols));
  uint16_t* sum = sum_buf.data();
  const uint32_t area = uint32_t(f * f);
  for (int y = 0; y < out.rows; ++y) {
    int x = 0;
#if CV_SIMD128
    for (; x + 8 <= cols; x += 8) {
      cv::v_uint16x8 acc = cv::v_load_expand(grey.ptr<uint8_t>(y * f) + x);
      for (int k = 1; k < f; ++k) acc += cv::v_load_expand(grey.ptr<uint8_t>(y * f + k) + x);
      cv::v_store(sum + x, acc);
    }
#endif
    for (; x < cols; ++x) {
      uint16_t acc = 0;
      for (int k = 0; k < f; ++k) acc = uint16_t(acc + grey.ptr<uint8_t>(y * f + k)[x]);
      sum[x] = acc;
    }
    uint8_t* o = out.ptr<uint8_t>(y);
    int ox = 0;
#if CV_SIMD128
    if constexpr (F == 3) {
      for (; ox + 8 <= out.cols; ox += 8) {
        cv::v_uint16x8 a, b, c;
        cv::v_load_deinterleave(sum + 3 * ox, a, b, c);
        cv::v_pack_store(o + ox, cv::v_mul_hi(a + b + c + cv::v_setall_u16(4), cv::v_setall_u16(7282)));
      }
    } else if constexpr (F == 4) {
      for (; ox + 8 <= out.cols; ox += 8) {
        cv::v_uint16x8 a, b, c, d;
        cv::v_load_deinterleave(sum + 4 * ox, a, b, c, d);
        cv::v_pack_store(o + ox, (a + b + c + d + cv::v_setall_u16(8)) >> 4);
      }
    }
#endif
    for (; ox < out.cols; ++ox) {
      uint32_t block = 0;
      for (int k = 0; k < f; ++k) block += sum[size_t(ox * f + k)];
      o[ox] = uint8_t((block + area / 2) / area);
    }
  }
}
}  // namespace

cv::Mat decimate(const cv::Mat& grey, int factor) {
  if (factor <= 1) return grey;
  // The block mean: noise averages out, and a marker's dark frame stays dark.
  CV_Assert(grey.type() == CV_8UC1 && factor <= 16);  // a 16x16 block's sum fits 16 bits
  cv::Mat out(grey.rows / factor, grey.cols / factor, CV_8UC1);
  if (factor == 2) {  // cv::resize's INTER_AREA to the level (its halving path), at a third of its time
    for (int y = 0; y < out.rows; ++y)
      halve_rows(grey.ptr<uint8_t>(2 * y), grey.ptr<uint8_t>(2 * y + 1), out.ptr<uint8_t>(y), out.cols);
    return out;
  }
  // Other factors: INTER_AREA takes its general path on the whole image, spreading the leftover columns over every
  // block, and its integer-factor path on the whole blocks is slower still (1.6 ms for 1920x1080 at 3). Here the
  // leftover is dropped, as undecimate assumes.
  switch (factor) {
    case 3: decimate_rows<3>(grey, out, factor); break;
    case 4: decimate_rows<4>(grey, out, factor); break;
    case 5: decimate_rows<5>(grey, out, factor); break;
    case 6: decimate_rows<6>(grey, out, factor); break;
    default: decimate_rows<0>(grey, out, factor); break;
  }
  return out;
}

cv::Mat search_image(GreyOnDemand& grey, const cv::Rect& region, int factor) {
  const cv::Mat& colour = grey.colour();
  if (factor == 2 && colour.type() == CV_8UC3 && region == cv::Rect(0, 0, colour.cols, colour.rows))
    return grey.convert_all_and_halve();
  grey.need(region);
  return decimate(grey.image()(region), factor);
}

// [SECTION] adaptive_threshold

namespace {
#if defined(__x86_64__) || defined(__i386__)
// adaptive_threshold's comparison with AVX2, 32 pixels (16 block means) at a time, the same arithmetic as the
// universal intrinsics' 16 below (which OpenCV's headers give 128 bits here): the unpacks and packs work within
// each 128-bit lane, and the means of lane k are pixels 16k..16k+15, so the bytes come out in order. Returns how
// many block means it did (a multiple of 16). The stage at 640x480: 0.125 -> 0.10 ms; 1920x1080's half-size
// search: 0.21 -> 0.17 ms.
__attribute__((target("avx2"))) int threshold_row_avx2(const uint16_t* v, int mw, const uint8_t* g, uint8_t* b,
                                                     int offset) {
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
  return i;
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"   // as grey_row_avx512's
#endif
// AVX-512: threshold_row_avx2's 16 block means a step as 32 (a 128-bit lane's means still make its 16 pixels), the
// comparison into a mask register and out as bytes. And the row of vertically blended means before it, 3 near + far,
// 32 a step. Each returns how many block means it did.
__attribute__((target("avx512f,avx512bw,avx512vl"))) int threshold_row_avx512(const uint16_t* v, int mw,
                                                                              const uint8_t* g, uint8_t* b,
                                                                              int offset) {
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
  return i;
}
__attribute__((target("avx512f,avx512bw,avx512vl"))) int blend_row_avx512(const uint8_t* near, const uint8_t* far,
                                                                          uint16_t* v, int mw) {
  int i = 0;
  for (; i + 32 <= mw; i += 32) {
    const __m512i n = _mm512_cvtepu8_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(near + i)));
    const __m512i f = _mm512_cvtepu8_epi16(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(far + i)));
    _mm512_storeu_si512(v + i, _mm512_add_epi16(_mm512_add_epi16(_mm512_slli_epi16(n, 1), n), f));
  }
  return i;
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

// One row's sums of K along it from its widened, padded row, 16 a step (row_sums_avx2).
template <int K>
__attribute__((target("avx2"))) int row_sums_k(const uint16_t* pad, int w, uint16_t* out) {
  int x = 0;
  for (; x + 16 <= w; x += 16) {
    __m256i even = _mm256_setzero_si256(), odd = _mm256_setzero_si256();
    for (int j = 0; j + 1 < K; j += 2) {
      even = _mm256_add_epi16(even, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pad + x + j)));
      odd = _mm256_add_epi16(odd, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pad + x + j + 1)));
    }
    if (K % 2) even = _mm256_add_epi16(even, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pad + x + K - 1)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + x), _mm256_add_epi16(even, odd));
  }
  return x;
}

// One row's sums of k along it (border replicated), through `pad` (w + k - 1 levels, widened to 16 bits once, so
// that the k shifted loads a vector are plain loads, not k widening shuffles: those were the bottleneck), in two
// chains of additions.
__attribute__((target("avx2"))) void row_sums_avx2(const uint8_t* in, int w, int k, uint16_t* pad, uint16_t* out) {
  const int r = k / 2;
  std::fill_n(pad, r, in[0]);
  int x = 0;
  for (; x + 16 <= w; x += 16)
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(pad + r + x),
                        _mm256_cvtepu8_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(in + x))));
  for (; x < w; ++x) pad[r + x] = in[x];
  std::fill_n(pad + r + w, r, in[w - 1]);
  switch (k) {   // the window's loads unrolled for the sizes the threshold uses (5 to 15)
    case 5: x = row_sums_k<5>(pad, w, out); break;
    case 7: x = row_sums_k<7>(pad, w, out); break;
    case 9: x = row_sums_k<9>(pad, w, out); break;
    case 11: x = row_sums_k<11>(pad, w, out); break;
    case 13: x = row_sums_k<13>(pad, w, out); break;
    case 15: x = row_sums_k<15>(pad, w, out); break;
    default: x = 0;
  }
  for (; x < w; ++x) {
    int sum = 0;
    for (int j = 0; j < k; ++j) sum += pad[x + j];
    out[x] = uint16_t(sum);
  }
}

// The box filter's mean of k x k pixels (k odd, border replicated), rounded to the nearest as cv::boxFilter's (a
// k x k sum over an odd count is never halfway), with AVX2: each row's sums of k along it (k shifted loads a vector),
// then a running sum of k rows down each column, divided by a 16-bit multiply-high and a shift. For windows up to
// 15 (the sums fit 16 bits); false leaves it to cv::boxFilter. 320x240 at 9 (the 640x480 threshold's): 0.05 -> 0.025
// ms.
__attribute__((target("avx2"))) bool box_mean_avx2(const cv::Mat& src, cv::Mat& dst, int k) {
  const int w = src.cols, h = src.rows, r = k / 2, d = k * k;
  if (k % 2 == 0 || k > 15 || w < 16 || h < 1) return false;
  // (sum + d / 2) / d as (x * m) >> (16 + shift), m = ceil(2^(16 + shift) / d) below 2^16. With e = m d - 2^(16 +
  // shift), x m / 2^(16 + shift) = x / d + x e / (d 2^(16 + shift)): the floor is x / d's for every x up to the
  // largest sum when that largest x times e is below 2^(16 + shift) (x / d's fraction is at most (d - 1) / d).
  const int shift = std::bit_width(unsigned(d)) - 1;
  const uint64_t power = uint64_t(1) << (16 + shift);
  const uint32_t m = uint32_t((power + uint64_t(d) - 1) / uint64_t(d));
  const uint64_t largest = 255 * uint64_t(d) + uint64_t(d / 2);
  if (m > 0xFFFF || largest * (uint64_t(m) * uint64_t(d) - power) >= power) return false;
  dst.create(src.size(), CV_8UC1);
  thread_local std::vector<uint16_t> pad, rows, column;
  pad.resize(size_t(w + 2 * r));
  const size_t stride = size_t(w);
  // The row sums in a ring of k + 1 rows (the window's k and the one coming in), made as the window reaches them:
  // all of them were 150 KB at 640x480, written and read back through the cache.
  const int ring = k + 1;
  rows.resize(stride * size_t(ring));
  column.resize(stride);
  int made = -1;   // the last row whose sums are in the ring
  auto row = [&](int y) {
    y = std::clamp(y, 0, h - 1);
    uint16_t* out = rows.data() + size_t(y % ring) * stride;
    for (; made < y;) {   // rows come in order: the next one
      const int next = ++made;
      row_sums_avx2(src.ptr<uint8_t>(next), w, k, pad.data(), rows.data() + size_t(next % ring) * stride);
    }
    return static_cast<const uint16_t*>(out);
  };
  std::fill(column.begin(), column.end(), uint16_t(0));
  for (int y = -r; y <= r; ++y) {
    const uint16_t* in = row(y);
    for (int x = 0; x < w; ++x) column[size_t(x)] = uint16_t(column[size_t(x)] + in[x]);
  }
  const __m256i mul = _mm256_set1_epi16(short(m)), half = _mm256_set1_epi16(short(d / 2));
  const __m128i bits = _mm_cvtsi32_si128(shift);
  for (int y = 0; y < h; ++y) {
    uint8_t* out = dst.ptr<uint8_t>(y);
    const uint16_t* drop = row(y - r);   // before the row coming in, which may take its place in the ring
    const uint16_t* add = row(y + r + 1);
    uint16_t* c = column.data();
    int x = 0;
    for (; x + 16 <= w; x += 16) {
      const __m256i sum = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(c + x));
      const __m256i mean = _mm256_srl_epi16(_mm256_mulhi_epu16(_mm256_add_epi16(sum, half), mul), bits);
      const __m256i packed = _mm256_permute4x64_epi64(_mm256_packus_epi16(mean, mean), 0x08);   // qwords 0, 2
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + x), _mm256_castsi256_si128(packed));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(c + x),
                          _mm256_sub_epi16(_mm256_add_epi16(sum, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(
                                                                    add + x))),
                                           _mm256_loadu_si256(reinterpret_cast<const __m256i*>(drop + x))));
    }
    for (; x < w; ++x) {
      out[x] = uint8_t(((uint32_t(c[x]) + uint32_t(d / 2)) * m) >> (16 + shift));
      c[x] = uint16_t(c[x] + add[x] - drop[x]);
    }
  }
  return true;
}
#endif

// adaptive_threshold's window mean: box_mean_avx2 where it can, else cv::boxFilter.
void box_mean(const cv::Mat& src, cv::Mat& dst, int k) {
#if defined(__x86_64__) || defined(__i386__)
  if (simd() >= Simd::avx2 && box_mean_avx2(src, dst, k)) return;
#endif
  cv::boxFilter(src, dst, CV_8U, cv::Size(k, k), cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
}
}  // namespace

cv::Mat adaptive_threshold(const cv::Mat& grey, const DetectorParams& p, cv::Mat* block_means) {
  cv::Mat binary;
  if (block_means) block_means->release();
  const int window = p.threshold_window_px | 1;  // the mean needs an odd window
  if (window < 9 || grey.cols < 32 || grey.rows < 32) {
    cv::adaptiveThreshold(grey, binary, 255, cv::ADAPTIVE_THRESH_MEAN_C, cv::THRESH_BINARY_INV, window,
                          p.threshold_offset);
    return binary;
  }
  // A window of 9 pixels or more: its mean is taken over the image's 2x2 block means, a window half as wide, and
  // brought back to every pixel bilinearly. The mean of a wide window hardly changes from one pixel to the next,
  // so this is as good for the threshold and a third of the work; the block means also calm sensor noise in the
  // mean (on the hard bench set, dim scenes: 69.7 -> 75.8 % of markers found). Each pixel itself is compared at
  // full resolution: small markers keep their quiet zones.
  // The blocks are the whole 2x2 blocks, decimate(grey, 2): cv::resize's INTER_AREA to the level (an odd side had
  // sent that to its general path, twenty times slower: a 641x361 region 0.57 ms), by our own halving, a third of
  // its halving path's time (hot, 640x480: 14 -> 4.4 us). An odd last column or row takes the mean of the blocks
  // beside it.
  const cv::Size whole(grey.cols / 2, grey.rows / 2);
  cv::Mat mean;
  const cv::Mat blocks = decimate(grey, 2);
  const int half = (window / 2) | 1;
  box_mean(blocks, mean, half);
  if (block_means) *block_means = blocks;
  // Brought back to the full size bilinearly and compared there, in one pass: black where grey + offset <= mean
  // (saturating, as cv::add would). At twice the size, bilinear weighs the two nearest block means 3:1 along each
  // axis (OpenCV's INTER_LINEAR, clamped at the edges the same way; here exact, where its fixed point may round a
  // level apart), so no full-size mean is written and read back: cv::resize's upsizing was more than half the
  // stage (0.12 of 0.21 ms at 640x480, 0.77 ms at 1920x1080 on the bench machine). An odd last row or column takes
  // the mean of the one before it. Vectorised with OpenCV's universal intrinsics.
  binary.create(grey.size(), CV_8UC1);
  const int offset = cv::saturate_cast<uint8_t>(p.threshold_offset);
  const int mw = mean.cols, mh = mean.rows;
  thread_local std::vector<uint16_t> vbuf;   // one row of vertically blended means, clamped one past each end
  vbuf.resize(size_t(mw) + 2);
  uint16_t* v = vbuf.data() + 1;
#if defined(__x86_64__) || defined(__i386__)
  const Simd level = simd();
#endif
  for (int y = 0; y < grey.rows; ++y) {
    const int yy = std::min(y, 2 * mh - 1);   // an odd last row: the row before it
    const int j = yy / 2;
    const int far = std::clamp(yy % 2 ? j + 1 : j - 1, 0, mh - 1);
    const uint8_t* mn = mean.ptr<uint8_t>(j);
    const uint8_t* mf = mean.ptr<uint8_t>(far);
    int i = 0;
#if defined(__x86_64__) || defined(__i386__)
    if (level >= Simd::avx512) i = blend_row_avx512(mn, mf, v, mw);
#endif
#if CV_SIMD
    for (; i + cv::v_uint16::nlanes <= mw; i += cv::v_uint16::nlanes) {
      const cv::v_uint16 n = cv::vx_load_expand(mn + i), f = cv::vx_load_expand(mf + i);
      cv::v_store(v + i, (n << 1) + n + f);
    }
#endif
    for (; i < mw; ++i) v[i] = uint16_t(3 * mn[i] + mf[i]);
    v[-1] = v[0];
    v[mw] = v[mw - 1];
    const uint8_t* g = grey.ptr<uint8_t>(y);
    uint8_t* b = binary.ptr<uint8_t>(y);
    i = 0;
#if defined(__x86_64__) || defined(__i386__)
    if (level >= Simd::avx512) i = threshold_row_avx512(v, mw, g, b, offset);
    if (level >= Simd::avx2) i += threshold_row_avx2(v + i, mw - i, g + 2 * i, b + 2 * i, offset);
#endif
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
    if (grey.cols % 2) put(grey.cols - 1, (3 * v[mw - 1] + v[mw] + 8) >> 4);
  }
  return binary;
}

// [SECTION] contours

namespace {

// Union-find over the runs, in an array of its own (dense for the joins and the final pass): a run's parent is never
// after it, so a root is the first run of its region in raster order, which holds the region's top-left pixel.
int find_root(std::vector<int>& parent, int i) {
  while (parent[size_t(i)] != i) {
    parent[size_t(i)] = parent[size_t(parent[size_t(i)])];  // path halving
    i = parent[size_t(i)];
  }
  return i;
}

// Bit k set where pixel x + k of the row is on (nonzero; zero when Light), for the up to 64 pixels from x; none
// past w.
template <bool Light>
uint64_t row_mask(const uint8_t* row, int x, int w) {
  uint64_t m = 0;
  int k = 0;
#if CV_SIMD128
  // Compared with zero, a lane is all ones where its pixel is nonzero: the sign bits are the mask, 16 pixels at a
  // time while they are inside the row (a row's last word too: coarse_search's 160-pixel rows end half-way through
  // one, and pixel by pixel it was a sixth of that stage).
  const cv::v_uint8x16 zero = cv::v_setzero_u8();
  for (; k < 64 && x + k + 16 <= w; k += 16)
    m |= uint64_t(uint32_t(cv::v_signmask(cv::v_load(row + x + k) > zero))) << k;
  if (Light) m = ~m & (k == 64 ? ~uint64_t(0) : (uint64_t(1) << k) - 1);
#endif
  for (; k < 64 && x + k < w; ++k) m |= uint64_t((row[x + k] != 0) != Light) << k;
  return m;
}

#if defined(__x86_64__) || defined(__i386__)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"   // as grey_row_avx512's
#endif
// A row's whole words of masks: AVX-512's byte test gives a word in one instruction, AVX2's two compares and
// movemasks (row_mask's 16 pixels at a time was 15 % of the contours stage at 640x480). Returns the words done.
template <bool Light>
__attribute__((target("avx512f,avx512bw"))) int row_masks_avx512(const uint8_t* row, int w, uint64_t* out) {
  int c = 0;
  for (; 64 * c + 64 <= w; ++c) {
    const __m512i v = _mm512_loadu_si512(row + 64 * c);
    out[c] = Light ? _mm512_testn_epi8_mask(v, v) : _mm512_test_epi8_mask(v, v);
  }
  return c;
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
template <bool Light>
__attribute__((target("avx2"))) int row_masks_avx2(const uint8_t* row, int w, uint64_t* out) {
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
#endif

// A row's masks, words (w + 63) / 64 of them.
template <bool Light>
void row_masks(const uint8_t* row, int w, int words, uint64_t* out) {
  int c = 0;
#if defined(__x86_64__) || defined(__i386__)
  const Simd level = simd();
  if (level >= Simd::avx512) c = row_masks_avx512<Light>(row, w, out);
  else if (level >= Simd::avx2) c = row_masks_avx2<Light>(row, w, out);
#endif
  for (; c < words; ++c) out[c] = row_mask<Light>(row, 64 * c, w);
}

// A buffer kept from call to call grows to n and never shrinks: growing it again, for the next frame after a smaller
// image (coarse_search's), would zero its new part.
template <typename T>
void at_least(std::vector<T>& buffer, size_t n) {
  if (buffer.size() < n) buffer.resize(n);
}

// A row's edges: bit k of edge word c is set where pixel 64c + k differs from the one before it, where a run of the
// row begins or ends. A row's masks have `words` words and its end word of nothing after them, so its edge words
// are words + 1: the last holds the end of a run that reaches the row's end at a multiple of 64. before[c] is the
// number of edges in the words before c.
struct RowEdges {
  std::vector<uint64_t> bits;
  std::vector<int> before;
  void reserve(int words) {
    at_least(bits, size_t(words) + 1);
    at_least(before, size_t(words) + 1);
  }
  // From a row's masks (`words` of them and the end word).
  [[gnu::always_inline]] int find(const uint64_t* mid, int words) {
    uint64_t carry = 0;   // the pixel before the current 64, as bit 0
    int n = 0;
    for (int c = 0; c <= words; ++c) {
      const uint64_t m = mid[c];
      const uint64_t e = m ^ ((m << 1) | carry);
      carry = m >> 63;
      bits[size_t(c)] = e;
      before[size_t(c)] = n;
      n += std::popcount(e);
    }
    return n;
  }
  // The edges left of pixel x (0 <= x <= 64 * (words + 1) - 1).
  [[gnu::always_inline]] int rank(int x) const {
    const uint64_t below = bits[size_t(x >> 6)] & ((uint64_t(1) << (x & 63)) - 1);
    return before[size_t(x >> 6)] + std::popcount(below);
  }
};

// The pixels where a row's runs begin and end, from its edge words (`words` of them), in order into `out`, which
// has room for 16 past the last; returns how many. Scanning byte by byte mispredicted a branch at every edge and was
// a third of the stage on a noisy threshold; visiting the set bits by counting trailing zeros mispredicts once a
// word, when its bits run out; AVX-512 compresses the pixels of each 16 bits at once, with no branch (when this
// also made the edge bits from the masks, find_contours on the standard set's 640x480 frames, in the cache, was 4-8 %
// faster for it).
inline int row_edges_plain(const uint64_t* edge_bits, int words, int* out) {
  int n = 0;
  for (int c = 0, x = 0; c < words; ++c, x += 64)
    for (uint64_t e = edge_bits[c]; e; e &= e - 1) out[n++] = x + std::countr_zero(e);
  return n;
}
#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx512f,avx512bw,popcnt"))) int row_edges_avx512(const uint64_t* edge_bits, int words,
                                                                        int* out) {
  int n = 0;
  const __m512i sixteen = _mm512_set1_epi32(16);
  __m512i x = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  for (int c = 0; c < words; ++c) {
    const uint64_t e = edge_bits[c];
    if (e == 0) {   // no edge (most words): compressing nothing four times was half of this on AMD Zen 4
      x = _mm512_add_epi32(x, _mm512_set1_epi32(64));
      continue;
    }
    // Where each 16 bits' pixels go, from the edges before them in the word (no chain of counts through the
    // stores).
    const int at[4] = {n, n + std::popcount(e & 0xFFFF), n + std::popcount(e & 0xFFFFFFFF),
                       n + std::popcount(e & 0xFFFFFFFFFFFF)};
    for (int q = 0; q < 4; ++q) {
      _mm512_storeu_si512(out + at[q], _mm512_maskz_compress_epi32(__mmask16(e >> (16 * q)), x));
      x = _mm512_add_epi32(x, sixteen);
    }
    n += std::popcount(e);
  }
  return n;
}
#endif
inline int row_edges(const uint64_t* edge_bits, int words, int* out) {
#if defined(__x86_64__) || defined(__i386__)
  if (simd() >= Simd::avx512) return row_edges_avx512(edge_bits, words, out);
#endif
  return row_edges_plain(edge_bits, words, out);
}

// Joins each of a row's runs (`ends`: its n runs' ends in turn, the first of them run `begin`) to the runs it
// touches in the row above (from run `above_begin`, with its edges `above`). 8-connected, [a0,a1) and [b0,b1) on
// neighbouring rows touch when a0 <= b1 and b0 <= a1. A row's edges go up in turn, a0 < a1 < the next a0: the runs
// above wholly before b (a1 < b0) are half the edges left of b0, rounded down, and those that begin by b's end
// (a0 <= b1) half the edges left of b1 + 1, rounded up. Each is a count of bits in the row above's edge words,
// with no walk and no branch on the data but the number touched: the merge walk this replaced took two
// data-dependent branches a pair of runs, and the AVX-512 compares along the row above that replaced the walk grew
// with that row's runs.
[[gnu::always_inline]] inline void join_row_body(const RowEdges& above, int above_begin, const int* ends, int begin,
                                                 int n, std::vector<int>& parent) {
  for (int k = 0; k < n; ++k) {
    const int first = above.rank(ends[2 * k]) / 2, last = (above.rank(ends[2 * k + 1] + 1) + 1) / 2;
    // A run that touches one run above (nearly every run of a large region) takes that run's parent, a run of
    // the same region and before it, without looking for the root: one load, where find_root's loop cost a chain of
    // loads and a mispredicted exit. The final pass takes every run to its root. A run that touches none is its
    // own. The choice as a mask: GCC made `first < last ? ... : self` a branch, which a noisy row mispredicts.
    const int self = begin + k, touches = -int(first < last);
    parent[size_t(self)] = (parent[size_t(above_begin + first)] & touches) | (self & ~touches);
    if (last - first < 2) continue;
    // It touches two or more: their regions are one, under the earliest root.
    int joined = find_root(parent, parent[size_t(self)]);
    for (int a = above_begin + first + 1; a < above_begin + last; ++a) {
      const int r = find_root(parent, a);
      if (r < joined) {
        parent[size_t(joined)] = r;
        joined = r;
      } else if (r > joined) {
        parent[size_t(r)] = joined;
      }
    }
  }
}
#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("popcnt"))) void join_row_popcnt(const RowEdges& above, int above_begin, const int* ends,
                                                       int begin, int n, std::vector<int>& parent) {
  join_row_body(above, above_begin, ends, begin, n, parent);
}
__attribute__((target("popcnt"))) int find_edges_popcnt(RowEdges& row, const uint64_t* mid, int words) {
  return row.find(mid, words);
}
#endif
void join_row(const RowEdges& above, int above_begin, const int* ends, int begin, int n, std::vector<int>& parent) {
#if defined(__x86_64__) || defined(__i386__)
  if (simd() >= Simd::avx2) return join_row_popcnt(above, above_begin, ends, begin, n, parent);
#endif
  join_row_body(above, above_begin, ends, begin, n, parent);
}
int find_edges(RowEdges& row, const uint64_t* mid, int words) {
#if defined(__x86_64__) || defined(__i386__)
  if (simd() >= Simd::avx2) return find_edges_popcnt(row, mid, words);
#endif
  return row.find(mid, words);
}

// A binary image as bit masks: row y's `words` words at row(y), bit k of word c the pixel 64c + k. Rows of nothing
// above and below it and a word of nothing at each end of a row let the neighbours of any pixel be read unchecked.
// Read as one array from the first row's first word (its left end's), the rows and their ends follow one another
// `stride` apart: a pass along that array does every row at once, and for a word at a row's end it takes the
// pixels beside the image, which are off.
struct BitRows {
  static constexpr int kPad = 3;   // rows of nothing above and below
  uint64_t* base;
  int words, h;
  ptrdiff_t stride() const { return ptrdiff_t(words) + 2; }
  // and three words more, for a pass four words a step that ends past the padding below
  size_t size() const { return size_t(stride()) * size_t(h + 2 * kPad) + 3; }
  uint64_t* row(int y) const { return base + stride() * (y + kPad) + 1; }
  uint64_t* first() const { return row(0) - 1; }      // the array of the image's rows, with their ends
  size_t length() const { return size_t(stride()) * size_t(h); }
  void clear_padding() const {
    std::fill(base, first(), 0);
    std::fill(first() + length(), base + size(), 0);
  }
};

// GCC and clang note that a function taking or returning Four::V outside AVX2 code would pass it differently;
// they are all inlined into AVX2 code (GCC's note comes at the file's end, so it is silenced from here on).
#if defined(__clang__)
#pragma clang diagnostic ignored "-Wpsabi"
#elif defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
// drop_small_regions' words, one at a time (Scalar) or four (Four), with the same operators (|, &, ^, ~).
struct Scalar {
  using V = uint64_t;
  static constexpr int kWords = 1;
  static V load(const uint64_t* at) { return *at; }
  static void store(uint64_t* at, V v) { *at = v; }
  template <int S> static V left(V v) { return v << S; }
  template <int S> static V right(V v) { return v >> S; }
  static int bits(V v) { return std::popcount(v); }
};
// Four words in GCC's vector extension, with the same operators: in drop_small_regions_avx2 one AVX2 instruction
// each (its helpers are always inlined there, so no AVX vector crosses a call and -Wpsabi's ABI note is moot).
struct Four {
  typedef uint64_t V __attribute__((vector_size(32)));
  static constexpr int kWords = 4;
  [[gnu::always_inline]] static V load(const uint64_t* at) {
    V v;
    std::memcpy(&v, at, sizeof v);
    return v;
  }
  [[gnu::always_inline]] static void store(uint64_t* at, V v) { std::memcpy(at, &v, sizeof v); }
  template <int S> [[gnu::always_inline]] static V left(V v) { return v << S; }
  template <int S> [[gnu::always_inline]] static V right(V v) { return v >> S; }
  [[gnu::always_inline]] static int bits(V v) {
    return std::popcount(v[0]) + std::popcount(v[1]) + std::popcount(v[2]) + std::popcount(v[3]);
  }
};

// Bit x of the result: pixel x - S (S > 0, from the left) or x + |S| (S < 0) of the word(s) at `at`, with the
// word before or after.
template <typename W, int S>
[[gnu::always_inline]] inline typename W::V moved(const uint64_t* at) {
  if constexpr (S > 0) return W::template left<S>(W::load(at)) | W::template right<64 - S>(W::load(at - 1));
  else return W::template right<-S>(W::load(at)) | W::template left<64 + S>(W::load(at + 1));
}

// Each pixel set where a pixel within R of it along the row is.
template <typename W, int R>
[[gnu::always_inline]] inline typename W::V spread_along(const uint64_t* at) {
  if constexpr (R == 0) return W::load(at);
  else return spread_along<W, R - 1>(at) | moved<W, R>(at) | moved<W, -R>(at);
}

// The pixels of rows y - R .. y + R, at the word(s) of row y at `at`.
template <typename W, int R>
[[gnu::always_inline]] inline typename W::V rows_around(const uint64_t* at, ptrdiff_t stride) {
  typename W::V v = W::load(at);
  for (int dy = 1; dy <= R; ++dy) v = v | W::load(at - dy * stride) | W::load(at + dy * stride);
  return v;
}

// Takes the specks out of `bits`, the pixels on with none of their eight neighbours on (each a region of its own),
// and returns how many it took when Count (else 0): in one pass, each pixel kept where a neighbour is on (into a
// buffer, then back). On a noisy threshold the specks sit in the rings drop_small_regions_body reads, and kept
// the small regions they ring from being taken: taking them first left about a quarter fewer runs on the 640x480
// frames of the hard and standard sets (36h11: 7176 -> 5290 and 4876 -> 3752 a frame), for a pass much cheaper than
// the 1x1 window of drop_small_regions_body's that it replaced.
template <typename W, bool Count>
[[gnu::always_inline]] inline int drop_specks_body(const BitRows& bits) {
  const ptrdiff_t s = bits.stride(), n = ptrdiff_t(bits.length());
  thread_local std::vector<uint64_t> near_buf;
  at_least(near_buf, bits.size());
  uint64_t* on = bits.first();
  uint64_t* near = near_buf.data() + (on - bits.base);
  for (ptrdiff_t i = 0; i < n; i += W::kWords)
    W::store(near + i, spread_along<W, 1>(on + i - s) | spread_along<W, 1>(on + i + s) | moved<W, 1>(on + i) |
                           moved<W, -1>(on + i));
  int count = 0;
  for (ptrdiff_t i = 0; i < n; i += W::kWords) {
    const typename W::V m = W::load(on + i), kept = m & W::load(near + i);
    if constexpr (Count) count += W::bits(m & ~kept);
    W::store(on + i, kept);
  }
  return count;
}

// Takes out of `bits` every region that fits in a K x K window (K odd) with no pixel on in the ring of pixels just
// outside it, and returns how many it took when Count (else 0). Such a region is a whole region (a step out of the
// window lands on the ring), and nearly every region that fits in K x K pixels has such a window: those go, without
// labelling a pixel. Per window centre the ring is read as whole words: its rows
// above and below, spread along the row, and its columns at each side, from the rows beside the centre's. The
// pixels within r = K / 2 of a centre whose ring is empty are the ones taken. A centre beside the image is as good
// as one in it (the pixels there are off). Each pass runs along the whole array of rows, W::kWords words a step
// (the arrays' padding takes the last step's overrun). A region with another region's pixel in every ring around
// it stays, and is counted and left untraced as before.
// The count, for K = 3: Gray's bit-quad Euler number of the pixels taken (for
// 8-connected regions: the number of 2x2 blocks with one pixel on, less those with three, less twice the diagonal
// pairs, over 4) is their regions less their holes, and a region in 3x3 pixels has a hole only at its centre, an off
// pixel with its four neighbours on.
template <typename W, int K, bool Count>
[[gnu::always_inline]] inline int drop_small_regions_body(const BitRows& bits) {
  static_assert(K % 2 == 1 && K >= 3 && K / 2 + 1 <= BitRows::kPad,
                "the ring's rows must lie within the masks' padding (and specks have drop_specks_body)");
  static_assert(K <= 3 || !Count, "the count knows the holes of regions in 3x3 pixels only");
  constexpr int r = K / 2, d = r + 1, step = W::kWords;
  const ptrdiff_t s = bits.stride(), n = ptrdiff_t(bits.length());
  thread_local std::vector<uint64_t> spread_buf, column_buf, free_buf;
  for (auto* buf : {&spread_buf, &column_buf, &free_buf}) at_least(*buf, bits.size());
  const BitRows spread{spread_buf.data(), bits.words, bits.h}, column{column_buf.data(), bits.words, bits.h},
      empty_ring{free_buf.data(), bits.words, bits.h};
  spread.clear_padding();
  column.clear_padding();
  empty_ring.clear_padding();
  uint64_t* on = bits.first();
  uint64_t *sp = spread.first(), *v = column.first(), *f = empty_ring.first();
  for (ptrdiff_t i = 0; i < n; i += step) {
    W::store(sp + i, spread_along<W, d>(on + i));    // the ring's rows above and below
    W::store(v + i, rows_around<W, r>(on + i, s));   // its columns, before they are moved aside
  }
  for (ptrdiff_t i = 0; i < n; i += step)
    W::store(f + i, ~(W::load(sp + i - d * s) | W::load(sp + i + d * s) | moved<W, d>(v + i) | moved<W, -d>(v + i)));
  // A last step past the rows found centres below the image whose ring's columns it could not read (the word after
  // it was never written): they certify nothing. Every other word the passes read past the rows is zero, as the
  // pixels there are (`Stages.SmallRegionsLeaveALongBarOnTheLastRowWhole`).
  std::fill(f + n, empty_ring.base + empty_ring.size(), 0);
  // The pixels near a centre whose ring is empty: those centres spread along their rows (into `spread`, its rings'
  // rows no longer needed) and over the rows around.
  for (ptrdiff_t i = 0; i < n; i += step) W::store(sp + i, spread_along<W, r>(f + i));
  uint64_t* taken = v;   // the pixels taken, for the count (`column` no longer needed)
  int count = 0;
  for (ptrdiff_t i = 0; i < n; i += step) {
    const typename W::V m = W::load(on + i), t = m & rows_around<W, r>(sp + i, s);
    W::store(on + i, m & ~t);
    if constexpr (Count) W::store(taken + i, t);
  }
  if constexpr (Count) {
    // The last step's overrun wrote past the rows: the count reads the padding below them.
    std::fill(taken + n, column.base + column.size(), 0);
    int one = 0, three = 0, diagonal = 0, holes = 0;
    // The 2x2 blocks of pixels x - 1 and x of rows y and y + 1, from y = -1.
    for (ptrdiff_t i = -s; i < n; i += step) {
      const typename W::V tl = moved<W, 1>(taken + i), tr = W::load(taken + i), bl = moved<W, 1>(taken + i + s),
                          br = W::load(taken + i + s);
      const typename W::V odd = tl ^ tr ^ bl ^ br, two = (tl & tr) | (bl & br) | ((tl | tr) & (bl | br));
      one += W::bits(odd & ~two);
      three += W::bits(odd & two);
      diagonal += W::bits((tl & br & ~tr & ~bl) | (tr & bl & ~tl & ~br));
    }
    for (ptrdiff_t i = 0; i < n; i += step)
      holes += W::bits(~W::load(taken + i) & W::load(taken + i - s) & W::load(taken + i + s) &
                       moved<W, 1>(taken + i) & moved<W, -1>(taken + i));
    count = (one - three - 2 * diagonal) / 4 + holes;
  }
  return count;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
template <int K, bool Count>
__attribute__((target("avx2,popcnt"))) int drop_small_regions_avx2(const BitRows& bits) {
  return drop_small_regions_body<Four, K, Count>(bits);
}
template <bool Count>
__attribute__((target("avx2,popcnt"))) int drop_specks_avx2(const BitRows& bits) {
  return drop_specks_body<Four, Count>(bits);
}
template <int K, bool Count>
int drop_small_regions(const BitRows& bits) {
  return simd() >= Simd::avx2 ? drop_small_regions_avx2<K, Count>(bits) : drop_small_regions_body<Scalar, K, Count>(bits);
}
template <bool Count>
int drop_specks(const BitRows& bits) {
  return simd() >= Simd::avx2 ? drop_specks_avx2<Count>(bits) : drop_specks_body<Scalar, Count>(bits);
}
#else
template <int K, bool Count>
int drop_small_regions(const BitRows& bits) {
  return drop_small_regions_body<Scalar, K, Count>(bits);
}
template <bool Count>
int drop_specks(const BitRows& bits) {
  return drop_specks_body<Scalar, Count>(bits);
}
#endif

// The small regions a border of min_perimeter_px leaves out, taken out of `bits`; their number when `count`. The
// specks first, then, of what is left, the regions in 5x5 pixels when a 5x5 box's border (20 pixels) is short and
// they need no count, else in 3x3 (12).
int drop_small_regions(const BitRows& bits, double min_perimeter_px, bool count) {
  if (min_perimeter_px <= 4.0) return 0;
  const int specks = count ? drop_specks<true>(bits) : drop_specks<false>(bits);
  if (20.0 < min_perimeter_px && !count) return drop_small_regions<5, false>(bits);
  if (12.0 < min_perimeter_px)
    return specks + (count ? drop_small_regions<3, true>(bits) : drop_small_regions<3, false>(bits));
  return specks;
}

// Moore-neighbour tracing of outer borders, several at once. Each border starts at its region's top-left pixel
// (the pixel to its west is background, so the first scan starts there) and goes clockwise on screen; at each
// border pixel the next is the first on pixel of its eight neighbours, scanned clockwise from the background pixel
// examined just before the step (the eight directions E SE S SW W NW N NE, 0 to 7). The trace ends when it is back
// at the start going the same way as at first.
//
// The pixels come from the contours' bit masks (`bits`: on where the region's pixels are, nothing beyond the image),
// a pixel's three rows of three neighbours in three 16-bit loads, and the next direction comes from a table of
// them (kMooreNext): no branch on the neighbours. One border's steps wait on each other (the loads, then the
// table, then the next pixel's loads), so kLanes borders are traced in turn, one step each, and the processor
// overlaps them. Tracing one border with a branch per neighbour mispredicted about once a step; the lanes take
// about half the time (the standard set's 640x480 frames, 5700 border pixels a frame: some 20 us a frame less).
struct BorderTrace {
  cv::Point start;
  std::vector<cv::Point>* out;
};
// The Moore trace's step as a table: for the direction a pixel's scan starts from (0 to 7, E SE S SW W NW N NE,
// clockwise on screen) and its nine pixels (around() below: the row above in bits 0-2, its own row in 3-5, the row
// below in 6-8, each from x - 1), the direction of the first on neighbour clockwise from there (bits 0-2) and where
// the scan at that neighbour starts (bits 3-5): the background pixel examined just before the step, seen from the
// new pixel. kMooreNone when no neighbour is on.
constexpr uint8_t kMooreNone = 0xFF;
constexpr std::array<std::array<uint8_t, 512>, 8> moore_next_table() {
  std::array<std::array<uint8_t, 512>, 8> table{};
  for (int from = 0; from < 8; ++from)
    for (int nine = 0; nine < 512; ++nine) {
      const auto bit = [&](int k) { return (nine >> k) & 1; };
      // E SE S SW W NW N NE
      const int ring[8] = {bit(5), bit(8), bit(7), bit(6), bit(3), bit(0), bit(1), bit(2)};
      uint8_t entry = kMooreNone;
      for (int k = 0; k < 8; ++k) {
        const int d = (from + k) & 7;
        if (ring[d]) {
          entry = uint8_t(d | ((d & 1) ? (d + 5) & 7 : (d + 6) & 7) << 3);
          break;
        }
      }
      table[size_t(from)][size_t(nine)] = entry;
    }
  return table;
}
constexpr auto kMooreNext = moore_next_table();

void trace_outer_borders(const BitRows& bits, int w, int h, const std::vector<BorderTrace>& borders) {
  static constexpr int dx[8] = {1, 1, 0, -1, -1, -1, 0, 1};  // E SE S SW W NW N NE: clockwise on screen
  static constexpr int dy[8] = {0, 1, 1, 1, 0, -1, -1, -1};
  // A pixel is the bit index, from the masks' base (the padding's first word), of the pixel to its west: x - 1 of
  // its row.
  const int64_t row_bits = int64_t(bits.stride()) * 64;
  int64_t step[8];
  for (int k = 0; k < 8; ++k) step[k] = dy[k] * row_bits + dx[k];
  const uint8_t* base = reinterpret_cast<const uint8_t*>(bits.base);
  auto at = [&](cv::Point p) { return (int64_t(p.y) + BitRows::kPad) * row_bits + 64 + p.x - 1; };
  // The nine pixels around `b` as bits: x - 1, x and x + 1 of the row above (bits 0-2), of its own row (3-5) and of
  // the row below (6-8). The rows are a whole number of words apart, so the three share one shift.
  const int64_t row_bytes = row_bits / 8;
  auto around = [&](int64_t b) {
    const uint8_t* at_b = base + (b >> 3);
    const int sh = int(b & 7);
    uint16_t t, m, u;
    std::memcpy(&t, at_b - row_bytes, 2);
    std::memcpy(&m, at_b, 2);
    std::memcpy(&u, at_b + row_bytes, 2);
    return ((unsigned(t) >> sh) & 7u) | ((unsigned(m) >> sh) & 7u) << 3 | ((unsigned(u) >> sh) & 7u) << 6;
  };
  // A point's x and y as one word, x + 2^32 y (cv::Point's layout: x in the low half), moved by one addition: a
  // step is dx + 2^32 dy, and x stays within 0 .. 2^32 - 1, so a step west borrows as it should.
  auto pack = [](int64_t x, int64_t y) { return uint64_t(x + y * (int64_t(1) << 32)); };
  uint64_t move[8];
  for (int k = 0; k < 8; ++k) move[k] = pack(dx[k], dy[k]);
  static_assert(sizeof(cv::Point) == sizeof(uint64_t) && std::endian::native == std::endian::little,
                "a point is x then y in one word, and a mask word's bit k is its byte k / 8's bit k % 8");
  // Each lane writes its border's points into its vector, grown to the reserved length and cut to the points at the
  // end (push_back kept the vector's end in memory, a store and a load a step).
  struct Lane {
    int64_t p = 0, start = 0, second = 0;
    uint64_t xy = 0;
    int from = 0;   // where the next pixel's scan starts
    cv::Point *at = nullptr, *end = nullptr;
    std::vector<cv::Point>* out = nullptr;
  };
  constexpr int kLanes = 4;
  const size_t guard_limit = size_t(4) * size_t(w) * size_t(h) + 8;
  size_t next_border = 0;
  auto finish = [](Lane& lane) { lane.out->resize(size_t(lane.at - lane.out->data())); };
  // Lane takes the next border that is more than one pixel; false when none is left.
  auto begin = [&](Lane& lane) {
    while (next_border < borders.size()) {
      const BorderTrace& b = borders[next_border++];
      b.out->assign(std::max<size_t>(b.out->capacity(), 16), cv::Point());
      b.out->front() = b.start;
      const int64_t s = at(b.start);
      const int e = kMooreNext[4][around(s)];
      if (e == kMooreNone) {   // a single pixel
        b.out->resize(1);
        continue;
      }
      const int d = e & 7;
      lane = {s + step[d], s, s + step[d], pack(b.start.x + dx[d], b.start.y + dy[d]), e >> 3, b.out->data() + 1,
              b.out->data() + b.out->size(), b.out};
      return true;
    }
    return false;
  };
  // A lane out of room: its vector twice as long, or the border cut there (a guard; a border is at most four steps
  // a pixel).
  auto grow = [&](Lane& lane) {
    const size_t n = size_t(lane.at - lane.out->data());
    if (n >= guard_limit) return false;
    lane.out->resize(2 * n);
    lane.at = lane.out->data() + n;
    lane.end = lane.out->data() + lane.out->size();
    return true;
  };
  Lane lanes[kLanes];
  bool busy[kLanes];
  int running = 0;
  for (int l = 0; l < kLanes; ++l) running += busy[l] = begin(lanes[l]);
  while (running > 0) {
#pragma GCC unroll 4
    for (int l = 0; l < kLanes; ++l) {
      if (!busy[l]) continue;
      Lane& a = lanes[l];
      const int e = kMooreNext[a.from][around(a.p)];   // never kMooreNone: the pixel came from an on neighbour
      const int nd = e & 7;
      const int64_t q = a.p + step[nd];
      if ((a.p == a.start && q == a.second) || (a.at == a.end && !grow(a))) {
        finish(a);
        if (!(busy[l] = begin(a))) --running;
        continue;
      }
      std::memcpy(static_cast<void*>(a.at++), &a.xy, sizeof a.xy);
      a.p = q;
      a.xy += move[nd];
      a.from = e >> 3;
    }
  }
}

// find_contours of the nonzero regions, or when Light of the zero ones. `keep`, when given, is asked about each
// region about to be traced, with its box undecimated (the grey image's scale, from the binary's origin): false
// leaves it untraced.
template <bool Light>
std::vector<std::vector<cv::Point>> region_contours(const cv::Mat& binary, double min_perimeter_px,
                                                    int* region_count, std::vector<SmallRegion>* small, int factor,
                                                    int max_side_px,
                                                    const std::function<bool(const cv::Rect&)>& keep = {}) {
  factor = std::max(factor, 1);
  min_perimeter_px /= factor;
  CV_Assert(binary.type() == CV_8UC1);
  const int w = binary.cols, h = binary.rows;
  // The runs and boxes of one call, kept per thread from call to call: a noisy 640x480 frame has 28000 runs, and
  // growing and zeroing fresh buffers that large every frame cost more than the scan.
  thread_local std::vector<int> ends;   // run i is [ends[2i], ends[2i + 1]) on its row
  thread_local std::vector<int> row_begin;   // row y's runs are from row_begin[y] to row_begin[y + 1]
  thread_local std::vector<int> parent;
  int run_count = 0;   // the runs so far (the buffers only grow: resizing them row by row zeroed each new part)
  // The image as bit masks, 64 pixels a word (one bit a pixel, set where it is on), row by row, with rows of
  // nothing above and below and a word of nothing at each end of a row.
  const int words = (w + 63) / 64;
  thread_local std::vector<uint64_t> masks;
  BitRows bits{nullptr, words, h};
  at_least(masks, bits.size());
  bits.base = masks.data();
  bits.clear_padding();
  for (int y = 0; y < h; ++y) {
    const uint8_t* row = binary.ptr<uint8_t>(y);
    uint64_t* out = bits.row(y);
    out[-1] = out[words] = 0;
    row_masks<Light>(row, w, words, out);
  }
  // Small regions: on a noisy frame nearly all regions are a few pixels (640x480: 4100 of 4300 fit in a 3x3 box),
  // and they made most of the runs. Those whose box could not hold a border of min_perimeter_px are taken out of the
  // masks and only counted (the region count stays exact), never made runs: the one-pixel ones (specks), then the
  // regions that fit in 5x5 pixels when a 5x5 box's border, 20 pixels, is short and they need no count, else in 3x3
  // pixels (12). Not when `small` lists the small regions: it keeps them in the regions' order.
  const int dropped = small ? 0 : drop_small_regions(bits, min_perimeter_px, region_count != nullptr);
  int prev_begin = 0;
  thread_local RowEdges above, here;   // the row above's edges and this row's
  above.reserve(words);
  here.reserve(words);
  std::fill_n(above.bits.begin(), words + 1, 0);   // the row above the first: nothing
  std::fill_n(above.before.begin(), words + 1, 0);
  at_least(row_begin, size_t(h) + 1);
  for (int y = 0; y < h; ++y) {
    const int begin = row_begin[size_t(y)] = run_count;
    // A run begins or ends where a bit differs from the one before it: the row's edge bits (RowEdges::find), their
    // pixels written in turn (row_edges), and the runs are their pairs.
    find_edges(here, bits.row(y), words);
    at_least(ends, 2 * size_t(begin) + size_t(w) + 1 + 16);   // a row's edges, and 16 more (row_edges' stores)
    const int n = row_edges(here.bits.data(), words + 1, ends.data() + 2 * begin) / 2;
    run_count = begin + n;
    at_least(parent, size_t(run_count));
    join_row(above, prev_begin, ends.data() + 2 * begin, begin, n, parent);
    std::swap(above, here);
    prev_begin = begin;
  }
  row_begin[size_t(h)] = run_count;
  // Every run points at its root, in one pass (a run's parent is before it, so already points at its root), and
  // the bounding box of each region gathers at its root: the root is its first run in raster order, so it starts
  // the box and the last run seen ends it. Without a branch on the data (on a noisy frame a fifth of the runs are
  // roots, at no pattern): each run's box starts as its own, and a run widens its root's (a root, its own: no
  // change); the roots are listed as they come.
  struct Box {
    int x0, y0, x1, y1;
  };
  thread_local std::vector<Box> boxes;
  thread_local std::vector<int> roots;
  at_least(boxes, size_t(run_count));
  at_least(roots, size_t(run_count));
  for (int y = 0; y < h; ++y)
    for (int i = row_begin[size_t(y)]; i < row_begin[size_t(y) + 1]; ++i)
      boxes[size_t(i)] = {ends[2 * size_t(i)], y, ends[2 * size_t(i) + 1] - 1, y};
  int root_count = 0;
  for (int y = 0; y < h; ++y) {
    for (int i = row_begin[size_t(y)]; i < row_begin[size_t(y) + 1]; ++i) {
      const int r = parent[size_t(parent[size_t(i)])];
      parent[size_t(i)] = r;
      Box& b = boxes[size_t(r)];
      b.x0 = std::min(b.x0, ends[2 * size_t(i)]);
      b.x1 = std::max(b.x1, ends[2 * size_t(i) + 1] - 1);
      b.y1 = y;
      roots[size_t(root_count)] = i;
      root_count += r == i;
    }
  }
  std::vector<std::vector<cv::Point>> contours;
  thread_local std::vector<BorderTrace> borders;
  borders.clear();
  const int regions = root_count;
  for (int k = 0; k < root_count; ++k) {
    const int i = roots[size_t(k)];
    const Box& b = boxes[size_t(i)];
    const int bw = b.x1 - b.x0 + 1, bh = b.y1 - b.y0 + 1;
    if (2.0 * (bw + bh) < min_perimeter_px) {
      if (small) small->push_back({cv::Rect(b.x0 * factor, b.y0 * factor, bw * factor, bh * factor)});
      continue;
    }
    if (max_side_px > 0 && std::max(bw, bh) * factor > max_side_px) continue;
    if (keep) {
      const cv::Point tl = undecimate(cv::Point(b.x0, b.y0), factor), br = undecimate(cv::Point(b.x1, b.y1), factor);
      if (!keep(cv::Rect(tl, br + cv::Point(1, 1)))) continue;
    }
    contours.emplace_back().reserve(size_t(2 * (bw + bh)));   // a convex border's length: one allocation, mostly
    borders.push_back({cv::Point(ends[2 * size_t(i)], b.y0), nullptr});   // the root's run begins the box
  }
  for (size_t k = 0; k < borders.size(); ++k) borders[k].out = &contours[k];
  trace_outer_borders(bits, w, h, borders);
  if (factor > 1)
    for (auto& contour : contours)
      for (cv::Point& p : contour) p = undecimate(p, factor);
  if (region_count) *region_count = regions + dropped;
  return contours;
}

}  // namespace

std::vector<std::vector<cv::Point>> find_contours(const cv::Mat& binary, double min_perimeter_px,
                                                  int* region_count, std::vector<SmallRegion>* small, int factor,
                                                  int max_side_px, const std::function<bool(const cv::Rect&)>& keep) {
  return region_contours<false>(binary, min_perimeter_px, region_count, small, factor, max_side_px, keep);
}

std::vector<cv::Rect> quad_holes(const cv::Mat& binary, const std::vector<cv::Rect>& dark, cv::Point origin,
                                 cv::Size grey, const DetectorParams& p, int factor, const std::vector<Quad>& markers) {
  std::vector<cv::Rect> boxes;
  if (p.fine_max_side_px <= 0) return boxes;
  factor = std::max(factor, 1);
  const cv::Rect image(0, 0, binary.cols, binary.rows);
  std::vector<cv::Rect> shapes;   // in the binary's pixels
  for (const cv::Rect& d : dark) {
    if (std::max(d.width, d.height) <= p.fine_max_side_px) continue;
    const cv::Rect box = d - origin;
    const cv::Point tl(box.x / factor, box.y / factor);
    const cv::Point br((box.x + box.width - 1) / factor + 1, (box.y + box.height - 1) / factor + 1);
    shapes.push_back(cv::Rect(tl, br) & image);
  }
  merge_overlapping(shapes);
  // A light region whose centre lies in a marker read is the marker's: one of its cells, or its quiet zone on a
  // dark ground. It is not traced (at 1920x1080 the cells of the frame's large markers had been most of this work).
  std::vector<std::vector<cv::Point2f>> outlines;   // the markers' quads as polygons, made once
  for (const Quad& q : markers) outlines.emplace_back(q.begin(), q.end());
  auto outside_markers = [&](const cv::Rect& hole) {
    const cv::Point2f centre(float(hole.x) + 0.5f * float(hole.width), float(hole.y) + 0.5f * float(hole.height));
    return std::none_of(outlines.begin(), outlines.end(),
                        [&](const std::vector<cv::Point2f>& o) { return cv::pointPolygonTest(o, centre, false) >= 0; });
  };
  // A marker's inside is 5/7 of its side (ARUCO_ORIGINAL; more for larger grids): half of min_perimeter_px keeps
  // the insides of the smallest markers the search is for.
  for (const cv::Rect& s : shapes) {
    const cv::Point shift = origin + s.tl() * factor;
    // A light region at the box's edge is not inside the shape (a hole lies within its region's box): not traced.
    auto inside_box = [&](const cv::Rect& in) {
      return in.x >= factor && in.y >= factor && in.x + in.width <= (s.width - 1) * factor &&
             in.y + in.height <= (s.height - 1) * factor;
    };
    std::vector<std::vector<cv::Point>> found =
        region_contours<true>(binary(s), p.min_perimeter_px / 2, nullptr, nullptr, factor, int(p.fine_max_side_px),
                              [&](const cv::Rect& in) { return inside_box(in) && outside_markers(in + shift); });
    for (auto& c : found) {
      const cv::Rect in = cv::boundingRect(c);
      for (cv::Point& pt : c) pt += shift;
      Quad q;
      if (!fit_quad(c, grey, p, &q, factor, false)) boxes.push_back(in + shift);
    }
  }
  return boxes;
}

// [SECTION] size_filter

std::optional<Rejection> size_filter(const std::vector<cv::Point>& contour, cv::Size image, const DetectorParams& p,
                                     bool explain, int factor) {
  const double perimeter = contour_length(contour, factor);
  if (perimeter < p.min_perimeter_px)
    return reject(Stage::size_filter, "min_perimeter_px", perimeter, p.min_perimeter_px,
                  explain ? fmt("perimeter %.0f px < min_perimeter_px %.0f px", perimeter, p.min_perimeter_px) : "");
  const double max_px = p.max_perimeter_rate * std::max(image.width, image.height);
  if (perimeter > max_px)
    return reject(Stage::size_filter, "max_perimeter_rate", perimeter, max_px,
                  explain ? fmt("perimeter %.0f px > max_perimeter_rate x frame = %.0f px", perimeter, max_px) : "");
  return std::nullopt;
}

// [SECTION] quad_fit

namespace {

// A side of a quad as the line a x + b y = c, (a, b) unit, fitted through its points by least squares (the line
// through their centroid along the principal axis of their scatter, as cv::fitLine's DIST_L2, without its
// allocations: the refinement fits four lines a pass).
template <class Points>
cv::Vec3d fit_side(const Points& pts) {
  double mx = 0, my = 0;
  for (const auto& q : pts) mx += q.x, my += q.y;
  const double n = double(std::size(pts));
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0, syy = 0;
  for (const auto& q : pts) {
    const double dx = q.x - mx, dy = q.y - my;
    sxx += dx * dx;
    sxy += dx * dy;
    syy += dy * dy;
  }
  const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);   // the direction of largest spread
  const double vx = std::cos(angle), vy = std::sin(angle);
  return cv::Vec3d(-vy, vx, -vy * mx + vx * my);
}

// Corner i where side i-1 meets side i, for the four corners; false when two neighbouring sides are parallel.
bool meet_sides(const std::array<cv::Vec3d, 4>& sides, Quad* corners) {
  for (size_t i = 0; i < 4; ++i) {
    const cv::Vec3d &l1 = sides[(i + 3) % 4], &l2 = sides[i];
    const double det = l1[0] * l2[1] - l1[1] * l2[0];
    if (std::abs(det) < 1e-9) return false;
    (*corners)[i] = cv::Point2f(float((l1[2] * l2[1] - l1[1] * l2[2]) / det),
                                float((l1[0] * l2[2] - l1[2] * l2[0]) / det));
  }
  return true;
}

#if defined(__x86_64__) || defined(__i386__)
// farthest_point's scan four points at a time with AVX2: each point a 64-bit lane (x low, y high), the measure in
// 64-bit integers from pmuldq, and per lane the first largest with its index. Returns how many points it did (a
// multiple of 4) and leaves `best`, `at` as the scan one at a time would.
template <bool Line>
__attribute__((target("avx2"))) int farthest_point_avx2(const cv::Point* c, int n, cv::Point p0, cv::Point dir,
                                                        int64_t* best, int* at) {
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
// AVX-512: sixteen points a step in two vectors of eight, each keeping its lanes' first largest; vpabsq for the
// line's distance.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"   // as grey_row_avx512's
#pragma GCC diagnostic ignored "-Wuninitialized"   // GCC 12's _mm512_reduce_* start from an undefined vector
#endif
template <bool Line>
__attribute__((target("avx512f"))) Farthest farthest_point_avx512(const cv::Point* c, int n, cv::Point p0,
                                                                 cv::Point dir) {
  const __m512i origin = _mm512_set1_epi64(int64_t(uint64_t(uint32_t(p0.y)) << 32 | uint32_t(p0.x)));
  const __m512i ix = _mm512_set1_epi64(dir.x), iy = _mm512_set1_epi64(dir.y);
  __m512i top[2] = {_mm512_set1_epi64(-1), _mm512_set1_epi64(-1)}, where[2] = {top[0], top[0]};
  __m512i index[2] = {_mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7), _mm512_setr_epi64(8, 9, 10, 11, 12, 13, 14, 15)};
  const __m512i sixteen = _mm512_set1_epi64(16);
  for (int k = 0; k < n; k += 16)
    for (int h = 0; h < 2; ++h) {
      // The points left from k + 8h, at most eight: a masked load, so a piece of any length takes this path.
      const int left = std::clamp(n - k - 8 * h, 0, 8);
      const __mmask8 valid = __mmask8((1u << left) - 1);
      const __m512i d = _mm512_sub_epi32(_mm512_maskz_loadu_epi64(valid, c + std::min(k + 8 * h, n)), origin);
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
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif

}  // namespace

Farthest farthest_point(const cv::Point* c, int n, cv::Point p0, cv::Point dir, bool from_line) {
  Farthest f;
  int k = 0;
#if defined(__x86_64__) || defined(__i386__)
  const Simd level = simd();
  if (level >= Simd::avx512)
    return from_line ? farthest_point_avx512<true>(c, n, p0, dir) : farthest_point_avx512<false>(c, n, p0, dir);
  if (level >= Simd::avx2) {
    int64_t best = -1;
    int at = -1;
    k = from_line ? farthest_point_avx2<true>(c, n, p0, dir, &best, &at)
                  : farthest_point_avx2<false>(c, n, p0, dir, &best, &at);
    f = {best, at};
  }
#endif
  for (; k < n; ++k) {
    const int64_t dx = c[k].x - p0.x, dy = c[k].y - p0.y;
    const int64_t m = from_line ? std::abs(dy * dir.x - dx * dir.y) : dx * dx + dy * dy;
    if (m > f.measure) f = {m, k};
  }
  return f;
}

namespace {

// quad_fit's polygon: the Douglas-Peucker approximation of a closed contour within `epsilon` px as cv::approxPolyDP
// makes it, as indices into the contour in contour order. The first split is at an approximately farthest pair
// (from the first point, the farthest point three times over); each piece is split at its point farthest from its
// chord while that is more than epsilon away; at the end a vertex within epsilon / sqrt 2 of the line through its
// neighbours, and between them, is dropped. The vertices start at the first of the farthest pair. It gives up once
// there are more than kMaxVertices (a quad has four):
// a shape of many corners costs only its first splits, and no polygon is written. approxPolyDP was 4.3 us for a
// contour of 254 points on the bench's 640x480 frames, most of quad_fit's time; this is about a third of that.
constexpr int kMaxVertices = 8;
int approx_polygon(const std::vector<cv::Point>& c, double epsilon, std::array<int, kMaxVertices + 1>* out) {
  const int n = int(c.size());
  if (n < 3) return n;
  auto farthest_from = [&](int a) { return farthest_point(c.data(), n, c[size_t(a)], {}, false).at; };
  int a = farthest_from(0);
  a = farthest_from(a);
  const int b = farthest_from(a);
  const double eps2 = epsilon * epsilon;
  {
    const double dx = c[size_t(b)].x - c[size_t(a)].x, dy = c[size_t(b)].y - c[size_t(a)].y;
    if (dx * dx + dy * dy <= eps2) return 1;   // a blob within epsilon of one point
  }
  // Pieces [from, to] along the contour (indices taken modulo n, to > from), split depth first.
  std::array<std::pair<int, int>, 64> stack;
  int top = 0;
  stack[size_t(top++)] = {a, b > a ? b : b + n};
  stack[size_t(top++)] = {b, a > b ? a : a + n};
  std::array<int, kMaxVertices + 1> split{};
  int count = 0;
  split[size_t(count++)] = a;
  split[size_t(count++)] = b;
  while (top > 0) {
    const auto [from, to] = stack[size_t(--top)];
    const cv::Point p0 = c[size_t(from % n)], p1 = c[size_t(to % n)];
    // The farthest point from the chord, as integers (the cross product of whole pixels), in up to two runs of
    // the contour (a piece may wrap past its end).
    const int ix = p1.x - p0.x, iy = p1.y - p0.y;
    int64_t best = -1;
    int at = -1;
    auto scan = [&](int k0, int k1, int shift) {
      if (k1 <= k0) return;
      const Farthest f = farthest_point(c.data() + k0, k1 - k0, p0, {ix, iy}, true);
      if (f.measure > best) best = f.measure, at = k0 + f.at + shift;
    };
    scan(from + 1, std::min(to, n), 0);
    if (to > n) scan(std::max(from + 1, n) - n, to - n, n);
    if (at < 0 || double(best) * double(best) <= eps2 * (double(ix) * ix + double(iy) * iy)) continue;
    if (count == kMaxVertices + 1 || top + 2 > int(stack.size())) return kMaxVertices + 1;
    split[size_t(count++)] = at % n;
    stack[size_t(top++)] = {at, to};
    stack[size_t(top++)] = {from, at};
  }
  std::sort(split.begin(), split.begin() + count);
  // The last pass: drop a vertex nearly on the line through its neighbours and between them.
  int kept = 0;
  std::array<int, kMaxVertices + 1> v{};
  for (int i = 0; i < count; ++i) {
    if (count - (i - kept) <= 2) {   // keep at least three
      v[size_t(kept++)] = split[size_t(i)];
      continue;
    }
    const cv::Point u = kept > 0 ? c[size_t(v[size_t(kept - 1)])] : c[size_t(split[size_t(count - 1)])];
    const cv::Point p = c[size_t(split[size_t(i)])], w = c[size_t(split[size_t((i + 1) % count)])];
    const double dx = w.x - u.x, dy = w.y - u.y;
    const double d = std::abs((p.x - u.x) * dy - (p.y - u.y) * dx);
    const double between = double(p.x - u.x) * (w.x - p.x) + double(p.y - u.y) * (w.y - p.y);
    if (d * d <= 0.5 * eps2 * (dx * dx + dy * dy) && dx != 0 && dy != 0 && between >= 0) continue;
    v[size_t(kept++)] = split[size_t(i)];
  }
  // From the first of the farthest pair (or the vertex after it along the contour, if the last pass dropped it),
  // as approxPolyDP starts.
  int first = 0;
  while (first < kept && v[size_t(first)] < a) ++first;
  for (int i = 0; i < kept; ++i) (*out)[size_t(i)] = v[size_t((first + i) % kept)];
  return kept;
}

// The corners where lines fitted to each side's contour points meet. approxPolyDP's vertices are contour points,
// and a corner that blur or decimation rounded off puts its vertex a pixel or more inside the true corner; the
// sides stay straight. Each side uses the contour between its two vertices, less a fifth at each end (the
// rounding). A side with too few points, or a corner that lands implausibly far from its vertex, keeps the
// vertices as they are. `shift`: what the contour points lack of their block's centre on a decimated search.
Quad corners_from_sides(const std::vector<cv::Point>& contour, const std::array<int, 4>& at, double shift) {
  Quad out;
  std::array<cv::Point, 4> poly;
  for (size_t i = 0; i < 4; ++i) {
    poly[i] = contour[size_t(at[i])];
    out[i] = cv::Point2f(float(poly[i].x + shift), float(poly[i].y + shift));
  }
  const int n = int(contour.size());
  std::array<cv::Vec3d, 4> lines;  // a x + b y = c, (a, b) unit
  std::vector<cv::Point2f> pts;
  for (size_t i = 0; i < 4; ++i) {
    const int from = at[i], len = (at[(i + 1) % 4] - from + n) % n;
    const int trim = len / 5;
    pts.clear();
    for (int k = trim; k <= len - trim; ++k) pts.emplace_back(contour[size_t((from + k) % n)]);
    if (pts.size() < 3) return out;
    lines[i] = fit_side(pts);
  }
  Quad fitted;
  if (!meet_sides(lines, &fitted)) return out;
  for (size_t i = 0; i < 4; ++i) {
    fitted[i] += cv::Point2f(float(shift), float(shift));
    const double side = std::min(cv::norm(poly[i] - poly[(i + 1) % 4]), cv::norm(poly[i] - poly[(i + 3) % 4]));
    if (cv::norm(fitted[i] - out[i]) > 0.25 * side) return out;
  }
  return fitted;
}

}  // namespace

std::optional<Rejection> fit_quad(const std::vector<cv::Point>& contour, cv::Size image, const DetectorParams& p,
                                  Quad* quad, int factor, bool explain) {
  const double perimeter = contour_length(contour, factor);
  const double epsilon = p.polygon_epsilon_rate * perimeter;
  std::array<int, kMaxVertices + 1> at{};
  int vertices = approx_polygon(contour, epsilon, &at);
  auto polygon = [&](const std::array<int, kMaxVertices + 1>& idx) {
    return std::vector<cv::Point>{contour[size_t(idx[0])], contour[size_t(idx[1])], contour[size_t(idx[2])],
                                  contour[size_t(idx[3])]};
  };
  if (vertices > 4 && contour.size() < 100) {
    // A small contour (under 100 steps) is jagged by whole pixels of the search image, and a corner rounded by blur
    // or decimation can take two vertices. One more try at twice the tolerance, kept only when the polygon still
    // covers the region (a blob is no quad).
    std::array<int, kMaxVertices + 1> coarse{};
    if (approx_polygon(contour, 2 * epsilon, &coarse) == 4 &&
        cv::contourArea(polygon(coarse)) >= 0.85 * cv::contourArea(contour)) {
      at = coarse;
      vertices = 4;
    }
  }
  if (vertices != 4) {
    std::string why;
    if (explain)
      why = vertices > kMaxVertices ? fmt("polygon has more than %.0f corners, not 4 (polygon_epsilon_rate %g)",
                                          kMaxVertices, p.polygon_epsilon_rate)
                                    : fmt("polygon has %.0f corners, not 4 (polygon_epsilon_rate %g)",
                                          double(vertices), p.polygon_epsilon_rate);
    return reject(Stage::quad_fit, "polygon_epsilon_rate", double(vertices), 4, std::move(why));
  }
  const std::vector<cv::Point> poly = polygon(at);
  if (!cv::isContourConvex(poly)) return reject(Stage::quad_fit, "", 0, 0, "quad is not convex");
  double min_side = 1e18;
  for (int i = 0; i < 4; ++i) {
    const cv::Point d = poly[size_t(i)] - poly[size_t((i + 1) % 4)];
    min_side = std::min(min_side, std::sqrt(double(d.dot(d))));
  }
  const double min_allowed = p.min_side_rate * perimeter;
  if (min_side < min_allowed)
    return reject(Stage::quad_fit, "min_side_rate", min_side, min_allowed,
                  explain ? fmt("shortest side %.1f px < min_side_rate x perimeter = %.1f px", min_side, min_allowed)
                          : "");
  int edge = 1 << 30;
  for (const auto& pt : poly)
    edge = std::min({edge, pt.x, pt.y, image.width - 1 - pt.x, image.height - 1 - pt.y});
  if (edge < p.min_border_distance_px)
    return reject(Stage::quad_fit, "min_border_distance_px", edge, p.min_border_distance_px,
                  explain ? fmt("corner %.0f px from the image edge < min_border_distance_px %.0f px", edge,
                                p.min_border_distance_px)
                          : "");
  Quad q = corners_from_sides(contour, {at[0], at[1], at[2], at[3]}, (factor - 1) / 2.0 - (factor - 1) / 2);
  // Clockwise on screen (y down): the cross product of the first two edges is positive.
  const cv::Point2f a = q[1] - q[0], b = q[2] - q[0];
  if (double(a.x) * b.y - double(a.y) * b.x < 0) std::swap(q[1], q[3]);
  *quad = q;
  return std::nullopt;
}

// [SECTION] nested_filter

std::vector<int> nested_filter(const std::vector<Quad>& quads, const DetectorParams& p,
                               const std::vector<int>* factors) {
  // Thick borders give two contours for one marker (outer and inner edge of the thresholded line); keep the
  // outer one. Two quads are the same when, for some cyclic pairing of corners, their mean corner distance is
  // below min_marker_distance_rate times the smaller perimeter.
  const size_t n = quads.size();
  std::vector<double> perim(n);
  std::vector<cv::Rect> box(n);
  for (size_t i = 0; i < n; ++i) {
    perim[i] = quad_perimeter(quads[i]);
    box[i] = cv::boundingRect(std::vector<cv::Point2f>(quads[i].begin(), quads[i].end()));
  }
  std::vector<int> replaced_by(n, -1);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      if ((box[i] & box[j]).area() <= 0) continue;
      const double limit = p.min_marker_distance_rate * std::min(perim[i], perim[j]);
      double best = 1e18;
      for (int shift = 0; shift < 4; ++shift) {
        double d = 0;
        for (int k = 0; k < 4; ++k) d += cv::norm(quads[i][size_t(k)] - quads[j][size_t((k + shift) % 4)]);
        best = std::min(best, d / 4);
      }
      if (best >= limit) continue;
      size_t inner = perim[i] < perim[j] ? i : j, outer = inner == i ? j : i;
      if (factors && (*factors)[inner] < (*factors)[outer])
        std::swap(inner, outer);   // the finer one stays
      if (replaced_by[inner] < 0) replaced_by[inner] = static_cast<int>(outer);
    }
  return replaced_by;
}

// [SECTION] perspective_removal

namespace {

// Bilinear interpolation at (x, y), pixel centres at integers, clamped to the image.
double sample_bilinear(const cv::Mat& grey, double x, double y) {
  x = std::clamp(x, 0.0, double(grey.cols - 1));
  y = std::clamp(y, 0.0, double(grey.rows - 1));
  const int x0 = std::min(int(x), grey.cols - 2 < 0 ? 0 : grey.cols - 2);
  const int y0 = std::min(int(y), grey.rows - 2 < 0 ? 0 : grey.rows - 2);
  const int x1 = std::min(x0 + 1, grey.cols - 1), y1 = std::min(y0 + 1, grey.rows - 1);
  const double fx = x - x0, fy = y - y0;
  const uint8_t* r0 = grey.ptr<uint8_t>(y0);
  const uint8_t* r1 = grey.ptr<uint8_t>(y1);
  const double top = r0[x0] + fx * (r0[x1] - r0[x0]);
  const double bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
  return top + fy * (bottom - top);
}

// Bilinear interpolation inside the image at (x, y) given in 1/256 pixel (both >= 0, and x / 256 + 1, y / 256 + 1
// inside): integer weights, no conversion to floating point per pixel. The value times 65536.
inline int bilinear_q8(const uchar* data, size_t stride, int x, int y) {
  const int fx = x & 255, fy = y & 255;
  const uchar* r0 = data + size_t(y >> 8) * stride + (x >> 8);
  const uchar* r1 = r0 + stride;
  const int top = r0[0] * (256 - fx) + r0[1] * fx, bottom = r1[0] * (256 - fx) + r1[1] * fx;
  return top * (256 - fy) + bottom * fy;
}

#if defined(__x86_64__) || defined(__i386__)
// bilinear_q8 at eight points (qx, qy in 1/256 pixel) with AVX2: each point's two pixel pairs gathered as dwords
// (so a point must lie 3 pixels inside its row's end), each pair weighed by pmaddwd, the rows blended as
// top * 256 + (bottom - top) * fy: the same integers as bilinear_q8.
__attribute__((target("avx2"))) inline __m256i bilinear_q8_avx2(const uchar* data, size_t stride, __m256i qx,
                                                                __m256i qy) {
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

// sample_line's samples 8 at a time along a line (x, y, dx, dy in 1/65536 pixel, as int32) with AVX2. Returns how
// many it did (a multiple of 8).
__attribute__((target("avx2"))) int sample_line_avx2(const uchar* data, size_t stride, int x, int y, int dx, int dy,
                                                     int n, int* out) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  __m256i vx = _mm256_add_epi32(_mm256_set1_epi32(x), _mm256_mullo_epi32(lane, _mm256_set1_epi32(dx)));
  __m256i vy = _mm256_add_epi32(_mm256_set1_epi32(y), _mm256_mullo_epi32(lane, _mm256_set1_epi32(dy)));
  const __m256i step_x = _mm256_set1_epi32(8 * dx), step_y = _mm256_set1_epi32(8 * dy);
  int j = 0;
  for (; j + 8 <= n; j += 8) {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + j),
                        bilinear_q8_avx2(data, stride, _mm256_srai_epi32(vx, 8), _mm256_srai_epi32(vy, 8)));
    vx = _mm256_add_epi32(vx, step_x);
    vy = _mm256_add_epi32(vy, step_y);
  }
  return j;
}
#endif

}  // namespace

// profile.size() samples from `from` in steps of `step`, bilinear, as grey levels times 65536 (integers: the
// refinement's sums over a profile stay exact and cheap). Where the whole line lies inside the image (the usual case)
// the samples step along it in 1/256 pixel with bilinear_q8 (one refinement pass over a 60 px quad: 19 us with
// floats, 13 then), eight at a time with AVX2 (corner_refinement at 640x480 0.062 -> 0.051 ms, the same integers);
// otherwise through sample_bilinear's clamping.
void sample_line(const cv::Mat& grey, cv::Point2d from, cv::Point2d step, std::span<int> profile) {
  const int n = int(profile.size());
  const cv::Point2d to = from + step * double(n - 1);
  const double xmax = grey.cols - 1.001, ymax = grey.rows - 1.001;
  if (std::min(from.x, to.x) < 0 || std::min(from.y, to.y) < 0 || std::max(from.x, to.x) > xmax ||
      std::max(from.y, to.y) > ymax) {
    for (int j = 0; j < n; ++j)
      profile[size_t(j)] = int(std::lround(65536 * sample_bilinear(grey, from.x + j * step.x, from.y + j * step.y)));
    return;
  }
  const uchar* data = grey.data;
  const size_t stride = grey.step;
  // 16 fractional bits while stepping, so that the steps add up no error to speak of over a profile. Rounded as
  // std::llround, halves away from zero, inline (llround is a library call, four a profile): truncated, then a step
  // away from zero when what was cut is a half or more (exact below 2^52; the line is inside the image here).
  auto round = [](double v) {
    int64_t t = int64_t(v);
    const double cut = v - double(t);
    t += (cut >= 0.5) - (cut <= -0.5);
    return t;
  };
  int64_t x = round(from.x * 65536), y = round(from.y * 65536);
  const int64_t dx = round(step.x * 65536), dy = round(step.y * 65536);
  int j = 0;
#if defined(__x86_64__) || defined(__i386__)
  // 8 at a time where the line stays 3 pixels inside the row's end (the gathers read 4 bytes) and its positions in
  // 1/65536 pixel and the pixels' offsets fit 32 bits.
  const bool avx2 = simd() >= Simd::avx2;
  if (avx2 && std::max(from.x, to.x) < grey.cols - 4 && grey.cols < 16384 && grey.rows < 16384 &&
      double(grey.step) * grey.rows < 2e9)
    j = sample_line_avx2(data, stride, int(x), int(y), int(dx), int(dy), n, profile.data());
  x += dx * j;
  y += dy * j;
#endif
  for (; j < n; ++j, x += dx, y += dy)
    profile[size_t(j)] = bilinear_q8(data, stride, int(x >> 8), int(y >> 8));
}



namespace {

// The homography taking the square [0, side]^2 to the quad, corner k of the square ((0,0), (side,0), (side,side),
// (0,side)) to quad[k]: Heckbert's closed form for the unit square, scaled. The same matrix as
// cv::getPerspectiveTransform up to rounding, without its linear solve and allocations (two per candidate).
cv::Matx33d square_to_quad(const Quad& q, double side) {
  const double x0 = q[0].x, y0 = q[0].y, x1 = q[1].x, y1 = q[1].y, x2 = q[2].x, y2 = q[2].y, x3 = q[3].x,
               y3 = q[3].y;
  const double sx = x0 - x1 + x2 - x3, sy = y0 - y1 + y2 - y3;
  double g = 0, h = 0;
  if (sx != 0 || sy != 0) {
    const double dx1 = x1 - x2, dx2 = x3 - x2, dy1 = y1 - y2, dy2 = y3 - y2;
    const double den = dx1 * dy2 - dx2 * dy1;
    if (den != 0) {
      g = (sx * dy2 - dx2 * sy) / den;
      h = (dx1 * sy - sx * dy1) / den;
    }
  }
  const double a = x1 - x0 + g * x1, b = x3 - x0 + h * x3, d = y1 - y0 + g * y1, e = y3 - y0 + h * y3;
  return cv::Matx33d(a / side, b / side, x0, d / side, e / side, y0, g / side, h / side, 1);
}

}  // namespace

#if defined(__x86_64__) || defined(__i386__)
namespace {
// One row of remove_perspective, eight pixels a step with AVX2: the homography in the same double operations in the
// same order (four at a time; no fused multiply-add: this target has none), truncated to 1/256 pixel, and
// bilinear_q8_avx2, rounded as the scalar loop rounds. A group with a sample outside the image, or within 3 pixels
// of its last column (the gathers read 4 bytes), is left to the scalar loop: done[g] says whether group g (pixels
// 8g..8g+7) was done here.
__attribute__((target("avx2"))) void warp_row_avx2(const cv::Matx33d& H, double y, int side, const uchar* data,
                                                   size_t stride, double xlimit, double ymax, uint8_t* row,
                                                   uint8_t* done) {
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
    const __m256i value = bilinear_q8_avx2(data, stride, _mm256_set_m128i(qx[1], qx[0]), _mm256_set_m128i(qy[1], qy[0]));
    const __m256i level = _mm256_shuffle_epi8(_mm256_srli_epi32(_mm256_add_epi32(value, round), 16), bytes);
    const int lo = _mm256_cvtsi256_si32(level), hi = _mm256_extract_epi32(level, 4);
    std::memcpy(row + u, &lo, 4);
    std::memcpy(row + u + 4, &hi, 4);
  }
}
}  // namespace
#endif

cv::Mat remove_perspective(const cv::Mat& grey, const Quad& quad, int cells, const DetectorParams& p) {
  const int side = cells * p.warp_cell_px;
  const cv::Matx33d H = square_to_quad(quad, side);
  cv::Mat warp(side, side, CV_8UC1);
  // A sample inside the image (nearly all) is interpolated by bilinear_q8 (a 28 px warp: 7.1 us with
  // sample_bilinear's clamped doubles, 4.5 now); one outside it, or of a quad refinement bent out of shape, is
  // clamped as before.
  const double xmax = grey.cols - 1.001, ymax = grey.rows - 1.001;
  const uchar* data = grey.data;
  const size_t stride = grey.step;
#if defined(__x86_64__) || defined(__i386__)
  // Eight samples at a time with AVX2, the same doubles and integers (the stage at 640x480 0.035 -> 0.014 ms).
  const bool avx2 = simd() >= Simd::avx2;
  const bool vector = avx2 && grey.cols < 16384 && grey.rows < 16384 && double(grey.step) * grey.rows < 2e9;
  thread_local std::vector<uint8_t> done;
  done.assign(size_t(side / 8), 0);
#endif
  for (int v = 0; v < side; ++v) {
    uint8_t* row = warp.ptr<uint8_t>(v);
    const double y = v + 0.5;
#if defined(__x86_64__) || defined(__i386__)
    if (vector) warp_row_avx2(H, y, side, data, stride, grey.cols - 4.0, ymax, row, done.data());
#endif
    for (int u = 0; u < side; ++u) {
#if defined(__x86_64__) || defined(__i386__)
      if (vector && u / 8 < int(done.size()) && done[size_t(u / 8)]) {
        u += 7;
        continue;
      }
#endif
      const double x = u + 0.5;
      const double inv_w = 1.0 / (H(2, 0) * x + H(2, 1) * y + H(2, 2));
      const double px = (H(0, 0) * x + H(0, 1) * y + H(0, 2)) * inv_w;
      const double py = (H(1, 0) * x + H(1, 1) * y + H(1, 2)) * inv_w;
      if (!(px >= 0 && py >= 0 && px < xmax && py < ymax)) {   // also false for NaN
        row[u] = static_cast<uint8_t>(sample_bilinear(grey, px, py) + 0.5);
        continue;
      }
      row[u] = static_cast<uint8_t>((bilinear_q8(data, stride, int(px * 256), int(py * 256)) + 32768) >> 16);
    }
  }
  return warp;
}

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
  auto at = [&](double u, double v, double* value) {
    const cv::Vec3d px = H * cv::Vec3d(u, v, 1);
    const double x = px[0] / px[2], y = px[1] / px[2];
    if (!(x >= 0 && y >= 0 && x <= grey.cols - 1 && y <= grey.rows - 1)) return false;
    *value = sample_bilinear(grey, x, y);
    return true;
  };
  QuietZone worst;
  for (int side = 0; side < 4; ++side) {
    int dark = 0, seen = 0;
    for (int k = 0; k < cells; ++k) {
      const double t = k + 0.5;
      // (u, v) at depth d outside the side (negative: inside); side k runs from corner k to corner k + 1.
      auto cell = [&](double d, double* value) {
        switch (side) {
          case 0: return at(t, -d, value);
          case 1: return at(cells + d, t, value);
          case 2: return at(cells - t, cells + d, value);
          default: return at(-d, cells - t, value);
        }
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

// [SECTION] otsu

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

// [SECTION] bit_grid

cv::Mat sample_bits(const cv::Mat& warp, int cells, int threshold, const DetectorParams& p) {
  const int cp = p.warp_cell_px;
  const int margin = std::min(static_cast<int>(p.warp_margin_rate * cp + 0.5), (cp - 1) / 2);
  cv::Mat bits(cells, cells, CV_8UC1);
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) {
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

// [SECTION] border_check

int border_errors(const cv::Mat& bits) {
  int errors = 0;
  const int n = bits.rows;
  for (int i = 0; i < n; ++i) {
    errors += bits.at<uint8_t>(0, i) + bits.at<uint8_t>(n - 1, i);
    if (i > 0 && i < n - 1) errors += bits.at<uint8_t>(i, 0) + bits.at<uint8_t>(i, n - 1);
  }
  return errors;
}

// [SECTION] identification

uint64_t inner_code(const cv::Mat& bits) {
  return Dictionary::pack(bits(cv::Rect(1, 1, bits.cols - 2, bits.rows - 2)).clone());
}

int correction_budget(const Dictionary& dict, const DetectorParams& p) {
  return static_cast<int>(dict.max_correction_bits() * p.error_correction_rate);
}

// [SECTION] corner_refinement


namespace {

// corner_refinement's profiles, kProfilesAtOnce at a time: each one's spread (its highest sample but the last less
// its lowest), and the sums for the centroid of its rising steps above a fifth of the highest step. Each profile's
// sums are added in the same order as alone (the same bits; no multiply-add is fused), but its chain of dependent
// additions runs beside the others' instead of after them, and a step at or below the floor adds +0 (wsum starts at
// +0), which leaves the sums as they were, with no branch: one profile at a time, with a branch that mispredicted
// on every other step, this was half the stage.
constexpr int kProfilesAtOnce = 8;
// Profile q is samples [first[q], first[q] + samples) of `profiles`.
void profile_edges_plain(const int* profiles, const int* first, int samples, int* spread, double* wsum,
                         double* jsum) {
  for (int q = 0; q < kProfilesAtOnce; ++q) {
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
#if defined(__x86_64__) || defined(__i386__)
// The eight profiles in the lanes of AVX2 vectors, sample j of each gathered at once; as the plain loop lane by lane
// (AVX2 without FMA: w * j is rounded before it is added, as there).
__attribute__((target("avx2"))) void profile_edges_avx2(const int* profiles, const int* first, int samples,
                                                        int* spread, double* wsum, double* jsum) {
  static_assert(kProfilesAtOnce == 8);
  const __m256i at = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(first));
  thread_local std::vector<int> steps;   // next - now for each j, eight at a time, kept for the second pass
  if (steps.size() < 8 * size_t(samples)) steps.resize(8 * size_t(samples));
  __m256i now = _mm256_i32gather_epi32(profiles, at, 4), peak = _mm256_setzero_si256(), lo = now, hi = now;
  for (int j = 0; j + 1 < samples; ++j) {
    const __m256i next = _mm256_i32gather_epi32(profiles + j + 1, at, 4);
    const __m256i step = _mm256_sub_epi32(next, now);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(steps.data() + 8 * j), step);
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
    const __m256i step = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(steps.data() + 8 * j));
    const __m256d w0 = _mm256_max_pd(_mm256_sub_pd(_mm256_cvtepi32_pd(_mm256_castsi256_si128(step)), floor0), zero);
    const __m256d w1 = _mm256_max_pd(_mm256_sub_pd(_mm256_cvtepi32_pd(_mm256_extracti128_si256(step, 1)), floor1), zero);
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
#endif
void profile_edges(const int* profiles, const int* first, int samples, int* spread, double* wsum, double* jsum) {
#if defined(__x86_64__) || defined(__i386__)
  if (simd() >= Simd::avx2) return profile_edges_avx2(profiles, first, samples, spread, wsum, jsum);
#endif
  profile_edges_plain(profiles, first, samples, spread, wsum, jsum);
}

// One pass of refine_corners; false when an edge could not be trusted (the corners are then left as they were).
bool refine_corners_once(const cv::Mat& grey, Quad& corners, int cells, const DetectorParams& p, double slack) {
  // Each side of the marker is the edge between its black border (inside) and the white quiet zone (outside).
  // Along the side, profiles across the edge locate it to a fraction of a pixel (the centroid of the rising
  // gradient, which sits on the edge for any symmetric blur); a line is fitted through those points and the
  // corners are where neighbouring lines meet. A corner that would move more than half a cell keeps its place.
  // Only the gradient above a fifth of the profile's peak counts: below it is mostly noise, spread evenly over
  // the profile, and it pulled the centroid towards the profile's middle (the corners' mean error on the bench
  // set fell from 0.117 to 0.067 px with that and a profile every 2 px instead of every 3).
  double min_side = 1e18;
  for (int i = 0; i < 4; ++i)
    min_side = std::min(min_side, double(cv::norm(corners[size_t(i)] - corners[size_t((i + 1) % 4)])));
  const double cell = min_side / cells;
  const double reach = std::max(std::clamp(0.6 * cell, 2.5, double(p.subpix_window_px) + 1.0), slack);
  const double step = 0.5;
  const int samples = static_cast<int>(std::lround(2 * reach / step)) + 1;
  const cv::Point2f centre = quad_centre(corners);

  std::array<cv::Vec3d, 4> lines;  // a x + b y = c, (a, b) unit
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d a = corners[size_t(i)], b = corners[size_t((i + 1) % 4)];
    const cv::Point2d dir = (b - a) / cv::norm(b - a);
    cv::Point2d normal(dir.y, -dir.x);
    if (normal.dot(cv::Point2d(centre) - a) > 0) normal = -normal;  // outward
    const int count = std::clamp(static_cast<int>(cv::norm(b - a) / 2), 8, 32);
    // Kept from side to side and quad to quad (per thread): no allocation a side.
    thread_local std::vector<cv::Point2d> pts, bases;
    thread_local std::vector<int> profiles;   // count profiles of `samples` grey levels times 65536
    pts.clear();
    bases.resize(size_t(count));
    profiles.resize(size_t(count) * size_t(samples));
    for (int k = 0; k < count; ++k) {
      const double t = 0.12 + 0.76 * (k + 0.5) / count;  // away from the corners
      bases[size_t(k)] = a + (b - a) * t;
      sample_line(grey, bases[size_t(k)] - normal * reach, normal * step,
                  std::span<int>(profiles.data() + size_t(k) * size_t(samples), size_t(samples)));
    }
    // Each profile's edge, kProfilesAtOnce at a time (profile_edges).
    for (int k0 = 0; k0 < count; k0 += kProfilesAtOnce) {
      int first[kProfilesAtOnce];   // past the last profile: the last again, computed and dropped
      for (int q = 0; q < kProfilesAtOnce; ++q) first[q] = std::min(k0 + q, count - 1) * samples;
      int spread[kProfilesAtOnce];
      double wsum[kProfilesAtOnce], jsum[kProfilesAtOnce];
      profile_edges(profiles.data(), first, samples, spread, wsum, jsum);
      for (int q = 0; q < kProfilesAtOnce && k0 + q < count; ++q) {
        if (spread[q] < 10 * 65536) continue;  // no edge here (occluded, glare)
        if (wsum[q] <= 0) continue;
        pts.push_back(bases[size_t(k0 + q)] + normal * (-reach + (jsum[q] / wsum[q] + 0.5) * step));
      }
    }
    if (pts.size() < 3) return false;  // not enough edge to trust: keep the corners as they are
    lines[size_t(i)] = fit_side(pts);
  }
  Quad refined;
  if (!meet_sides(lines, &refined)) return false;
  for (size_t i = 0; i < 4; ++i)
    if (cv::norm(refined[i] - corners[i]) > std::max({cell, 2.0, slack})) return false;
  corners = refined;
  return true;
}

}  // namespace

void refine_corners(const cv::Mat& grey, Quad& corners, int cells, const DetectorParams& p, int factor) {
  if (p.corner_refinement == 0) return;
  // Each pass profiles across the sides found by the last one, so the profiles end up square to the true edges;
  // it stops when no corner moves more than subpix_epsilon_px (usually after two or three passes). A quad found on
  // the decimated image starts up to about `factor` pixels off: the first pass reaches that far, and one more
  // pass follows with the usual reach.
  // When that first reach is longer than the usual one (0.6 of a cell: a small marker), its profiles can take in
  // an inner cell's edge, and it takes two more passes to settle (tiny markers on the hard set: 0.2-0.6 px off
  // after one, 0.05-0.3 after two); a large marker's noisy edges only wander with more.
  double min_side = 1e18;
  for (size_t i = 0; i < 4; ++i) min_side = std::min(min_side, double(cv::norm(corners[i] - corners[(i + 1) % 4])));
  const double slack = factor > 1 ? factor + 1.5 : 0;
  const bool far = slack > std::clamp(0.6 * min_side / cells, 2.5, double(p.subpix_window_px) + 1.0);
  const int passes = p.subpix_max_iterations + (factor > 1 ? 1 : 0) + (far ? 1 : 0);
  for (int it = 0; it < passes; ++it) {
    const Quad before = corners;
    if (!refine_corners_once(grey, corners, cells, p, it == 0 ? slack : 0)) return;
    double moved = 0;
    for (size_t k = 0; k < 4; ++k) moved = std::max(moved, double(cv::norm(corners[k] - before[k])));
    if (moved < p.subpix_epsilon_px) return;
  }
}

}  // namespace arwb::stages
