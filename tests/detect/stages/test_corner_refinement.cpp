// corner_refinement: the profiles' samples, the true corner, the same bits on every level.
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
