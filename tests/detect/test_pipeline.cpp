// Each stage on small crafted images, and the parameter table.
#include "detect/detector.hpp"
#include "detect/params.hpp"
#include "detect/pipeline.hpp"
#include "detect/simd.hpp"
#include "synth/synth.hpp"
#include "support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <bit>
#include <cmath>

using namespace arwb;

namespace {
// A white canvas with one marker drawn axis-aligned, its outer corners at (x0,y0)..(x0+side,y0+side).
cv::Mat canvas_with_marker(const Dictionary& d, int id, float x0, float y0, float side, cv::Size size = {200, 200}) {
  cv::Mat img(size, CV_8UC1, cv::Scalar(255));
  draw_marker(img, d, id, Quad{cv::Point2f(x0, y0), {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}});
  return img;
}
}  // namespace

TEST(Stages, AcquisitionMakesGreyAndResizes) {
  cv::Mat bgr(100, 200, CV_8UC3, cv::Scalar(10, 20, 30));
  AcquisitionSettings a;
  a.resize = false;
  double sx = 0, sy = 0;
  cv::Mat g = stages::acquire(bgr, a, &sx, &sy);
  EXPECT_EQ(g.type(), CV_8UC1);
  EXPECT_EQ(g.size(), cv::Size(200, 100));
  a.resize = true;
  a.size = {100, 0};
  g = stages::acquire(bgr, a, &sx, &sy);
  EXPECT_EQ(g.size(), cv::Size(100, 50));  // aspect kept
  EXPECT_DOUBLE_EQ(sx, 2.0);
  EXPECT_DOUBLE_EQ(sy, 2.0);
  // The paper's 640x480 (aspect not kept), and the resized colour frame for callers that show it.
  a.size = {640, 480};
  cv::Mat colour;
  g = stages::acquire(bgr, a, &sx, &sy, &colour);
  EXPECT_EQ(g.size(), cv::Size(640, 480));
  EXPECT_EQ(g.type(), CV_8UC1);
  EXPECT_EQ(colour.size(), cv::Size(640, 480));
  EXPECT_EQ(colour.type(), CV_8UC3);
  EXPECT_EQ(colour.at<cv::Vec3b>(240, 320), cv::Vec3b(10, 20, 30));
  EXPECT_DOUBLE_EQ(sx, 200.0 / 640);
  EXPECT_DOUBLE_EQ(sy, 100.0 / 480);
  // Resize off: the colour frame is a copy, never the caller's buffer.
  a.resize = false;
  g = stages::acquire(bgr, a, &sx, &sy, &colour);
  EXPECT_EQ(colour.size(), bgr.size());
  EXPECT_NE(colour.data, bgr.data);
}

// A colour frame's grey image is converted where the stages ask, by tiles; what is converted is the conversion's.
TEST(Stages, GreyOnDemandConvertsOnlyTheTilesAskedFor) {
  cv::Mat bgr(70, 100, CV_8UC3);   // 4 x 3 tiles of 32, the last column and row cut
  cv::randu(bgr, 0, 256);
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  stages::GreyOnDemand g(bgr);
  EXPECT_EQ(g.image().size(), bgr.size());
  EXPECT_DOUBLE_EQ(g.converted(), 0.0);
  g.need(cv::Rect(-10, -10, 5, 5));   // outside: nothing
  EXPECT_DOUBLE_EQ(g.converted(), 0.0);
  g.need(cv::Rect(40, 10, 5, 5));   // inside tile (1, 0)
  EXPECT_DOUBLE_EQ(g.converted(), 1.0 / 12);
  EXPECT_EQ(cv::norm(g.image()(cv::Rect(32, 0, 32, 32)), expected(cv::Rect(32, 0, 32, 32)), cv::NORM_INF), 0);
  g.need(cv::Rect(20, 20, 60, 30));   // tiles (0..2, 0..1): five more, around the one done
  EXPECT_DOUBLE_EQ(g.converted(), 6.0 / 12);
  EXPECT_EQ(cv::norm(g.image()(cv::Rect(0, 0, 96, 64)), expected(cv::Rect(0, 0, 96, 64)), cv::NORM_INF), 0);
  g.need(cv::Rect(90, 60, 100, 100));   // tiles (2..3, 1..2), clipped: three more, the corner one cut
  EXPECT_DOUBLE_EQ(g.converted(), 9.0 / 12);
  EXPECT_EQ(cv::norm(g.image()(cv::Rect(64, 32, 36, 38)), expected(cv::Rect(64, 32, 36, 38)), cv::NORM_INF), 0);
  g.need_all();
  EXPECT_DOUBLE_EQ(g.converted(), 1.0);
  EXPECT_EQ(cv::norm(g.image(), expected, cv::NORM_INF), 0);
  // BGRA the same; a grey frame is the grey image itself.
  cv::Mat bgra;
  cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
  stages::GreyOnDemand a(bgra);
  a.need_all();
  EXPECT_EQ(cv::norm(a.image(), expected, cv::NORM_INF), 0);
  stages::GreyOnDemand grey(expected);
  EXPECT_TRUE(grey.colour().empty());
  EXPECT_DOUBLE_EQ(grey.converted(), 1.0);
  EXPECT_EQ(grey.image().data, expected.data);
}

// A cap lowers the vector level the kernels take while it lives, for every thread, and puts the last one back.
TEST(Stages, SimdCapLowersTheLevelAndPutsItBack) {
  const Simd cpu = simd_of_cpu();
  EXPECT_EQ(simd(), cpu);
  {
    SimdCap none(Simd::none);
    EXPECT_EQ(simd(), Simd::none);
    {
      SimdCap all(Simd::avx512_vbmi);
      EXPECT_EQ(simd(), cpu);   // never above the processor's
    }
    EXPECT_EQ(simd(), Simd::none);
  }
  EXPECT_EQ(simd(), cpu);
  EXPECT_EQ(simd_levels_here().back(), cpu);
  EXPECT_STREQ(simd_name(Simd::avx2), "avx2");
  EXPECT_STREQ(simd_name(Simd::avx512_vbmi), "avx512vbmi");
}

// The grey levels are cvtColor's to the level for every colour (the stages' own conversion is vectorised apart from
// OpenCV's), in a whole frame and in tiles whose rows end off the vector width.
TEST(Stages, GreyConversionIsCvtColorsForEveryColour) {
  cv::Mat all(4096, 4096, CV_8UC3);   // all 2^24 colours, each once
  for (int i = 0; i < 1 << 24; ++i) {
    uint8_t* p = all.data + 3 * size_t(i);
    p[0] = uint8_t(i), p[1] = uint8_t(i >> 8), p[2] = uint8_t(i >> 16);
  }
  cv::Mat expected;
  cv::cvtColor(all, expected, cv::COLOR_BGR2GRAY);
  // Each path the processor has (AVX-512, AVX2, SSSE3, plain C++), each row's tail by the narrower ones.
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    stages::GreyOnDemand whole(all);
    whole.need_all();
    EXPECT_EQ(cv::countNonZero(whole.image() != expected), 0);
    const cv::Mat odd = all(cv::Rect(3, 5, 1001, 77));   // a view: its rows are not contiguous
    stages::GreyOnDemand tiles(odd);
    tiles.need(cv::Rect(7, 1, 50, 9));
    tiles.need(cv::Rect(500, 40, 501, 37));
    const cv::Rect a(0, 0, 64, 32), b(480, 32, 521, 45);
    EXPECT_EQ(cv::countNonZero(tiles.image()(a) != expected(cv::Rect(3, 5, 1001, 77))(a)), 0);
    EXPECT_EQ(cv::countNonZero(tiles.image()(b) != expected(cv::Rect(3, 5, 1001, 77))(b)), 0);
    double sx = 0, sy = 0;
    EXPECT_EQ(cv::countNonZero(stages::acquire(odd, AcquisitionSettings{.resize = false}, &sx, &sy) !=
                               expected(cv::Rect(3, 5, 1001, 77))),
              0);
  }
}

