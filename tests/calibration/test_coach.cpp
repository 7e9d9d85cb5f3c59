// The Calibrate workspace's advice names what the views lack (calibration/coach.hpp), not one sentence for all.
#include "calibration/coach.hpp"

#include <gtest/gtest.h>

namespace arwb {
namespace {

// An 8x6 grid with corners everywhere but in the rows [r0, r1) and columns [c0, c1).
cv::Mat1i grid_without(int r0, int r1, int c0, int c1) {
  cv::Mat1i g(6, 8, 5);
  g(cv::Range(r0, r1), cv::Range(c0, c1)).setTo(0);
  return g;
}

TEST(Coach, NamesTheShortBarAndTheSideItLacks) {
  const CoverageBars full{1, 1, 1, 1};
  EXPECT_EQ(coverage_advice(full, cv::Mat1i(6, 8, 0), 0),
            "Show the whole board to the camera, then move it to a new place for each view.");
  CoverageBars b = full;
  b.y = 0.3;
  EXPECT_EQ(coverage_advice(b, grid_without(0, 2, 0, 8), 5),
            "Y is at 30 %: cover the top of the image, the board near it.");
  EXPECT_EQ(coverage_advice(b, grid_without(4, 6, 0, 8), 5),
            "Y is at 30 %: cover the bottom of the image, the board near it.");
  b = full;
  b.x = 0.2;
  EXPECT_EQ(coverage_advice(b, grid_without(0, 6, 6, 8), 5),
            "X is at 20 %: cover the right edge of the image, the board near it.");
  b.size = 0.1;   // the shortest bar is the one named
  EXPECT_EQ(coverage_advice(b, grid_without(0, 6, 6, 8), 5),
            "Size is at 10 %: bring the board nearer, so that it fills most of the image, and take it farther away.");
  b = full;
  b.skew = 0.45;
  EXPECT_EQ(coverage_advice(b, grid_without(0, 0, 0, 0), 5),
            "Skew is at 45 %: tilt the board more, to the left and right and up and down.");
}

TEST(Coach, WithNoShortBarNamesTheEmptyPartOfTheImage) {
  const CoverageBars full{0.9, 0.9, 0.9, 0.9};
  EXPECT_EQ(coverage_advice(full, grid_without(0, 2, 6, 8), 9),
            "No corners in the top-right corner yet: cover it, where the lens bends the most.");
  EXPECT_EQ(coverage_advice(full, grid_without(0, 6, 0, 2), 9),
            "No corners in the left edge yet: cover it, where the lens bends the most.");
  EXPECT_EQ(coverage_advice(full, grid_without(0, 0, 0, 0), 9),
            "The coverage is complete: more views only replace the worst ones.");
  EXPECT_EQ(coverage_advice(full, cv::Mat1i(), 9), "The coverage is complete: more views only replace the worst ones.");
}

}  // namespace
}  // namespace arwb
