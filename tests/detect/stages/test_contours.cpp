// contours: regions as OpenCV labels them, small ones dropped and counted, borders traced as Moore's.
#include "detect/detector.hpp"
#include "detect/params.hpp"
#include "detect/pipeline.hpp"
#include "detect/kernels/simd.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <bit>
#include <cmath>

using namespace arwb;

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