// The search image of a whole colour frame at 2 is the grey image's 2x2 block means, made as each pair of rows is
// converted, on any side and of a view whose rows are not contiguous; the grey image is then converted whole.
TEST(Stages, HalfSizeSearchImageIsTheDecimatedGreyImageMadeInOnePass) {
  cv::RNG rng(7);
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    for (const cv::Size size : {cv::Size(2, 2), cv::Size(37, 23), cv::Size(641, 361), cv::Size(1921, 1081)}) {
      cv::Mat frame(size.height + 4, size.width + 6, CV_8UC3);
      rng.fill(frame, cv::RNG::UNIFORM, 0, 256);
      const cv::Mat bgr = frame(cv::Rect(cv::Point(3, 2), size));
      cv::rectangle(frame, cv::Rect(0, 0, size.width / 2, size.height), cv::Scalar(255, 0, 0), -1);   // saturated
      cv::Mat grey;
      cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
      stages::GreyOnDemand g(bgr);
      const cv::Mat half = stages::search_image(g, cv::Rect(cv::Point(0, 0), size), 2);
      cv::Mat expected;   // cv::resize's INTER_AREA halving, on the whole blocks
      cv::resize(grey(cv::Rect(0, 0, size.width / 2 * 2, size.height / 2 * 2)), expected,
                 cv::Size(size.width / 2, size.height / 2), 0, 0, cv::INTER_AREA);
      EXPECT_EQ(cv::norm(stages::decimate(grey, 2), expected, cv::NORM_INF), 0) << size;
      ASSERT_EQ(half.size(), expected.size()) << size;
      EXPECT_EQ(cv::norm(half, expected, cv::NORM_INF), 0) << size;
      EXPECT_DOUBLE_EQ(g.converted(), 1.0) << size;
      EXPECT_EQ(cv::norm(g.image(), grey, cv::NORM_INF), 0) << size;
    }
  }
  // Of a region, the region's grey pixels decimated, converting little more than the region.
  cv::Mat bgr(200, 300, CV_8UC3);
  rng.fill(bgr, cv::RNG::UNIFORM, 0, 256);
  stages::GreyOnDemand g(bgr);
  const cv::Rect region(64, 32, 64, 64);
  const cv::Mat part = stages::search_image(g, region, 2);
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(part, stages::decimate(grey(region), 2), cv::NORM_INF), 0);
  EXPECT_LT(g.converted(), 0.2);
}

// The refinement's profiles are the fixed-point bilinear blend, to the integer, whichever way they are computed (eight
// samples at a time with AVX2 where the line stays 3 pixels inside the row's end, one at a time elsewhere): random
// lines of every length in every direction, in a view whose rows are not contiguous, up to the image's last column.
TEST(Stages, ProfileSamplesAreTheFixedPointBilinearBlend) {
  cv::RNG rng(11);
  cv::Mat frame(230, 331, CV_8UC1);
  rng.fill(frame, cv::RNG::UNIFORM, 0, 256);
  const cv::Mat grey = frame(cv::Rect(5, 3, 317, 211));
  auto expected = [&](cv::Point2d from, cv::Point2d step, int j) {
    const int64_t x = std::llround(from.x * 65536) + j * std::llround(step.x * 65536);
    const int64_t y = std::llround(from.y * 65536) + j * std::llround(step.y * 65536);
    const int qx = int(x >> 8), qy = int(y >> 8), fx = qx & 255, fy = qy & 255;
    const uint8_t* r0 = grey.ptr<uint8_t>(qy >> 8) + (qx >> 8);
    const uint8_t* r1 = grey.ptr<uint8_t>((qy >> 8) + 1) + (qx >> 8);
    const int top = r0[0] * (256 - fx) + r0[1] * fx, bottom = r1[0] * (256 - fx) + r1[1] * fx;
    return top * (256 - fy) + bottom * fy;
  };
  int lines = 0, near_end = 0;
  for (int k = 0; k < 4000; ++k) {
    const int n = 1 + k % 40;
    const double angle = rng.uniform(0.0, 2 * CV_PI);
    const cv::Point2d step(0.5 * std::cos(angle), 0.5 * std::sin(angle));
    const cv::Point2d from(rng.uniform(0.0, grey.cols - 1.01), rng.uniform(0.0, grey.rows - 1.01));
    const cv::Point2d to = from + step * double(n - 1);
    if (to.x < 0 || to.y < 0 || to.x > grey.cols - 1.001 || to.y > grey.rows - 1.001) continue;
    std::vector<int> profile(static_cast<size_t>(n), 0);
    stages::sample_line(grey, from, step, profile);
    ++lines;
    if (std::max(from.x, to.x) >= grey.cols - 4) ++near_end;
    for (int j = 0; j < n; ++j) {
      ASSERT_EQ(profile[size_t(j)], expected(from, step, j)) << "line " << k << " sample " << j;
      const cv::Point2d at = from + step * double(j);
      cv::Mat one;
      cv::getRectSubPix(grey, cv::Size(1, 1), cv::Point2f(at), one, CV_32F);
      // Positions rounded down to 1/256 pixel, on noise that changes by up to 255 levels a pixel: within 3 levels of
      // OpenCV's bilinear value.
      EXPECT_NEAR(profile[size_t(j)] / 65536.0, one.at<float>(0, 0), 3.0);
    }
  }
  EXPECT_GT(lines, 2000);
  EXPECT_GT(near_end, 10);
  // Starts and steps exactly half a 1/65536 pixel off the grid round away from zero, as std::llround, and just
  // under a half towards it.
  const double half = 0.5 / 65536, under = std::nextafter(0.5, 0.0) / 65536;
  for (const double off : {half, -half, under, -under, 3 * half})
    for (const double s : {off, -off, 0.5 + off, -0.5 - off}) {
      const cv::Point2d from(100 + off, 50 - off), step(s, -s);
      std::vector<int> profile(9, 0);
      stages::sample_line(grey, from, step, profile);
      for (int j = 0; j < 9; ++j) ASSERT_EQ(profile[size_t(j)], expected(from, step, j)) << off << " " << s << " " << j;
    }
}

TEST(Stages, AdaptiveThresholdMarksDarkAgainstItsNeighbourhood) {
  cv::Mat grey(60, 60, CV_8UC1, cv::Scalar(200));
  cv::rectangle(grey, cv::Rect(20, 20, 20, 20), cv::Scalar(40), -1);
  DetectorParams p;
  const cv::Mat bin = stages::adaptive_threshold(grey, p);
  EXPECT_EQ(bin.at<uint8_t>(21, 21), 255);  // dark edge pixel
  EXPECT_EQ(bin.at<uint8_t>(5, 5), 0);      // flat light area
  // A flat area, however dark, is not "darker than its neighbourhood".
  const cv::Mat flat = stages::adaptive_threshold(cv::Mat(60, 60, CV_8UC1, cv::Scalar(30)), p);
  EXPECT_EQ(cv::countNonZero(flat), 0);
}

// From a window of 9 up, the mean is the box mean of the 2x2 block means brought back to every pixel bilinearly
// (as cv::resize's INTER_LINEAR, computed exactly: a pixel may differ only where the two are within a grey level
// of each other), the blocks are the whole ones, and an odd last column or row is compared with the mean before it.
TEST(Stages, AdaptiveThresholdIsTheBilinearBlockMeanOnAnySide) {
  cv::Mat img(161, 213, CV_8UC1);
  cv::randu(img, 60, 200);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 2.0);
  cv::rectangle(img, cv::Rect(40, 30, 60, 60), cv::Scalar(30), cv::FILLED);
  DetectorParams p;
  const int offset = int(p.threshold_offset);
  for (const cv::Size size : {cv::Size(212, 160), cv::Size(213, 161), cv::Size(33, 47)}) {
    const cv::Mat grey = img(cv::Rect({0, 0}, size));
    const cv::Mat bin = stages::adaptive_threshold(grey, p);
    ASSERT_EQ(bin.size(), size);
    const cv::Size whole(size.width / 2, size.height / 2);
    cv::Mat blocks, mean, up;
    cv::resize(grey(cv::Rect({0, 0}, whole * 2)), blocks, whole, 0, 0, cv::INTER_AREA);
    const int half = (p.threshold_window_px / 2) | 1;
    cv::boxFilter(blocks, mean, CV_8U, cv::Size(half, half), cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
    cv::resize(mean, up, whole * 2, 0, 0, cv::INTER_LINEAR);
    int differ = 0;
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        const int m = up.at<uint8_t>(std::min(y, up.rows - 1), std::min(x, up.cols - 1));
        const int lifted = std::min(grey.at<uint8_t>(y, x) + offset, 255);
        if (bin.at<uint8_t>(y, x) == (lifted <= m ? 255 : 0)) continue;
        ++differ;
        EXPECT_LE(std::abs(lifted - m), 1) << size << " at " << x << "," << y;
      }
    EXPECT_LT(differ, int(grey.total()) / 200) << size;
  }
  // An odd side adds a column and a row; the pixels before them are thresholded as without them.
  const cv::Mat even = stages::adaptive_threshold(img(cv::Rect(0, 0, 212, 160)), p);
  const cv::Mat odd = stages::adaptive_threshold(img, p);
  EXPECT_EQ(cv::countNonZero(odd(cv::Rect(0, 0, 212, 160)) != even), 0);
}

