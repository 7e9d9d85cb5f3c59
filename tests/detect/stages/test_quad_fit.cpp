// quad_fit: squares kept, other shapes rejected, corners where the sides meet.
#include "detect/detector.hpp"
#include "detect/params.hpp"
#include "detect/pipeline.hpp"
#include "detect/kernels/simd.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <bit>
#include <cmath>

using namespace arwb;

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

// A square of 60 px with a line 2 px thick leaving one side, and the same at half size (factor 2): no quad fits
// the polygon as it is, the square's does once the line is cut off, where the square lies. A square crossed by a
// line end to end (two stubs) gives the square too; an L and a square with a notch are no quads.
TEST(Stages, QuadFitCutsAThinLinesStubFromAQuad) {
  for (const int factor : {1, 2}) {
    SCOPED_TRACE(factor);
    DetectorParams p;
    cv::Mat bin(400 / factor, 400 / factor, CV_8UC1, cv::Scalar(0));
    const int s = 60 / factor;
    cv::rectangle(bin, cv::Rect(100 / factor, 100 / factor, s, s), cv::Scalar(255), -1);
    cv::line(bin, cv::Point(100 / factor + s, 100 / factor + s / 2), cv::Point(360 / factor, 40 / factor),
             cv::Scalar(255), 2);
    const auto contours = stages::find_contours(bin, p.min_perimeter_px, nullptr, nullptr, factor);
    ASSERT_EQ(contours.size(), 1u);
    Quad q;
    p.cut_thin_lines = 0;
    EXPECT_TRUE(stages::fit_quad(contours[0], cv::Size(400, 400), p, &q, factor));
    p.cut_thin_lines = 1;
    ASSERT_FALSE(stages::fit_quad(contours[0], cv::Size(400, 400), p, &q, factor));
    // The outer pixels' centres: 100 .. 159 (at factor 2 the blocks' centres 100 .. 158).
    const float far = factor == 1 ? 159.f : 158.f;
    const Quad want{cv::Point2f(100, 100), {far, 100}, {far, far}, {100, far}};
    for (const cv::Point2f& w : want) {
      double nearest = 1e9;
      for (const cv::Point2f& c : q) nearest = std::min(nearest, double(cv::norm(c - w)));
      EXPECT_LT(nearest, 0.75) << w;
    }
  }
  DetectorParams p;
  Quad q;
  auto fits = [&](const cv::Mat& bin) {
    const auto contours = stages::find_contours(bin, p.min_perimeter_px);
    return contours.size() == 1 && !stages::fit_quad(contours[0], bin.size(), p, &q);
  };
  cv::Mat through(300, 300, CV_8UC1, cv::Scalar(0));
  cv::rectangle(through, cv::Rect(100, 100, 40, 40), cv::Scalar(255), -1);
  cv::line(through, cv::Point(40, 60), cv::Point(260, 200), cv::Scalar(255), 2);
  ASSERT_TRUE(fits(through));
  for (const cv::Point2f& w : {cv::Point2f(100, 100), {139, 100}, {139, 139}, {100, 139}}) {
    double nearest = 1e9;
    for (const cv::Point2f& c : q) nearest = std::min(nearest, double(cv::norm(c - w)));
    EXPECT_LT(nearest, 0.75) << w;
  }
  cv::Mat ell(300, 300, CV_8UC1, cv::Scalar(0));
  cv::rectangle(ell, cv::Rect(100, 100, 20, 60), cv::Scalar(255), -1);
  cv::rectangle(ell, cv::Rect(100, 140, 60, 20), cv::Scalar(255), -1);
  EXPECT_FALSE(fits(ell));
  cv::Mat notch(300, 300, CV_8UC1, cv::Scalar(0));
  cv::rectangle(notch, cv::Rect(100, 100, 40, 40), cv::Scalar(255), -1);
  cv::rectangle(notch, cv::Rect(115, 100, 10, 15), cv::Scalar(0), -1);
  cv::line(notch, cv::Point(140, 120), cv::Point(220, 90), cv::Scalar(255), 2);
  EXPECT_FALSE(fits(notch));
}

