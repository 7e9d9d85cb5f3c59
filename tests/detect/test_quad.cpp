// A quad's perimeter and centre, the one home of both.
#include "detect/quad.hpp"

#include <gtest/gtest.h>

namespace arwb {
namespace {

TEST(Quad, PerimeterIncludesTheClosingSide) {
  const Quad square{cv::Point2f(0, 0), cv::Point2f(10, 0), cv::Point2f(10, 10), cv::Point2f(0, 10)};
  EXPECT_DOUBLE_EQ(quad_perimeter(square), 40.0);
  const Quad kite{cv::Point2f(0, 0), cv::Point2f(3, 4), cv::Point2f(0, 8), cv::Point2f(-3, 4)};
  EXPECT_DOUBLE_EQ(quad_perimeter(kite), 20.0);
}

TEST(Quad, CentreIsTheMeanOfTheCorners) {
  const Quad q{cv::Point2f(0, 0), cv::Point2f(8, 0), cv::Point2f(12, 6), cv::Point2f(0, 2)};
  EXPECT_FLOAT_EQ(quad_centre(q).x, 5.0f);
  EXPECT_FLOAT_EQ(quad_centre(q).y, 2.0f);
}

}  // namespace
}  // namespace arwb