// The comparison is its formula to the pixel on every width, whichever vectors do it (AVX-512's 64 pixels, AVX2's 32,
// 16 of OpenCV's universal intrinsics, one at a time at the end; each level the processor has): the block means (cv::boxFilter's, which the stage's own
// box mean matches up to a window of 15 blocks) blended 3:1 between rows, then 3:1 with the neighbouring block,
// rounded to the nearest sixteenth.
TEST(Stages, AdaptiveThresholdComparesByItsFormulaExactly) {
  DetectorParams p;
  const int offset = int(p.threshold_offset);
  cv::RNG rng(3);
  // 32 pixels a side at least: smaller images are cv::adaptiveThreshold's.
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    for (const int window : {9, 13, 17, 21, 27, 31, 45}) {   // box means of 5, 7, 9, 11, 13, 15 and 23 blocks
      for (const cv::Size size : {cv::Size(641, 361), cv::Size(213, 161), cv::Size(1920, 40), cv::Size(70, 34)}) {
        p.threshold_window_px = window;
        cv::Mat grey(size, CV_8UC1);
        rng.fill(grey, cv::RNG::UNIFORM, 0, 256);
        cv::GaussianBlur(grey, grey, cv::Size(0, 0), 1.5);
        grey(cv::Rect(0, 0, size.width / 3, size.height)).setTo(250);   // saturating lifts too
        const cv::Mat bin = stages::adaptive_threshold(grey, p);
        const cv::Size whole(size.width / 2, size.height / 2);
        cv::Mat blocks, mean;
        cv::resize(grey(cv::Rect({0, 0}, whole * 2)), blocks, whole, 0, 0, cv::INTER_AREA);
        const int half = (p.threshold_window_px / 2) | 1;
        cv::boxFilter(blocks, mean, CV_8U, cv::Size(half, half), cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
        int wrong = 0;
        for (int y = 0; y < size.height; ++y) {
          const int yy = std::min(y, 2 * mean.rows - 1), j = yy / 2;
          const int far = std::clamp(yy % 2 ? j + 1 : j - 1, 0, mean.rows - 1);
          auto v = [&](int i) {
            i = std::clamp(i, 0, mean.cols - 1);
            return 3 * mean.at<uint8_t>(j, i) + mean.at<uint8_t>(far, i);
          };
          for (int x = 0; x < size.width; ++x) {
            const int i = std::min(x / 2, mean.cols - 1), side = x >= 2 * mean.cols ? 1 : x % 2 ? 1 : -1;
            const int m = (3 * v(i) + v(i + side) + 8) >> 4;
            const bool dark = std::min(grey.at<uint8_t>(y, x) + offset, 255) <= m;
            wrong += bin.at<uint8_t>(y, x) != (dark ? 255 : 0);
          }
        }
        EXPECT_EQ(wrong, 0) << size << " window " << window << " " << simd_name(level);
      }
    }
  }
}

// The regions contours finds are OpenCV's 8-connected components, on any width (rows are scanned 64 pixels at a
// time, the last part pixel by pixel) and whatever nonzero value marks a pixel on.
TEST(Stages, ContourRegionsAreTheEightConnectedComponents) {
  // Each level of vector code the processor has (AVX-512, AVX2, plain).
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    for (const int width : {64, 131, 200, 257}) {
      cv::Mat noise(97, width, CV_8UC1), bin;
      cv::randu(noise, 0, 256);
      cv::threshold(noise, bin, 150, 255, cv::THRESH_BINARY);
      cv::rectangle(bin, cv::Rect(width / 3, 20, width / 3, 40), cv::Scalar(255), cv::FILLED);  // long runs
      bin.rowRange(70, 73).setTo(255);   // whole rows: 64-pixel chunks all on, a run carried across them
      bin.rowRange(80, 83).setTo(0);     // and all off
      bin.col(width - 1).setTo(255);     // runs to the row's end
      bin.at<uint8_t>(5, 7) = 1;
      cv::Mat labels, stats, centroids;
      const int components = cv::connectedComponentsWithStats(bin, labels, stats, centroids, 8) - 1;
      int regions = 0;
      std::vector<stages::SmallRegion> small;
      stages::find_contours(bin, 1e9, &regions, &small);   // every region too short: each one's box in `small`
      EXPECT_EQ(regions, components) << width;
      std::vector<std::array<int, 4>> ours, theirs;
      for (const auto& r : small) ours.push_back({r.bbox.x, r.bbox.y, r.bbox.width, r.bbox.height});
      for (int k = 1; k <= components; ++k)
        theirs.push_back({stats.at<int>(k, cv::CC_STAT_LEFT), stats.at<int>(k, cv::CC_STAT_TOP),
                          stats.at<int>(k, cv::CC_STAT_WIDTH), stats.at<int>(k, cv::CC_STAT_HEIGHT)});
      std::sort(ours.begin(), ours.end());
      std::sort(theirs.begin(), theirs.end());
      EXPECT_EQ(ours, theirs) << width;
      // Without `small`, one-pixel regions (specks) are counted, not made runs: the same count and the same contours.
      // Pixels that touch only across a 64-pixel word's end are no specks.
      cv::Mat sparse = cv::Mat::zeros(bin.size(), CV_8UC1);
      bin(cv::Rect(0, 0, width, 30)).copyTo(sparse(cv::Rect(0, 0, width, 30)));
      cv::Mat dots = noise > 245;   // scattered single pixels, some touching
      dots.rowRange(30, bin.rows).copyTo(sparse.rowRange(30, bin.rows));
      if (width > 65) {
        sparse.at<uint8_t>(90, 63) = sparse.at<uint8_t>(91, 64) = 255;   // a pair, diagonal across the word's end
        sparse.at<uint8_t>(94, 64) = sparse.at<uint8_t>(94, 63) = 0;
        sparse.at<uint8_t>(93, 64) = 255;                                 // and a speck beside it on the next word
        for (int y = 92; y <= 94; ++y)
          for (int x = 62; x <= 66; ++x)
            if (y != 93 || x != 64) sparse.at<uint8_t>(y, x) = 0;
      }
      for (const double min_perimeter : {8.0, 20.0}) {
        int with_small = 0, without = 0;
        std::vector<stages::SmallRegion> boxes;
        const auto a = stages::find_contours(sparse, min_perimeter, &with_small, &boxes);
        const auto b = stages::find_contours(sparse, min_perimeter, &without);
        EXPECT_EQ(with_small, cv::connectedComponents(sparse, labels, 8) - 1) << width;
        EXPECT_EQ(without, with_small) << width;
        EXPECT_EQ(a, b) << width;
        EXPECT_GT(std::count_if(boxes.begin(), boxes.end(), [](const auto& r) { return r.bbox.area() == 1; }), 5);
      }
    }
  }
}

// Small regions, which contours takes out of its bit masks without labelling them (those within a 3x3 or 5x5 box
// whose border is below min_perimeter_px), are exactly the regions it would not trace: the same contours and the
// same region count as when every region is listed, on clusters of every shape up to 7x7 (rings with holes among
// them), packed closer than the ring around a window, at the image's edges and across the 64-pixel words.
TEST(Stages, SmallRegionsAreTakenOutWholeAndCountedExactly) {
  // Each level of vector code the processor has (AVX-512, AVX2, plain).
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    cv::RNG rng(7);
    for (const int width : {64, 131, 200, 257}) {
      for (const double density : {0.3, 0.6, 0.9}) {
        cv::Mat bin = cv::Mat::zeros(90, width, CV_8UC1);
        for (int k = 0; k < width * 3; ++k) {   // clusters of random pixels in random boxes of 1x1 to 7x7
          const int bw = rng.uniform(1, 8), bh = rng.uniform(1, 8);
          const int x0 = rng.uniform(-2, width), y0 = rng.uniform(-2, bin.rows);
          for (int y = y0; y < y0 + bh; ++y)
            for (int x = x0; x < x0 + bw; ++x)
              if (x >= 0 && y >= 0 && x < width && y < bin.rows && rng.uniform(0.0, 1.0) < density)
                bin.at<uint8_t>(y, x) = 255;
        }
        // Rings with holes: a 3x3 one (its hole the centre) and a 5x5 one, by a word's end; a long bar for a contour.
        const int at = std::min(width - 6, 61);
        for (const cv::Rect& clear : {cv::Rect(at - 2, 38, 7, 7), cv::Rect(at - 1, 59, 7, 7)})
          bin(clear & cv::Rect(0, 0, width, bin.rows)) = 0;
        cv::Mat five = bin(cv::Rect(at, 60, 5, 5));
        bin(cv::Rect(at, 40, 3, 3)).setTo(255);
        bin.at<uint8_t>(41, at + 1) = 0;
        five.setTo(255);
        five(cv::Rect(1, 1, 3, 3)).setTo(0);
        bin(cv::Rect(0, 80, width, 2)).setTo(255);
        cv::Mat labels;
        const int components = cv::connectedComponents(bin, labels, 8) - 1;
        for (const double min_perimeter : {8.0, 13.0, 20.0, 21.0, 48.0}) {
          int listed = 0, counted = 0;
          std::vector<stages::SmallRegion> small;
          const auto all = stages::find_contours(bin, min_perimeter, &listed, &small);   // nothing taken out
          const auto with_count = stages::find_contours(bin, min_perimeter, &counted);
          const auto without = stages::find_contours(bin, min_perimeter);
          EXPECT_EQ(listed, components) << width << " " << density << " " << min_perimeter;
          EXPECT_EQ(counted, components) << width << " " << density << " " << min_perimeter;
          EXPECT_EQ(with_count, all) << width << " " << density << " " << min_perimeter;
          EXPECT_EQ(without, all) << width << " " << density << " " << min_perimeter;
          EXPECT_FALSE(all.empty());
        }
      }
    }
  }
}

