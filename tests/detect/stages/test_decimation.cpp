// decimation: the search image's block means, and contours mapped back to grey pixels.
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
