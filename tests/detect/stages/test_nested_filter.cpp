// nested_filter: two traces of one border become the outer one.
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