// The same on many small images, of every width to 200 and height to 12 (the rows' words with their ends any number
// modulo four), random pixels from sparse to dense.
TEST(Stages, SmallRegionsAreTakenOutRightOnImagesOfAnySize) {
  // Each level of vector code the processor has (AVX-512, AVX2, plain).
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    cv::RNG rng(11);
    for (int k = 0; k < 600; ++k) {
      const int w = rng.uniform(1, 201), h = rng.uniform(1, 13);
      cv::Mat noise(h, w, CV_8UC1), bin;
      cv::randu(noise, 0, 256);
      cv::threshold(noise, bin, rng.uniform(60, 250), 255, cv::THRESH_BINARY);
      cv::Mat labels;
      const int components = cv::connectedComponents(bin, labels, 8) - 1;
      for (const double min_perimeter : {5.0, 13.0, 21.0, 48.0}) {
        int listed = 0, counted = 0;
        std::vector<stages::SmallRegion> small;
        const auto all = stages::find_contours(bin, min_perimeter, &listed, &small);
        EXPECT_EQ(stages::find_contours(bin, min_perimeter, &counted), all) << w << "x" << h << " " << min_perimeter;
        EXPECT_EQ(stages::find_contours(bin, min_perimeter), all) << w << "x" << h << " " << min_perimeter;
        EXPECT_EQ(listed, components) << w << "x" << h;
        EXPECT_EQ(counted, components) << w << "x" << h << " " << min_perimeter;
      }
    }
  }
}

// The passes that find the small regions run along all rows at once, four words a step with AVX2, and the last step
// runs past the rows: what it finds below the image must not take pixels of the last rows. A bar along the last row
// of images whose rows' words (with their ends) are not a multiple of four: 160x6 (30 words), 160x5 (25), 150x2.
TEST(Stages, SmallRegionsLeaveALongBarOnTheLastRowWhole) {
  struct Case {
    int w, h, x0, x1;
  };
  for (const Case c : {Case{160, 6, 63, 100}, Case{160, 5, 127, 159}, Case{150, 2, 60, 90}, Case{200, 3, 0, 199}}) {
    cv::Mat bin = cv::Mat::zeros(c.h, c.w, CV_8UC1);
    bin(cv::Range(c.h - 1, c.h), cv::Range(c.x0, c.x1 + 1)).setTo(255);
    for (const double min_perimeter : {13.0, 21.0, 48.0}) {
      int listed = 0, counted = 0;
      std::vector<stages::SmallRegion> small;
      const auto all = stages::find_contours(bin, min_perimeter, &listed, &small);
      EXPECT_EQ(stages::find_contours(bin, min_perimeter, &counted), all) << c.w << "x" << c.h << " " << min_perimeter;
      EXPECT_EQ(stages::find_contours(bin, min_perimeter), all) << c.w << "x" << c.h << " " << min_perimeter;
      EXPECT_EQ(counted, 1) << c.w << "x" << c.h << " " << min_perimeter;
      ASSERT_EQ(all.size(), 1u);
      EXPECT_EQ(all[0].front(), cv::Point(c.x0, c.h - 1));
    }
  }
}

// Each contour is the Moore-neighbour trace of its region's outer border (from the top-left pixel, clockwise,
// stopping when the first step repeats) as the plain tracing reads it one neighbour at a time on the image: on
// random shapes across the 64-pixel words of the bit masks the tracing reads, and along the image's four edges.
TEST(Stages, ContoursAreTheMooreTraceOfEachOuterBorder) {
  // Each level of vector code the processor has (AVX-512, AVX2, plain).
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    auto moore = [](const cv::Mat& bin, cv::Point start) {
      const int dx[8] = {1, 1, 0, -1, -1, -1, 0, 1}, dy[8] = {0, 1, 1, 1, 0, -1, -1, -1};
      auto on = [&](int x, int y) { return x >= 0 && y >= 0 && x < bin.cols && y < bin.rows && bin.at<uint8_t>(y, x); };
      auto next = [&](cv::Point p, int from) {
        for (int k = 0; k < 8; ++k)
          if (on(p.x + dx[(from + k) & 7], p.y + dy[(from + k) & 7])) return (from + k) & 7;
        return -1;
      };
      std::vector<cv::Point> out{start};
      int d = next(start, 4);
      if (d < 0) return out;
      const cv::Point second(start.x + dx[d], start.y + dy[d]);
      cv::Point p = second;
      for (;;) {
        const int nd = next(p, (d & 1) ? (d + 5) & 7 : (d + 6) & 7);
        const cv::Point q(p.x + dx[nd], p.y + dy[nd]);
        if (p == start && q == second) break;
        out.push_back(p);
        p = q;
        d = nd;
      }
      return out;
    };
    cv::RNG rng(23);
    int traced = 0;
    for (const int width : {40, 64, 65, 127, 128, 190}) {
      cv::Mat bin = cv::Mat::zeros(70, width, CV_8UC1);
      for (int k = 0; k < 25; ++k) {   // blobs, some across a word's end, some over an edge of the image
        const cv::Point c(rng.uniform(-4, width + 4), rng.uniform(-4, 74));
        const cv::Size axes(rng.uniform(2, 14), rng.uniform(2, 14));
        cv::ellipse(bin, c, axes, rng.uniform(0.0, 180.0), 0, 360, cv::Scalar(255), cv::FILLED);
      }
      cv::Mat speckle(bin.size(), CV_8UC1);
      rng.fill(speckle, cv::RNG::UNIFORM, 0, 256);
      bin.setTo(0, speckle > 235);   // ragged borders and holes
      bin.setTo(255, speckle < 12);
      const auto contours = stages::find_contours(bin, 8);
      for (const auto& c : contours) {
        ASSERT_EQ(c, moore(bin, c.front())) << "width " << width << " from " << c.front();
        ++traced;
      }
    }
    EXPECT_GT(traced, 60);
  }
}

TEST(Stages, ContoursTraceOuterBordersClockwiseAndSkipSpecks) {
  cv::Mat bin = cv::Mat::zeros(50, 50, CV_8UC1);
  cv::rectangle(bin, cv::Rect(10, 10, 20, 15), cv::Scalar(255), -1);  // a block
  cv::rectangle(bin, cv::Rect(14, 14, 5, 5), cv::Scalar(0), -1);      // with a hole: no second border
  bin.at<uint8_t>(40, 40) = 255;                                      // a speck
  int regions = 0;
  std::vector<stages::SmallRegion> small;
  const auto contours = stages::find_contours(bin, 20, &regions, &small);
  EXPECT_EQ(regions, 2);
  ASSERT_EQ(contours.size(), 1u);
  ASSERT_EQ(small.size(), 1u);
  EXPECT_EQ(small[0].bbox, cv::Rect(40, 40, 1, 1));
  const auto& c = contours[0];
  EXPECT_EQ(c.front(), cv::Point(10, 10));
  EXPECT_EQ(cv::boundingRect(c), cv::Rect(10, 10, 20, 15));
  EXPECT_EQ(c.size(), size_t(2 * (19 + 14)));  // every border pixel once
  EXPECT_GT(cv::contourArea(c, true), 0);      // clockwise on screen (y down) is positive in OpenCV's sense
}

TEST(Stages, SizeFilterNamesTheParameterAndValue) {
  DetectorParams p;
  std::vector<cv::Point> small(31, cv::Point(0, 0));
  auto why = stages::size_filter(small, {640, 480}, p);
  ASSERT_TRUE(why);
  EXPECT_EQ(why->stage, Stage::size_filter);
  EXPECT_EQ(why->param, "min_perimeter_px");
  EXPECT_EQ(why->value, 31);
  EXPECT_EQ(why->message, "perimeter 31 px < min_perimeter_px 48 px");
  EXPECT_FALSE(stages::size_filter(std::vector<cv::Point>(100), {640, 480}, p));
}

