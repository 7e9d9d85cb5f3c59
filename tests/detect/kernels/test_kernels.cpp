// The kernel tables: each level's table is its own, and every entry gives the plain table's bits on random rows of
// every length around the vector widths.
#include "detect/kernels/kernels.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

using namespace arwb;
using kernels::Kernels;

namespace {

std::vector<uint8_t> random_bytes(std::mt19937& rng, size_t n, int zero_share = 0) {
  std::uniform_int_distribution<int> byte(0, 255), pct(0, 99);
  std::vector<uint8_t> v(n);
  for (auto& b : v) b = pct(rng) < zero_share ? 0 : uint8_t(byte(rng));
  return v;
}

// Runs `check(k, plain)` for every level's table the processor can run.
template <class Check>
void at_every_level(Check check) {
  const Kernels& plain = kernels::plain_kernels();
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    check(kernels::kernels(), plain);
  }
}

}  // namespace

TEST(Kernels, EachLevelHasItsOwnTable) {
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    EXPECT_EQ(kernels::kernels().level, level) << simd_name(level);
  }
  EXPECT_EQ(kernels::plain_kernels().level, Simd::none);
}

TEST(Kernels, RowKernelsGiveThePlainBitsForEveryLength) {
  std::mt19937 rng(7);
  at_every_level([&](const Kernels& k, const Kernels& plain) {
    for (int n = 0; n <= 200; ++n) {
      const auto bgr = random_bytes(rng, 3 * size_t(n) + 64), a = random_bytes(rng, 2 * size_t(n) + 64),
                 b = random_bytes(rng, 2 * size_t(n) + 64);
      std::vector<uint8_t> got(size_t(n) + 64, 1), want(size_t(n) + 64, 1);
      k.grey_row(bgr.data(), got.data(), n);
      plain.grey_row(bgr.data(), want.data(), n);
      ASSERT_EQ(got, want) << "grey_row, n " << n;
      const auto px = random_bytes(rng, 4 * size_t(n) + 64);
      for (const bool rgba : {false, true}) {
        k.grey_row4(px.data(), got.data(), n, rgba);
        plain.grey_row4(px.data(), want.data(), n, rgba);
        ASSERT_EQ(got, want) << "grey_row4, n " << n << (rgba ? ", RGBA" : ", BGRA");
      }
      k.halve_rows(a.data(), b.data(), got.data(), n);
      plain.halve_rows(a.data(), b.data(), want.data(), n);
      ASSERT_EQ(got, want) << "halve_rows, n " << n;
      // threshold_row reads v[-1] and v[n]: one row of blended means with a mean beside each end.
      std::vector<uint16_t> v(size_t(n) + 2), w(size_t(n) + 2);
      k.blend_row(a.data(), b.data(), v.data() + 1, n);
      plain.blend_row(a.data(), b.data(), w.data() + 1, n);
      ASSERT_EQ(v, w) << "blend_row, n " << n;
      v[0] = v[1];
      v[size_t(n) + 1] = n > 0 ? v[size_t(n)] : 0;
      for (int offset : {0, 7, 40}) {
        std::vector<uint8_t> got_bits(2 * size_t(n) + 8, 1), want_bits(2 * size_t(n) + 8, 1);
        k.threshold_row(v.data() + 1, n, a.data(), got_bits.data(), offset);
        plain.threshold_row(v.data() + 1, n, a.data(), want_bits.data(), offset);
        ASSERT_EQ(got_bits, want_bits) << "threshold_row, n " << n << ", offset " << offset;
      }
    }
  });
}

TEST(Kernels, ContourKernelsGiveThePlainBitsForEveryLength) {
  std::mt19937 rng(11);
  at_every_level([&](const Kernels& k, const Kernels& plain) {
    for (int w = 1; w <= 300; w += (w < 140 ? 1 : 7)) {
      const int words = (w + 63) / 64;
      const auto row = random_bytes(rng, size_t(w) + 64, 60);
      for (bool light : {false, true}) {
        std::vector<uint64_t> got(size_t(words) + 1, 0), want(size_t(words) + 1, 0);
        k.row_masks(row.data(), w, words, got.data(), light);
        plain.row_masks(row.data(), w, words, want.data(), light);
        ASSERT_EQ(got, want) << "row_masks, w " << w << ", light " << light;
        // The row's edges, and the pixels where its runs begin and end (room for 16 more).
        std::vector<uint64_t> got_edges(size_t(words) + 1), want_edges(size_t(words) + 1);
        std::vector<int> got_before(size_t(words) + 1), want_before(size_t(words) + 1);
        const int n = k.find_edges(got.data(), words, {got_edges.data(), got_before.data()});
        ASSERT_EQ(n, plain.find_edges(want.data(), words, {want_edges.data(), want_before.data()}));
        ASSERT_EQ(got_edges, want_edges);
        ASSERT_EQ(got_before, want_before);
        std::vector<int> got_at(size_t(n) + 16), want_at(size_t(n) + 16);
        ASSERT_EQ(k.row_edges(got_edges.data(), words + 1, got_at.data()), n);
        ASSERT_EQ(plain.row_edges(want_edges.data(), words + 1, want_at.data()), n);
        got_at.resize(size_t(n));
        want_at.resize(size_t(n));
        ASSERT_EQ(got_at, want_at) << "row_edges, w " << w;
      }
    }
  });
}

