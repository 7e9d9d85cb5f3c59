// fine_search: the regions it plans, and the holes of larger shapes.
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

TEST(Stages, FineSearchPlansARegionAroundEachSmallSquarishShape) {
  DetectorParams p;   // fine_max_side_px 80, threshold_window_px 17, min_perimeter_px 32
  const cv::Size frame(640, 480);
  // A 30 px shape: half a side (15 px) of margin each way.
  std::vector<cv::Rect> r = stages::plan_fine_search({cv::Rect(100, 100, 30, 30)}, frame, p);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0], cv::Rect(85, 85, 60, 60));
  // A 12 px shape: at least half the threshold's window and 2 px (10 px).
  r = stages::plan_fine_search({cv::Rect(200, 200, 12, 12)}, frame, p);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0], cv::Rect(190, 190, 32, 32));
  // Too long, too thin, too small to hold 3/4 of min_perimeter_px: not searched again.
  EXPECT_TRUE(stages::plan_fine_search({cv::Rect(0, 0, 81, 76), cv::Rect(300, 300, 40, 10), cv::Rect(50, 50, 8, 8)},
                                       frame, p).empty());
  // Overlapping regions are merged, and clipped to the frame; less than 32 px a side left in a corner is dropped.
  r = stages::plan_fine_search({cv::Rect(100, 100, 30, 30), cv::Rect(140, 100, 30, 30), cv::Rect(610, 440, 30, 30),
                                cv::Rect(626, 466, 12, 12)},
                               frame, p);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0], cv::Rect(85, 85, 100, 60));
  EXPECT_EQ(r[1], cv::Rect(595, 425, 45, 55));
  p.fine_max_side_px = 0;
  EXPECT_TRUE(stages::plan_fine_search({cv::Rect(100, 100, 30, 30)}, frame, p).empty()) << "off";
}

// A binary image of a half-size search (factor 2): a dark ring whose quiet zone closed into a larger dark shape
// still holds a light quad, and quad_holes gives its box in the grey image's pixels; a round hole, a quad hole
// larger than fine_max_side_px and the light background are not given, nor the holes inside a marker read.

TEST(Stages, QuadHolesFindTheInsideOfARingMergedIntoALargerShape) {
  // Each level of vector code the processor has (the light regions' masks: AVX-512, AVX2, plain).
  for (const Simd level : simd_levels_here()) {
    SimdCap cap(level);
    SCOPED_TRACE(simd_name(level));
    DetectorParams p;   // fine_max_side_px 80, min_perimeter_px 32
    cv::Mat bin(200, 300, CV_8UC1, cv::Scalar(0));
    cv::rectangle(bin, cv::Rect(20, 20, 60, 150), cv::Scalar(255), -1);    // the larger shape
    cv::rectangle(bin, cv::Rect(80, 60, 16, 16), cv::Scalar(255), -1);     // the ring, touching it
    cv::rectangle(bin, cv::Rect(83, 63, 10, 10), cv::Scalar(0), -1);       // its inside
    bin(cv::Rect(86, 66, 2, 3)).setTo(255);                                  // a cell inside, apart from the ring
    cv::circle(bin, cv::Point(160, 100), 16, cv::Scalar(255), -1);         // a round hole in a disc
    cv::circle(bin, cv::Point(160, 100), 9, cv::Scalar(0), -1);
    cv::rectangle(bin, cv::Rect(200, 40, 60, 60), cv::Scalar(255), -1);    // a quad hole 2 x 50 px a side
    cv::rectangle(bin, cv::Rect(205, 45, 50, 50), cv::Scalar(0), -1);
    // The dark shapes' boxes in the grey image's pixels (the binary lies at (10, 0)).
    auto boxes = [](const cv::Mat& b, int min_perimeter) {
      std::vector<cv::Rect> out;
      for (const auto& c : stages::find_contours(b, min_perimeter, nullptr, nullptr, 2))
        out.push_back(cv::boundingRect(c) + cv::Point(10, 0));
      return out;
    };
    const std::vector<cv::Rect> dark = boxes(bin, int(p.min_perimeter_px));
    const std::vector<cv::Rect> holes = stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2);
    ASSERT_EQ(holes.size(), 1u);
    // The inside's pixels 83..92 are the blocks' centres 2 x 83 + 10 (the origin) .. 2 x 92 + 10 in the grey image.
    EXPECT_EQ(holes[0], cv::Rect(176, 126, 19, 19));
    // Inside a marker read, a hole is the marker's: a quad around the ring (grey image's pixels), or one around its
    // inside only (its centre in the marker), leaves none; a marker beside it leaves it.
    const Quad ring{cv::Point2f(170, 120), {201, 120}, {201, 151}, {170, 151}};
    EXPECT_TRUE(stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2, {ring}).empty());
    const Quad centre{cv::Point2f(182, 132), {189, 132}, {189, 139}, {182, 139}};
    EXPECT_TRUE(stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2, {centre}).empty());
    const Quad beside{cv::Point2f(420, 90), {520, 90}, {520, 190}, {420, 190}};
    EXPECT_EQ(stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2, {beside}).size(), 1u);
    // Only shapes longer than fine_max_side_px are looked into: a ring of 60 px (30 decimated) on its own is searched
    // again whole if it does not read.
    cv::Mat alone(200, 300, CV_8UC1, cv::Scalar(0));
    cv::rectangle(alone, cv::Rect(80, 60, 30, 30), cv::Scalar(255), -1);
    cv::rectangle(alone, cv::Rect(85, 65, 20, 20), cv::Scalar(0), -1);
    EXPECT_TRUE(stages::quad_holes(alone, boxes(alone, int(p.min_perimeter_px)), cv::Point(10, 0), cv::Size(620, 400),
                                   p, 2)
                    .empty());
    p.fine_max_side_px = 0;
    EXPECT_TRUE(stages::quad_holes(bin, dark, cv::Point(10, 0), cv::Size(620, 400), p, 2).empty()) << "off";
  }
}