TEST(Stages, QuadFitAcceptsSquaresAndRejectsOtherShapes) {
  DetectorParams p;
  cv::Mat bin = cv::Mat::zeros(100, 100, CV_8UC1);
  cv::rectangle(bin, cv::Rect(20, 20, 40, 40), cv::Scalar(255), -1);
  auto contours = stages::find_contours(bin, 10);
  Quad q;
  EXPECT_FALSE(stages::fit_quad(contours.at(0), bin.size(), p, &q));
  const cv::Point2f a = q[1] - q[0], b = q[2] - q[0];
  EXPECT_GT(a.x * b.y - a.y * b.x, 0);  // clockwise on screen

  cv::Mat disc = cv::Mat::zeros(100, 100, CV_8UC1);
  cv::circle(disc, {50, 50}, 30, cv::Scalar(255), -1);
  auto why = stages::fit_quad(stages::find_contours(disc, 10).at(0), disc.size(), p, &q);
  ASSERT_TRUE(why);
  EXPECT_EQ(why->stage, Stage::quad_fit);
  EXPECT_EQ(why->param, "polygon_epsilon_rate");

  cv::Mat edge = cv::Mat::zeros(100, 100, CV_8UC1);
  cv::rectangle(edge, cv::Rect(0, 30, 40, 40), cv::Scalar(255), -1);  // touches the image edge
  why = stages::fit_quad(stages::find_contours(edge, 10).at(0), edge.size(), p, &q);
  ASSERT_TRUE(why);
  EXPECT_EQ(why->param, "min_border_distance_px");
}

// quad_fit's own Douglas-Peucker polygon (it stops early on shapes of many corners) closes a quad exactly where
// The polygon approximation's search for the farthest point (four points at a time with AVX2, the rest one at a
// time) finds the first of the farthest, as a plain loop does: random point lists of every length from 0 to 40,
// on a small grid so that many points tie, from a point and from a line, and a list at the far ends of int.
TEST(Stages, FarthestPointIsTheFirstOfTheFarthest) {
  // Each level of vector code the processor has (AVX-512 sixteen points a step, AVX2 four, plain).
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    cv::RNG rng(17);
    auto expected = [](const std::vector<cv::Point>& c, cv::Point p0, cv::Point dir, bool line) {
      stages::Farthest f;
      for (int k = 0; k < int(c.size()); ++k) {
        const int64_t dx = int64_t(c[size_t(k)].x) - p0.x, dy = int64_t(c[size_t(k)].y) - p0.y;
        const int64_t m = line ? std::abs(dy * dir.x - dx * dir.y) : dx * dx + dy * dy;
        if (m > f.measure) f = {m, k};
      }
      return f;
    };
    for (int trial = 0; trial < 4000; ++trial) {
      const int n = trial % 71;
      const int range = trial % 3 == 0 ? 3 : 200;
      std::vector<cv::Point> c(static_cast<size_t>(n));
      for (auto& q : c) q = cv::Point(rng.uniform(-range, range + 1), rng.uniform(-range, range + 1));
      const cv::Point p0(rng.uniform(-range, range + 1), rng.uniform(-range, range + 1));
      const cv::Point dir(rng.uniform(-range, range + 1), rng.uniform(-range, range + 1));
      for (bool line : {false, true}) {
        const stages::Farthest got = stages::farthest_point(c.data(), n, p0, dir, line);
        const stages::Farthest want = expected(c, p0, dir, line);
        ASSERT_EQ(got.at, want.at) << "trial " << trial << (line ? " from a line" : " from a point");
        ASSERT_EQ(got.measure, want.measure) << "trial " << trial;
      }
    }
    // Coordinates of 2^30: the squares and cross products need all 64 bits.
    std::vector<cv::Point> far(16, cv::Point(0, 0));
    far[9] = cv::Point(1 << 30, -(1 << 30));
    far[13] = cv::Point(-(1 << 30), 1 << 30);
    EXPECT_EQ(stages::farthest_point(far.data(), 16, {0, 0}, {}, false).at, 9);
    EXPECT_EQ(stages::farthest_point(far.data(), 16, {0, 0}, {1 << 30, 1 << 30}, true).at, 9);
  }
}

// cv::approxPolyDP's polygon has four vertices: regular polygons of 3 to 9 corners, turned, and random quads.
TEST(Stages, QuadFitClosesAQuadWhereApproxPolyDPHasFourVertices) {
  DetectorParams p;
  cv::RNG rng(3);
  int quads = 0, shapes = 0;
  for (int corners = 3; corners <= 9; ++corners)
    for (int turn = 0; turn < 12; ++turn) {
      std::vector<cv::Point> poly;
      const double radius = rng.uniform(40.0, 90.0);
      for (int k = 0; k < corners; ++k) {
        const double angle = 2 * CV_PI * k / corners + turn * 0.13;
        // Random quads: each corner pushed about; other polygons regular.
        const double r = corners == 4 ? radius * rng.uniform(0.7, 1.0) : radius;
        poly.emplace_back(int(100 + r * std::cos(angle)), int(100 + r * std::sin(angle)));
      }
      cv::Mat bin = cv::Mat::zeros(200, 200, CV_8UC1);
      cv::fillConvexPoly(bin, poly, cv::Scalar(255));
      const auto contours = stages::find_contours(bin, p.min_perimeter_px);
      ASSERT_EQ(contours.size(), 1u);
      const std::vector<cv::Point>& c = contours[0];
      ASSERT_GE(c.size(), 100u);   // no second try at twice the tolerance
      std::vector<cv::Point> expected;
      cv::approxPolyDP(c, expected, p.polygon_epsilon_rate * double(c.size()), true);
      Quad q;
      const auto why = stages::fit_quad(c, bin.size(), p, &q);
      const bool closed = !why || why->param != "polygon_epsilon_rate";
      EXPECT_EQ(closed, expected.size() == 4) << corners << " corners, turn " << turn << ": approxPolyDP "
                                              << expected.size() << (why ? ", " + why->message : "");
      ++shapes;
      if (!why) {
        ++quads;
        // Each corner within a few pixels of a vertex of approxPolyDP's (the corners are where the sides meet).
        for (const cv::Point2f& corner : q) {
          double nearest = 1e9;
          for (const cv::Point& v : expected) nearest = std::min(nearest, cv::norm(corner - cv::Point2f(v)));
          EXPECT_LT(nearest, 3.0) << corners << " corners, turn " << turn;
        }
      }
    }
  EXPECT_EQ(shapes, 84);
  EXPECT_GE(quads, 10);
}

TEST(Stages, FineSearchPlansARegionAroundEachSmallSquarishShape) {
  DetectorParams p;   // fine_max_side_px 80, threshold_window_px 17, min_perimeter_px 48
  const cv::Size frame(640, 480);
  // A 30 px shape: half a side (15 px) of margin each way.
  std::vector<cv::Rect> r = stages::plan_fine_search({cv::Rect(100, 100, 30, 30)}, frame, p);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0], cv::Rect(85, 85, 60, 60));
  // A 12 px shape: at least half the threshold's window and 2 px (10 px).
  r = stages::plan_fine_search({cv::Rect(200, 200, 12, 12)}, frame, p);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0], cv::Rect(190, 190, 32, 32));
  // Too long, too thin, too small to hold 3/4 of min_perimeter_px: not searched again.
  EXPECT_TRUE(stages::plan_fine_search({cv::Rect(0, 0, 81, 76), cv::Rect(300, 300, 40, 10), cv::Rect(50, 50, 8, 8)},
                                       frame, p).empty());
  // Overlapping regions are merged, and clipped to the frame; less than 32 px a side left in a corner is dropped.
  r = stages::plan_fine_search({cv::Rect(100, 100, 30, 30), cv::Rect(140, 100, 30, 30), cv::Rect(610, 440, 30, 30),
                                cv::Rect(626, 466, 12, 12)},
                               frame, p);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0], cv::Rect(85, 85, 100, 60));
  EXPECT_EQ(r[1], cv::Rect(595, 425, 45, 55));
  p.fine_max_side_px = 0;
  EXPECT_TRUE(stages::plan_fine_search({cv::Rect(100, 100, 30, 30)}, frame, p).empty()) << "off";
}