// A square that lines join to a large round shape and to each other: one outline of more corners than
// cut_thin_lines follows, split at the lines into the square's own outline, which fits the square.
TEST(Stages, SplitThinLinesFreesASquareThatLinesJoinToOtherShapes) {
  for (const int factor : {1, 2}) {
    SCOPED_TRACE(factor);
    DetectorParams p;
    const int f = factor;
    cv::Mat bin(480 / f, 640 / f, CV_8UC1, cv::Scalar(0));
    cv::rectangle(bin, cv::Rect(100 / f, 100 / f, 80 / f, 80 / f), cv::Scalar(255), -1);
    cv::circle(bin, cv::Point(450 / f, 300 / f), 90 / f, cv::Scalar(255), -1);
    cv::line(bin, cv::Point(180 / f, 140 / f), cv::Point(400 / f, 260 / f), cv::Scalar(255), 2);   // into the disc
    cv::line(bin, cv::Point(140 / f, 180 / f), cv::Point(90 / f, 420 / f), cv::Scalar(255), 2);    // to nothing
    cv::line(bin, cv::Point(60 / f, 420 / f), cv::Point(420 / f, 440 / f), cv::Scalar(255), 2);    // and on
    const auto contours = stages::find_contours(bin, p.min_perimeter_px, nullptr, nullptr, f);
    ASSERT_EQ(contours.size(), 1u);
    Quad q;
    const auto why = stages::fit_quad(contours[0], cv::Size(640, 480), p, &q, f);
    ASSERT_TRUE(why);
    EXPECT_EQ(why->param, "polygon_epsilon_rate");
    const auto parts = stages::split_thin_lines(contours[0], f, p);
    ASSERT_GE(parts.size(), 2u);   // the square, the disc, and lines' ends
    int squares = 0;
    for (const auto& part : parts) {
      if (stages::fit_quad(part, cv::Size(640, 480), p, &q, f)) continue;
      ++squares;
      // The outer pixels' centres: 100 .. 179 (at factor 2 the blocks' centres 100 .. 178).
      const float far = f == 1 ? 179.f : 178.f;
      for (const cv::Point2f& w : {cv::Point2f(100, 100), {far, 100}, {far, far}, {100, far}}) {
        double nearest = 1e9;
        for (const cv::Point2f& c : q) nearest = std::min(nearest, double(cv::norm(c - w)));
        EXPECT_LT(nearest, 1.5) << w;
      }
    }
    EXPECT_EQ(squares, 1);
    DetectorParams off = p;
    off.split_thin_lines_px = 0;
    EXPECT_TRUE(stages::split_thin_lines(contours[0], f, off).empty());
    // Lines wider than split_thin_lines_px are no lines: a 9 px one keeps the shape whole.
    cv::Mat thick = bin.clone();
    cv::line(thick, cv::Point(180 / f, 140 / f), cv::Point(400 / f, 260 / f), cv::Scalar(255), 18 / f);
    cv::line(thick, cv::Point(140 / f, 180 / f), cv::Point(90 / f, 420 / f), cv::Scalar(255), 18 / f);
    cv::line(thick, cv::Point(60 / f, 420 / f), cv::Point(420 / f, 440 / f), cv::Scalar(255), 18 / f);
    const auto thick_contours = stages::find_contours(thick, p.min_perimeter_px, nullptr, nullptr, f);
    ASSERT_EQ(thick_contours.size(), 1u);
    EXPECT_TRUE(stages::split_thin_lines(thick_contours[0], f, p).empty());
  }
  DetectorParams p;
  auto split = [&](const cv::Mat& bin) {
    const auto contours = stages::find_contours(bin, p.min_perimeter_px);
    return contours.size() == 1 ? stages::split_thin_lines(contours[0], 1, p).size() : size_t(99);
  };
  // A square alone has no line; a comb of lines is mostly lines, no marker's shape.
  cv::Mat square(300, 300, CV_8UC1, cv::Scalar(0));
  cv::rectangle(square, cv::Rect(100, 100, 80, 80), cv::Scalar(255), -1);
  EXPECT_EQ(split(square), 0u);
  cv::Mat comb(300, 300, CV_8UC1, cv::Scalar(0));
  cv::line(comb, cv::Point(20, 40), cv::Point(280, 40), cv::Scalar(255), 2);
  for (int k = 40; k <= 260; k += 40) cv::line(comb, cv::Point(k, 40), cv::Point(k + 10, 200), cv::Scalar(255), 2);
  EXPECT_EQ(split(comb), 0u);
  // A checkerboard's squares touch at their corners, where the outline is thin for a moment: pinches, no lines.
  for (const int overlap : {0, 1, 2}) {
    cv::Mat board(300, 300, CV_8UC1, cv::Scalar(0));
    for (int r = 0; r < 6; ++r)
      for (int c = r % 2; c < 6; c += 2)
        cv::rectangle(board, cv::Rect(30 + 40 * c, 30 + 40 * r, 40 + overlap, 40 + overlap), cv::Scalar(255), -1);
    EXPECT_EQ(split(board), 0u) << overlap;
  }
}