TEST(Kernels, FarthestPointAndNearestCodeGiveThePlainAnswers) {
  std::mt19937 rng(13);
  std::uniform_int_distribution<int> coord(-2000, 2000);
  at_every_level([&](const Kernels& k, const Kernels& plain) {
    for (int n = 0; n <= 70; ++n) {
      std::vector<kernels::Point> c(static_cast<size_t>(n));
      for (auto& p : c) p = {coord(rng) / 40, coord(rng) / 40};   // few distinct values: ties are common
      const kernels::Point p0{coord(rng), coord(rng)}, dir{coord(rng), coord(rng)};
      // And with one point far out (beyond 32-bit measures: SIMD128's kernel must leave those to 64 bits).
      std::vector<kernels::Point> far = c;
      if (n > 0) far[size_t(n) / 2] = {coord(rng) * 40, coord(rng) * 40};
      for (bool line : {false, true})
        for (const auto* points : {&c, &far}) {
          const kernels::Farthest got = k.farthest_point(points->data(), n, p0, dir, line);
          const kernels::Farthest want = plain.farthest_point(points->data(), n, p0, dir, line);
          ASSERT_EQ(got.measure, want.measure) << "n " << n;
          ASSERT_EQ(got.at, want.at) << "n " << n;
        }
    }
    std::uniform_int_distribution<uint64_t> bits(0, (uint64_t(1) << 36) - 1);
    for (int ids : {0, 1, 2, 3, 50, 587}) {
      std::vector<uint64_t> codes(4 * size_t(ids));
      for (auto& c : codes) c = bits(rng);
      for (int q = 0; q < 40; ++q) {
        // Half the questions are a code of the list, a bit or two off: exact matches and near ties.
        uint64_t code = bits(rng);
        if (ids > 0 && q % 2) code = codes[size_t(q) % codes.size()] ^ (q % 4 == 1 ? 0 : uint64_t(1) << (q % 36));
        const kernels::CodeMatch got = k.nearest_code(codes.data(), ids, code);
        const kernels::CodeMatch want = plain.nearest_code(codes.data(), ids, code);
        ASSERT_EQ(got.id, want.id);
        ASSERT_EQ(got.rotation, want.rotation);
        ASSERT_EQ(got.hamming, want.hamming);
        kernels::CodeMatch got4[4], want4[4];
        k.nearest_per_rotation(codes.data(), ids, code, got4);
        plain.nearest_per_rotation(codes.data(), ids, code, want4);
        for (int r = 0; r < 4; ++r) ASSERT_EQ(got4[r].id * 100 + got4[r].hamming, want4[r].id * 100 + want4[r].hamming);
      }
    }
  });
}

TEST(Kernels, SmallRegionPassesGiveThePlainBits) {
  std::mt19937 rng(17);
  at_every_level([&](const Kernels& k, const Kernels& plain) {
    for (const int w : {1, 63, 64, 65, 130, 200, 333}) {
      for (const int density : {3, 12, 40}) {   // percent of pixels on: specks, small regions, big ones
        const int words = (w + 63) / 64, h = 37;
        kernels::BitRows shape{nullptr, words, h};
        std::vector<uint64_t> mine(shape.size()), theirs(shape.size()), scratch(3 * shape.size());
        kernels::BitRows a{mine.data(), words, h}, b{theirs.data(), words, h};
        a.clear_padding();
        std::uniform_int_distribution<int> pct(0, 99);
        for (int y = 0; y < h; ++y)
          for (int c = 0; c < words; ++c) {
            uint64_t word = 0;
            for (int x = 64 * c; x < std::min(w, 64 * c + 64); ++x) word |= uint64_t(pct(rng) < density) << (x % 64);
            a.row(y)[c] = word;
          }
        for (int y = 0; y < h; ++y) a.row(y)[-1] = a.row(y)[words] = 0;
        theirs = mine;
        ASSERT_EQ(k.drop_specks(a, scratch.data(), true), plain.drop_specks(b, scratch.data(), true)) << w;
        ASSERT_EQ(mine, theirs) << "drop_specks, w " << w << ", density " << density;
        for (const int window : {3, 5}) {
          const bool count = window == 3;
          ASSERT_EQ(k.drop_small_regions(a, window, count, scratch.data()),
                    plain.drop_small_regions(b, window, count, scratch.data()));
          ASSERT_EQ(mine, theirs) << "drop_small_regions " << window << ", w " << w << ", density " << density;
        }
      }
    }
  });
}

// box_mean, at each level that has it, is the k x k mean with the border replicated, rounded to the nearest.
TEST(Kernels, BoxMeanIsTheRoundedMeanOfItsWindow) {
  std::mt19937 rng(19);
  int checked = 0;
  at_every_level([&](const Kernels& k, const Kernels&) {
    for (const int w : {16, 17, 40, 101}) {
      const int h = 23;
      const auto src = random_bytes(rng, size_t(w) * size_t(h));
      for (int window = 5; window <= 15; window += 2) {
        std::vector<uint16_t> scratch(kernels::box_mean_scratch(w, window));
        std::vector<uint8_t> got(size_t(w) * size_t(h));
        if (!k.box_mean(src.data(), size_t(w), w, h, window, got.data(), size_t(w), scratch.data())) continue;
        ++checked;
        const int r = window / 2, area = window * window;
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x) {
            int sum = 0;
            for (int dy = -r; dy <= r; ++dy)
              for (int dx = -r; dx <= r; ++dx)
                sum += src[size_t(std::clamp(y + dy, 0, h - 1)) * size_t(w) + size_t(std::clamp(x + dx, 0, w - 1))];
            ASSERT_EQ(int(got[size_t(y) * size_t(w) + size_t(x)]), (sum + area / 2) / area)
                << "w " << w << ", k " << window << " at " << x << "," << y;
          }
      }
    }
  });
  // The plain level has no box mean (the stage calls cv::boxFilter); a vector level has one.
  if (simd_levels_here().size() > 1) {
    EXPECT_GT(checked, 0);
  }
}