// A binary image of a half-size search (factor 2): a dark ring whose quiet zone closed into a larger dark shape
// still holds a light quad, and quad_holes gives its box in the grey image's pixels; a round hole, a quad hole
// larger than fine_max_side_px and the light background are not given, nor the holes inside a marker read.
TEST(Stages, QuadHolesFindTheInsideOfARingMergedIntoALargerShape) {
  // Each level of vector code the processor has (the light regions' masks: AVX-512, AVX2, plain).
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    DetectorParams p;   // fine_max_side_px 80, min_perimeter_px 48
    cv::Mat bin(200, 300, CV_8UC1, cv::Scalar(0));
    cv::rectangle(bin, cv::Rect(20, 20, 60, 150), cv::Scalar(255), -1);    // the larger shape
    cv::rectangle(bin, cv::Rect(80, 60, 16, 16), cv::Scalar(255), -1);     // the ring, touching it
    cv::rectangle(bin, cv::Rect(83, 63, 10, 10), cv::Scalar(0), -1);       // its inside
    bin(cv::Rect(86, 66, 2, 3)).setTo(255);                                  // a cell inside, apart from the ring
    cv::circle(bin, cv::Point(160, 100), 16, cv::Scalar(255), -1);         // a round hole in a disc
    cv::circle(bin, cv::Point(160, 100), 9, cv::Scalar(0), -1);
    cv::rectangle(bin, cv::Rect(200, 40, 60, 60), cv::Scalar(255), -1);    // a quad hole 2 x 50 px a side
    cv::rectangle(bin, cv::Rect(205, 45, 50, 50), cv::Scalar(0), -1);
    // The dark shapes' boxes in the grey image's pixels (the binary lies at (10, 0)).
    auto boxes = [](const cv::Mat& b, int min_perimeter) {
      std::vector<cv::Rect> out;
      for (const auto& c : stages::find_contours(b, min_perimeter, nullptr, nullptr, 2))
        out.push_back(cv::boundingRect(c) + cv::Point(10, 0));
      return out;
    };
    const std::vector<cv::Rect> dark = boxes(bin, int(p.min_perimeter_px));
    const std::vector<cv::Rect> holes = stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2);
    ASSERT_EQ(holes.size(), 1u);
    // The inside's pixels 83..92 are the blocks' centres 2 x 83 + 10 (the origin) .. 2 x 92 + 10 in the grey image.
    EXPECT_EQ(holes[0], cv::Rect(176, 126, 19, 19));
    // Inside a marker read, a hole is the marker's: a quad around the ring (grey image's pixels), or one around its
    // inside only (its centre in the marker), leaves none; a marker beside it leaves it.
    const Quad ring{cv::Point2f(170, 120), {201, 120}, {201, 151}, {170, 151}};
    EXPECT_TRUE(stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2, {ring}).empty());
    const Quad centre{cv::Point2f(182, 132), {189, 132}, {189, 139}, {182, 139}};
    EXPECT_TRUE(stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2, {centre}).empty());
    const Quad beside{cv::Point2f(420, 90), {520, 90}, {520, 190}, {420, 190}};
    EXPECT_EQ(stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2, {beside}).size(), 1u);
    // Only shapes longer than fine_max_side_px are looked into: a ring of 60 px (30 decimated) on its own is searched
    // again whole if it does not read.
    cv::Mat alone(200, 300, CV_8UC1, cv::Scalar(0));
    cv::rectangle(alone, cv::Rect(80, 60, 30, 30), cv::Scalar(255), -1);
    cv::rectangle(alone, cv::Rect(85, 65, 20, 20), cv::Scalar(0), -1);
    EXPECT_TRUE(stages::quad_holes(alone, boxes(alone, int(p.min_perimeter_px)), cv::Point(10, 0), cv::Size(620, 400),
                                   p, 2)
                    .empty());
    p.fine_max_side_px = 0;
    EXPECT_TRUE(stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2).empty()) << "off";
  }
}

TEST(Stages, NestedFilterKeepsTheOuterOfTwoTracesOfOneBorder) {
  DetectorParams p;
  const Quad outer{cv::Point2f(10, 10), {110, 10}, {110, 110}, {10, 110}};
  const Quad inner{cv::Point2f(12, 12), {108, 12}, {108, 108}, {12, 108}};
  const Quad far{cv::Point2f(200, 200), {250, 200}, {250, 250}, {200, 250}};
  const auto r = stages::nested_filter({inner, outer, far}, p);
  EXPECT_EQ(r[0], 1);  // inner replaced by outer
  EXPECT_EQ(r[1], -1);
  EXPECT_EQ(r[2], -1);
}

TEST(Stages, PerspectiveOtsuBitsBorderAndIdentification) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = canvas_with_marker(d, 321, 40, 50, 105);
  DetectorParams p;
  const Quad q{cv::Point2f(40, 50), {145, 50}, {145, 155}, {40, 155}};
  const cv::Mat warp = stages::remove_perspective(img, q, 7, p);
  EXPECT_EQ(warp.size(), cv::Size(28, 28));
  const auto o = stages::otsu(warp);
  EXPECT_GT(o.threshold, 20);
  EXPECT_LT(o.threshold, 235);
  EXPECT_GT(o.stddev, 50);
  int total = 0;
  for (int v : o.histogram) total += v;
  EXPECT_EQ(total, 28 * 28);
  const cv::Mat bits = stages::sample_bits(warp, 7, o.threshold, p);
  EXPECT_EQ(stages::border_errors(bits), 0);
  EXPECT_EQ(cv::countNonZero(bits(cv::Rect(1, 1, 5, 5)) != d.bits(321)), 0);
  const DictMatch m = d.nearest(stages::inner_code(bits));
  EXPECT_EQ(m.id, 321);
  EXPECT_EQ(m.hamming, 0);
  EXPECT_EQ(stages::correction_budget(*dictionary_by_name("6X6_250"), p), 3);  // OpenCV's 5 bits x rate 0.6
  EXPECT_EQ(stages::correction_budget(d, p), 0);
}

// The warp against OpenCV's own: cv::getPerspectiveTransform and cv::warpPerspective (bilinear, pixel centres, the
// edge replicated) on a tilted quad inside the image, one that crosses the image's edge, and a bowtie that corner
// refinement could bend a quad into. Within a grey level everywhere.
TEST(Stages, PerspectiveRemovalMatchesOpenCVsWarpInsideAcrossTheEdgeAndOnABowtie) {
  cv::Mat img(120, 160, CV_8UC1);   // smooth, so that OpenCV's 1/32 pixel steps cost under a grey level
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x)
      img.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(128 + 100 * std::sin(x / 9.0) * std::cos(y / 7.0));
  DetectorParams p;
  const Quad quads[] = {Quad{cv::Point2f(30.3f, 20.7f), {101.2f, 31.9f}, {92.8f, 99.4f}, {25.1f, 84.6f}},
                        Quad{cv::Point2f(-12.5f, 60.2f), {70.1f, 55.4f}, {75.3f, 131.8f}, {-8.4f, 125.0f}},
                        Quad{cv::Point2f(20, 20), {90, 90}, {90, 20}, {20, 90}}};
  for (const Quad& q : quads) {
    const cv::Mat warp = stages::remove_perspective(img, q, 7, p);
    const float s = float(warp.cols);
    const cv::Point2f square[4] = {{0, 0}, {s, 0}, {s, s}, {0, s}};
    // Ours samples (u + 0.5, v + 0.5) of the square; warpPerspective samples destination pixel centres at integers.
    const cv::Matx33d H = cv::Matx33d(cv::getPerspectiveTransform(square, q.data())) *
                          cv::Matx33d(1, 0, 0.5, 0, 1, 0.5, 0, 0, 1);
    cv::Mat ref;
    cv::warpPerspective(img, ref, cv::Mat(H), warp.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                        cv::BORDER_REPLICATE);
    cv::Mat diff;
    cv::absdiff(warp, ref, diff);
    double worst = 0;
    cv::minMaxLoc(diff, nullptr, &worst);
    EXPECT_LE(worst, 1) << "quad " << q[0] << " " << q[1] << " " << q[2] << " " << q[3];
  }
}

// The warp's samples are the same integers whichever way they are taken: eight at a time with AVX2, or one at a time
// where a sample lies within 3 pixels of the image's last column. Quads reaching into those columns of a noisy
// image, warped there and in a wider copy of it (where those samples are taken eight at a time), are equal.
TEST(Stages, PerspectiveRemovalIsTheSameBySamplesOneOrEightAtATime) {
  cv::RNG rng(5);
  cv::Mat wide(120, 200, CV_8UC1);
  rng.fill(wide, cv::RNG::UNIFORM, 0, 256);
  const cv::Mat narrow = wide(cv::Rect(0, 0, 160, 120)).clone();
  DetectorParams p;
  for (int k = 0; k < 300; ++k) {
    Quad q;
    const float cx = rng.uniform(120.f, 150.f), cy = rng.uniform(30.f, 90.f), r = rng.uniform(5.f, 25.f);
    const float turn = rng.uniform(0.f, 6.28f);
    for (int j = 0; j < 4; ++j)
      q[size_t(j)] = cv::Point2f(cx + r * std::cos(turn + 1.5708f * float(j)), cy + r * std::sin(turn + 1.5708f * float(j)));
    float right = 0;
    for (const auto& c : q) right = std::max(right, c.x);
    const float shift = rng.uniform(156.5f, 158.8f) - right;   // into the last 4 columns, inside the last centre
    for (auto& c : q) c.x += shift;
    const cv::Mat a = stages::remove_perspective(narrow, q, 7, p), b = stages::remove_perspective(wide, q, 7, p);
    ASSERT_EQ(cv::norm(a, b, cv::NORM_INF), 0) << "quad " << k;
  }
}

