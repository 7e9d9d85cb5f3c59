// size_filter: the rejection names its parameter and value.
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

TEST(Stages, SizeFilterNamesTheParameterAndValue) {
  DetectorParams p;
  std::vector<cv::Point> small(31, cv::Point(0, 0));
  auto why = stages::size_filter(small, {640, 480}, p);
  ASSERT_TRUE(why);
  EXPECT_EQ(why->stage, Stage::size_filter);
  EXPECT_EQ(why->param, "min_perimeter_px");
  EXPECT_EQ(why->value, 31);
  EXPECT_EQ(why->message, "perimeter 31 px < min_perimeter_px 32 px");
  EXPECT_FALSE(stages::size_filter(std::vector<cv::Point>(100), {640, 480}, p));
}
