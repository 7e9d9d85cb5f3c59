// adaptive_threshold: dark against the neighbourhood, by its formula on every level.
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