TEST(Stages, QuietZoneIsLightAroundAMarkerAndDarkWhereAShapeGoesOn) {
  const Dictionary d = make_aruco_original();
  cv::Mat img = canvas_with_marker(d, 321, 40, 50, 105);
  const Quad q{cv::Point2f(40, 50), {145, 50}, {145, 155}, {40, 155}};
  DetectorParams p;
  const auto o = stages::otsu(stages::remove_perspective(img, q, 7, p));
  EXPECT_EQ(stages::quiet_zone(img, q, 7, o).dark_share, 0.0);
  // The same under a shadow across it: border and quiet zone darken alike, the step between them stays.
  cv::Mat shaded = img.clone();
  shaded(cv::Rect(0, 100, 200, 100)) *= 0.5;
  EXPECT_EQ(stages::quiet_zone(shaded, q, 7, o).dark_share, 0.0);
  // A black bar from the left side outwards: that side's quiet zone is dark, along part of it.
  cv::rectangle(img, cv::Rect(0, 50, 40, 60), cv::Scalar(0), -1);
  const stages::QuietZone left = stages::quiet_zone(img, q, 7, o);
  EXPECT_EQ(left.side, 3);
  EXPECT_NEAR(left.dark_share, 4.0 / 7, 1e-9);  // 60 of 105 px: the four cells from the top
  // Off the image, nothing counts: a marker at the frame's edge keeps its quiet zone.
  const cv::Mat edge = canvas_with_marker(d, 321, 0, 50, 105);
  const Quad at_edge{cv::Point2f(0, 50), {105, 50}, {105, 155}, {0, 155}};
  EXPECT_EQ(stages::quiet_zone(edge, at_edge, 7, o).dark_share, 0.0);
}

TEST(Stages, CornerRefinementReachesTheTrueCorner) {
  const Dictionary d = make_aruco_original();
  const Quad truth{cv::Point2f(40.3f, 50.6f), {146.1f, 48.2f}, {150.7f, 151.9f}, {37.5f, 155.4f}};
  cv::Mat img(220, 220, CV_8UC1, cv::Scalar(255));
  draw_marker(img, d, 5, truth);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.8);
  Quad guess = truth;
  for (auto& c : guess) c += cv::Point2f(1.2f, -0.9f);
  stages::refine_corners(img, guess, 7, DetectorParams{});
  for (int k = 0; k < 4; ++k) EXPECT_LT(cv::norm(guess[size_t(k)] - truth[size_t(k)]), 0.2) << "corner " << k;
}

// The refinement's profiles are analysed eight at a time with AVX2 and one at a time without: the corners come out
// the same to the last bit on every path the processor has, over markers of every size from 12 to 200 px, turned,
// blurred and noisy, near the image's edge too, from a decimated quad's start as well.
TEST(Stages, CornerRefinementIsTheSameToTheBitOnEveryPath) {
  const Dictionary d = make_aruco_original();
  cv::RNG rng(11);
  int compared = 0, moved = 0;
  for (int i = 0; i < 60; ++i) {
    const float side = float(rng.uniform(12.0, 200.0)), angle = float(rng.uniform(0.0, CV_PI / 2));
    const cv::Point2f centre(float(rng.uniform(0.3, 0.7)) * 320, float(rng.uniform(0.3, 0.7)) * 320);
    Quad truth;
    for (int k = 0; k < 4; ++k) {
      const float a = angle + float(k) * float(CV_PI / 2) - float(3 * CV_PI / 4);
      truth[size_t(k)] = centre + cv::Point2f(std::cos(a), std::sin(a)) * (side / std::sqrt(2.0f));
    }
    cv::Mat img(320, 320, CV_8UC1, cv::Scalar(230));
    draw_marker(img, d, i, truth);
    cv::GaussianBlur(img, img, cv::Size(0, 0), rng.uniform(0.5, 2.0));
    cv::Mat noise(img.size(), CV_16SC1);
    rng.fill(noise, cv::RNG::NORMAL, 0, 4);
    img.convertTo(img, CV_16SC1);
    img += noise;
    img.convertTo(img, CV_8UC1);
    Quad start = truth;
    for (auto& c : start) c += cv::Point2f(float(rng.uniform(-1.5, 1.5)), float(rng.uniform(-1.5, 1.5)));
    for (const int factor : {1, 2}) {
      std::vector<Quad> out;
      Quad refined = start;
      stages::refine_corners(img, refined, 7, DetectorParams{}, factor);
      for (size_t k = 0; k < 4; ++k) moved += cv::norm(refined[k] - start[k]) > 0.05;
      for (const Simd level : simd_levels_here()) {
        SimdCap cap(level);
        Quad q = start;
        stages::refine_corners(img, q, 7, DetectorParams{}, factor);
        out.push_back(q);
      }
      for (size_t l = 1; l < out.size(); ++l)
        for (size_t k = 0; k < 4; ++k) {
          EXPECT_EQ(out[l][k].x, out[0][k].x) << "marker " << i << " corner " << k << " " << simd_name(Simd(l));
          EXPECT_EQ(out[l][k].y, out[0][k].y) << "marker " << i << " corner " << k << " " << simd_name(Simd(l));
        }
      compared += int(out.size());
    }
  }
  EXPECT_EQ(compared, 120 * int(simd_levels_here().size()));
  EXPECT_GT(moved, 400);   // of 480 corners: the refinement did move them (the paths agree on real work)
}

TEST(Params, TableDrivesDefaultsRangesAndYaml) {
  const DetectorParams p;
  for (const auto& info : param_table()) {
    EXPECT_EQ(get_param(p, info), info.default_value) << info.name;
    EXPECT_LE(info.min_value, info.default_value) << info.name;
    EXPECT_GE(info.max_value, info.default_value) << info.name;
    EXPECT_STRNE(info.help, "") << info.name;
    EXPECT_TRUE(param_stage_known(info.stage)) << info.name << " names stage " << info.stage;
  }
  DetectorParams q;
  std::string err;
  EXPECT_FALSE(set_param(q, *find_param("threshold_window_px"), 2.5, &err));
  EXPECT_NE(err.find("threshold_window_px"), std::string::npos);
  EXPECT_FALSE(set_param(q, *find_param("warp_cell_px"), 1000, &err));
  EXPECT_NE(err.find("1..32"), std::string::npos);

  test::TempDir dir;
  q.threshold_offset = 11;
  q.warp_cell_px = 6;
  ASSERT_TRUE(save_params_yaml(dir.str("p.yml"), q, &err)) << err;
  DetectorParams back;
  std::vector<std::string> errors;
  ASSERT_TRUE(load_params_yaml(dir.str("p.yml"), back, &errors));
  EXPECT_EQ(back.threshold_offset, 11);
  EXPECT_EQ(back.warp_cell_px, 6);

  test::write_file(dir.str("plain.yml"), "threshold_offset: 9\n");  // no %YAML header, as people write it
  ASSERT_TRUE(load_params_yaml(dir.str("plain.yml"), back, &errors));
  EXPECT_EQ(back.threshold_offset, 9);
}

TEST(Params, BadPresetsChangeNothingAndNameFileAndKey) {
  test::TempDir dir;
  DetectorParams p;
  std::vector<std::string> errors;
  test::write_file(dir.str("bad.yml"), "threshold_offset: 3\nno_such_param: 1\nwarp_cell_px: 99\n");
  EXPECT_FALSE(load_params_yaml(dir.str("bad.yml"), p, &errors));
  EXPECT_EQ(p.threshold_offset, DetectorParams{}.threshold_offset);  // nothing applied
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_NE(errors[0].find("bad.yml"), std::string::npos);
  EXPECT_NE(errors[0].find("no_such_param"), std::string::npos);
  EXPECT_NE(errors[1].find("warp_cell_px"), std::string::npos);
  errors.clear();
  test::write_file(dir.str("broken.yml"), "threshold_offset: [1, 2\n  : :\n");
  EXPECT_FALSE(load_params_yaml(dir.str("broken.yml"), p, &errors));
  ASSERT_FALSE(errors.empty());
  EXPECT_NE(errors[0].find("broken.yml"), std::string::npos);
}

