// perspective_removal: OpenCV's warp, the same bits one or eight samples at a time.
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
