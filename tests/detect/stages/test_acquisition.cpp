// acquisition: the frame resized and made grey, where the stages look.
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

TEST(Stages, GreyConversionIsCvtColorsForEveryColour) {
  cv::Mat all(4096, 4096, CV_8UC3);   // all 2^24 colours, each once
  for (int i = 0; i < 1 << 24; ++i) {
    uint8_t* p = all.data + 3 * size_t(i);
    p[0] = uint8_t(i), p[1] = uint8_t(i >> 8), p[2] = uint8_t(i >> 16);
  }
  cv::Mat expected;
  cv::cvtColor(all, expected, cv::COLOR_BGR2GRAY);
  // BGR, BGRA, a browser's RGBA (the web core's frames) and RGB, each with its own channel order.
  struct Format {
    const char* name;
    int from_bgr;   // cvtColor's code making it of `all`, or -1
    bool rgb;
  };
  for (const Format f : {Format{"BGR", -1, false}, Format{"BGRA", cv::COLOR_BGR2BGRA, false},
                         Format{"RGBA", cv::COLOR_BGR2RGBA, true}, Format{"RGB", cv::COLOR_BGR2RGB, true}}) {
    SCOPED_TRACE(f.name);
    cv::Mat frame = all;
    if (f.from_bgr >= 0) cv::cvtColor(all, frame, f.from_bgr);
    // Each path the processor has (AVX-512, AVX2, SSSE3, plain C++), each row's tail by the narrower ones.
    for (const Simd level : simd_levels_here()) {
      SimdCap cap(level);
      SCOPED_TRACE(simd_name(level));
      stages::GreyOnDemand whole(frame, f.rgb);
      whole.need_all();
      EXPECT_EQ(cv::countNonZero(whole.image() != expected), 0);
      const cv::Mat odd = frame(cv::Rect(3, 5, 1001, 77));   // a view: its rows are not contiguous
      stages::GreyOnDemand tiles(odd, f.rgb);
      tiles.need(cv::Rect(7, 1, 50, 9));
      tiles.need(cv::Rect(500, 40, 501, 37));
      const cv::Rect a(0, 0, 64, 32), b(480, 32, 521, 45);
      EXPECT_EQ(cv::countNonZero(tiles.image()(a) != expected(cv::Rect(3, 5, 1001, 77))(a)), 0);
      EXPECT_EQ(cv::countNonZero(tiles.image()(b) != expected(cv::Rect(3, 5, 1001, 77))(b)), 0);
      double sx = 0, sy = 0;
      EXPECT_EQ(cv::countNonZero(stages::acquire(odd, AcquisitionSettings{.resize = false, .rgb = f.rgb}, &sx,
                                                 &sy) != expected(cv::Rect(3, 5, 1001, 77))),
                0);
    }
  }
}

// The search image of a whole colour frame at 2 is the grey image's 2x2 block means, made as each pair of rows is
// converted, on any side and of a view whose rows are not contiguous; the grey image is then converted whole.

TEST(Stages, HalfSizeSearchImageIsTheDecimatedGreyImageMadeInOnePass) {
  cv::RNG rng(7);
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    for (const cv::Size size : {cv::Size(2, 2), cv::Size(37, 23), cv::Size(641, 361), cv::Size(1921, 1081)})
    for (const int channels : {3, 4}) {   // BGR, and a browser's RGBA
      cv::Mat frame(size.height + 4, size.width + 6, CV_8UC(channels));
      rng.fill(frame, cv::RNG::UNIFORM, 0, 256);
      const cv::Mat bgr = frame(cv::Rect(cv::Point(3, 2), size));
      cv::rectangle(frame, cv::Rect(0, 0, size.width / 2, size.height), cv::Scalar(255, 0, 0), -1);   // saturated
      cv::Mat grey;
      cv::cvtColor(bgr, grey, channels == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_RGBA2GRAY);
      stages::GreyOnDemand g(bgr, channels == 4);
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