// Presets from before the resize became acquisition's still load; their resize keys are named in a note, never
// silently applied or dropped.
TEST(Params, OldPresetsWithResizeKeysLoadWithANote) {
  test::TempDir dir;
  test::write_file(dir.str("old.yml"), "resize_width: 0\nresize_height: 0\nthreshold_offset: 9\n");
  DetectorParams p;
  std::vector<std::string> errors, notes;
  ASSERT_TRUE(load_params_yaml(dir.str("old.yml"), p, &errors, &notes));
  EXPECT_TRUE(errors.empty());
  EXPECT_EQ(p.threshold_offset, 9);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[0].find("old.yml: resize_width"), std::string::npos) << notes[0];
  EXPECT_NE(notes[0].find("--resize"), std::string::npos) << notes[0];

  test::write_file(dir.str("small.yml"), "resize_width: 320\nwarp_cell_px: 6\n");
  notes.clear();
  ASSERT_TRUE(load_params_yaml(dir.str("small.yml"), p, &errors, &notes));
  EXPECT_EQ(p.warp_cell_px, 6);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("resize_width = 320 is not applied"), std::string::npos) << notes[0];

  // The shipped presets load without a note: they no longer name a resize.
  for (const char* name : {"default.yml", "small-markers.yml", "fast.yml"}) {
    notes.clear();
    errors.clear();
    EXPECT_TRUE(load_params_yaml(std::string(ARWB_SOURCE_DIR) + "/assets/presets/" + name, p, &errors, &notes))
        << name;
    EXPECT_TRUE(notes.empty()) << name;
  }
  // default.yml undoes any tuning: every parameter of the table, at its default.
  DetectorParams tuned;
  for (const ParamInfo& info : param_table()) {
    const double other = info.default_value == info.max_value ? info.min_value : info.max_value;
    ASSERT_TRUE(set_param(tuned, info, other)) << info.name;
  }
  ASSERT_TRUE(load_params_yaml(std::string(ARWB_SOURCE_DIR) + "/assets/presets/default.yml", tuned, &errors));
  for (const ParamInfo& info : param_table())
    EXPECT_EQ(get_param(tuned, info), info.default_value) << info.name << " is not in default.yml";
  EXPECT_EQ(tuned, DetectorParams{});
  // Still an unknown key elsewhere is an error, and nothing changes.
  test::write_file(dir.str("typo.yml"), "resize_width: 0\nthreshold_ofset: 3\n");
  const DetectorParams before = p;
  EXPECT_FALSE(load_params_yaml(dir.str("typo.yml"), p, &errors, &notes));
  EXPECT_EQ(p, before);
}

// decimation: the search image is the block mean, a factor that would leave fewer than 64 pixels a side is lowered,
// and contours found on it come back in the grey image's pixels, their length in those pixels.
TEST(Stages, DecimationShrinksTheSearchAndContoursComeBackInGreyPixels) {
  cv::Mat grey(200, 300, CV_8UC1, cv::Scalar(200));
  grey(cv::Rect(0, 0, 2, 2)).setTo(0);
  cv::rectangle(grey, cv::Rect(100, 60, 80, 80), cv::Scalar(20), -1);
  const cv::Mat small = stages::decimate(grey, 2);
  ASSERT_EQ(small.size(), cv::Size(150, 100));
  EXPECT_EQ(small.at<uint8_t>(0, 0), 0);        // the 2x2 block's mean
  EXPECT_EQ(small.at<uint8_t>(0, 1), 200);
  EXPECT_EQ(stages::decimate(grey, 1).data, grey.data);
  // Every factor: each pixel the rounded mean of its block; the leftover columns and rows are dropped.
  cv::Mat noise(200, 301, CV_8UC1);
  cv::randu(noise, 0, 256);
  for (int f : {2, 3, 4, 5, 6}) {
    const cv::Mat ours = stages::decimate(noise, f);
    cv::Mat theirs;
    // INTER_AREA on the whole blocks only: past them it would spread the leftover columns over every block.
    cv::resize(noise(cv::Rect(0, 0, 301 / f * f, 200 / f * f)), theirs, cv::Size(301 / f, 200 / f), 0, 0,
               cv::INTER_AREA);
    ASSERT_EQ(ours.size(), theirs.size()) << f;
    cv::Mat diff;
    cv::absdiff(ours, theirs, diff);
    double most = 0;
    cv::minMaxLoc(diff, nullptr, &most);
    EXPECT_LE(most, 1.0) << "factor " << f;  // a tie may round the other way
    EXPECT_EQ(ours.at<uint8_t>(1, 2), uint8_t((cv::sum(noise(cv::Rect(2 * f, f, f, f)))[0] + f * f / 2) / (f * f)));
  }
  DetectorParams p;
  p.decimation_factor = 4;
  EXPECT_EQ(stages::decimation_used(grey.size(), p), 3);  // 200 / 4 = 50 < 64 pixels
  p.decimation_factor = 2;
  EXPECT_EQ(stages::decimation_used(grey.size(), p), 2);
  EXPECT_EQ(stages::decimation_used({100, 100}, p), 1);
  p.decimation_factor = 0;   // by the frame: 2 from a shorter side of 720 px
  EXPECT_EQ(stages::decimation_used({640, 480}, p), 1);
  EXPECT_EQ(stages::decimation_used({1280, 719}, p), 1);
  EXPECT_EQ(stages::decimation_used({1280, 720}, p), 2);
  EXPECT_EQ(stages::decimation_used({720, 1280}, p), 2);
  EXPECT_EQ(stages::decimation_used({3840, 2160}, p), 2);

  cv::Mat bin(small.size(), CV_8UC1, cv::Scalar(0));
  cv::rectangle(bin, cv::Rect(50, 30, 40, 40), cv::Scalar(255), -1);
  std::vector<stages::SmallRegion> specks;
  bin(cv::Rect(5, 5, 2, 2)).setTo(255);
  const auto contours = stages::find_contours(bin, 48, nullptr, &specks, 2);
  ASSERT_EQ(contours.size(), 1u);
  const cv::Rect box = cv::boundingRect(contours[0]);
  EXPECT_EQ(box, cv::Rect(100, 60, 79, 79));  // the square's outer pixels, each its block's top-left
  EXPECT_DOUBLE_EQ(stages::contour_length(contours[0], 2), 2.0 * double(contours[0].size()));
  ASSERT_EQ(specks.size(), 1u);
  EXPECT_EQ(specks[0].bbox, cv::Rect(10, 10, 4, 4));
  // quad_fit on the mapped contour: the corners of the square, to a pixel.
  Quad q;
  ASSERT_FALSE(stages::fit_quad(contours[0], grey.size(), p, &q, 2));
  const cv::Point2f expected[4] = {{100, 60}, {179, 60}, {179, 139}, {100, 139}};
  for (size_t k = 0; k < 4; ++k) EXPECT_LE(cv::norm(q[k] - expected[k]), 1.0) << k;
}

// Every possible block sum of the factors with a vectorised path (3: 0 to 2295, 4: 0 to 4080) comes out as the
// block's mean rounded to the nearest, as the plain division gives it.
TEST(Stages, DecimationRoundsEveryBlockSumToTheNearest) {
  for (const int f : {3, 4, 5}) {
    const int area = f * f, sums = 255 * area + 1;
    cv::Mat grey(f, f * sums, CV_8UC1);
    for (int s = 0; s < sums; ++s)   // the sum s spread over the block's pixels, none over 255
      for (int k = 0; k < area; ++k)
        grey.at<uint8_t>(k / f, s * f + k % f) = uint8_t(s / area + (k < s % area ? 1 : 0));
    const cv::Mat out = stages::decimate(grey, f);
    ASSERT_EQ(out.size(), cv::Size(sums, 1));
    for (int s = 0; s < sums; ++s)
      ASSERT_EQ(out.at<uint8_t>(0, s), (s + area / 2) / area) << "factor " << f << ", block sum " << s;
  }
}

// quad_fit places each corner where the lines of its two sides meet, not on the contour point nearest it: a corner
// rounded by blur puts the contour's vertex inside the true corner.
TEST(Stages, QuadFitCornersAreWhereTheSidesMeetWhenBlurRoundsThem) {
  cv::Mat img(220, 220, CV_8UC1, cv::Scalar(230));
  cv::rectangle(img, cv::Rect(60, 50, 100, 110), cv::Scalar(20), cv::FILLED);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 4.0);
  DetectorParams p;
  p.threshold_window_px = 61;  // the whole edge, not a ring: the region is the square, its corners rounded
  p.threshold_offset = 20;
  const cv::Mat bin = stages::adaptive_threshold(img, p);
  const auto contours = stages::find_contours(bin, p.min_perimeter_px);
  ASSERT_EQ(contours.size(), 1u);
  Quad q;
  ASSERT_FALSE(stages::fit_quad(contours[0], img.size(), p, &q));
  // The region's edge, where the blurred square is darker than the window's mean by the offset, runs about
  // 1.5 px inside the printed edge; the corners should be its sides' crossings, not a point on the rounding.
  const cv::Point2f truth[4] = {{61.5f, 51.5f}, {157.5f, 51.5f}, {157.5f, 157.5f}, {61.5f, 157.5f}};
  for (size_t k = 0; k < 4; ++k) EXPECT_LT(cv::norm(q[k] - truth[k]), 1.2) << k << ": " << q[k];
}
