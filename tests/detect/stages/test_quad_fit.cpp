// quad_fit: squares kept, other shapes rejected, corners where the sides meet.
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
