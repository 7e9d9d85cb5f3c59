// The reading stages: otsu, bit_grid, border_check (and its quiet zone), identification.
#include "detect/detector.hpp"
#include "detect/params.hpp"
#include "detect/pipeline.hpp"
#include "detect/kernels/simd.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"
#include "stage_test_util.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <bit>
#include <cmath>

using namespace arwb;
using arwb::test::canvas_with_marker;

TEST(Stages, PerspectiveOtsuBitsBorderAndIdentification) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = canvas_with_marker(d, 321, 40, 50, 105);
  DetectorParams p;
  const Quad q{cv::Point2f(40, 50), {145, 50}, {145, 155}, {40, 155}};
  const cv::Mat warp = stages::remove_perspective(img, q, 7, p);
  EXPECT_EQ(warp.size(), cv::Size(56, 56));   // 15 px a cell: twice warp_cell_px (view_scale, below)
  const auto o = stages::otsu(warp);
  EXPECT_GT(o.threshold, 20);
  EXPECT_LT(o.threshold, 235);
  EXPECT_GT(o.stddev, 50);
  int total = 0;
  for (int v : o.histogram) total += v;
  EXPECT_EQ(total, 56 * 56);
  const cv::Mat bits = stages::sample_bits(warp, 7, o.threshold, p);
  EXPECT_EQ(stages::border_errors(bits), 0);
  EXPECT_EQ(cv::countNonZero(bits(cv::Rect(1, 1, 5, 5)) != d.bits(321)), 0);
  const DictMatch m = d.nearest(stages::inner_code(bits));
  EXPECT_EQ(m.id, 321);
  EXPECT_EQ(m.hamming, 0);
  EXPECT_EQ(stages::correction_budget(*dictionary_by_name("6X6_250"), p), 3);  // OpenCV's 5 bits x rate 0.6
  EXPECT_EQ(stages::correction_budget(d, p), 0);
}

// perspective_removal's view scale: a quad whose cells would put warp_cell_px samples more than warp_max_step_px
// image pixels apart is viewed at the least multiple of warp_cell_px that brings them within it, at most 4 times
// and 16 px a cell; its longest side counts.
TEST(Stages, ALargeQuadIsViewedWithDenserSamples) {
  DetectorParams p;   // warp_cell_px 4, warp_max_step_px 3: one more scale per 12 px of cell
  auto square = [](float side) { return Quad{cv::Point2f(0, 0), {side, 0}, {side, side}, {0, side}}; };
  EXPECT_EQ(stages::view_scale(square(84), 7, p), 1);   // 12 px a cell: samples 3 px apart
  EXPECT_EQ(stages::view_scale(square(85), 7, p), 2);
  EXPECT_EQ(stages::view_scale(square(252), 7, p), 3);
  EXPECT_EQ(stages::view_scale(square(253), 8, p), 3);  // APRILTAG_36h11's 8 cells
  EXPECT_EQ(stages::view_scale(square(2000), 7, p), 4);
  EXPECT_EQ(stages::view_scale(Quad{cv::Point2f(0, 0), {200, 0}, {200, 40}, {0, 40}}, 7, p), 3);
  EXPECT_EQ(stages::remove_perspective(cv::Mat(300, 300, CV_8UC1, cv::Scalar(0)), square(252), 7, p).size(),
            cv::Size(84, 84));
  p.warp_cell_px = 8;
  EXPECT_EQ(stages::view_scale(square(2000), 7, p), 2);   // 16 px a cell
  p.warp_max_step_px = 0;
  EXPECT_EQ(stages::view_scale(square(2000), 7, p), 1);
}

// A thin dark line along a large white cell's diagonal: of the four samples warp_cell_px gives the cell's centre,
// two lie on the line and the cell reads black; the denser view samples the same centre 36 times and the line is a
// minority of them.
TEST(Stages, AThinLineAcrossALargeCellIsAMinorityOfItsSamples) {
  const Dictionary d = make_aruco_original();
  const int id = 321;
  cv::Mat img = canvas_with_marker(d, id, 20, 20, 210, {250, 250});   // 30 px a cell
  const cv::Mat inner = d.bits(id);
  cv::Point white(-1, -1);
  for (int r = 0; r < 5 && white.x < 0; ++r)
    for (int c = 0; c < 5 && white.x < 0; ++c)
      if (inner.at<uint8_t>(r, c)) white = {c + 1, r + 1};
  ASSERT_GE(white.x, 0);
  const cv::Point corner(20 + 30 * white.x, 20 + 30 * white.y);
  cv::line(img, corner, corner + cv::Point(30, 30), cv::Scalar(0), 3, cv::LINE_AA);
  const Quad q{cv::Point2f(20, 20), {230, 20}, {230, 230}, {20, 230}};
  auto read = [&](const DetectorParams& p) {
    const cv::Mat warp = stages::remove_perspective(img, q, 7, p);
    return stages::sample_bits(warp, 7, stages::otsu(warp).threshold, p);
  };
  DetectorParams sparse;
  sparse.warp_max_step_px = 0;
  const cv::Mat four = read(sparse);
  EXPECT_EQ(four.at<uint8_t>(white.y, white.x), 0) << "the line does not flip the sparse read: the test shows nothing";
  const cv::Mat dense = read(DetectorParams{});
  EXPECT_EQ(stages::border_errors(dense), 0);
  EXPECT_EQ(cv::countNonZero(dense(cv::Rect(1, 1, 5, 5)) != inner), 0);
}

// The warp against OpenCV's own: cv::getPerspectiveTransform and cv::warpPerspective (bilinear, pixel centres, the
// edge replicated) on a tilted quad inside the image, one that crosses the image's edge, and a bowtie that corner
// refinement could bend a quad into. Within a grey level everywhere.

TEST(Stages, QuietZoneIsLightAroundAMarkerAndDarkWhereAShapeGoesOn) {
  const Dictionary d = make_aruco_original();
  cv::Mat img = canvas_with_marker(d, 321, 40, 50, 105);
  const Quad q{cv::Point2f(40, 50), {145, 50}, {145, 155}, {40, 155}};
  DetectorParams p;
  const auto o = stages::otsu(stages::remove_perspective(img, q, 7, p));
  EXPECT_EQ(stages::quiet_zone(img, q, 7, o).dark_share, 0.0);
  // The same under a shadow across it: border and quiet zone darken alike, the step between them stays.
  cv::Mat shaded = img.clone();
  shaded(cv::Rect(0, 100, 200, 100)) *= 0.5;
  EXPECT_EQ(stages::quiet_zone(shaded, q, 7, o).dark_share, 0.0);
  // A black bar from the left side outwards: that side's quiet zone is dark, along part of it.
  cv::rectangle(img, cv::Rect(0, 50, 40, 60), cv::Scalar(0), -1);
  const stages::QuietZone left = stages::quiet_zone(img, q, 7, o);
  EXPECT_EQ(left.side, 3);
  EXPECT_NEAR(left.dark_share, 4.0 / 7, 1e-9);  // 60 of 105 px: the four cells from the top
  // Off the image, nothing counts: a marker at the frame's edge keeps its quiet zone.
  const cv::Mat edge = canvas_with_marker(d, 321, 0, 50, 105);
  const Quad at_edge{cv::Point2f(0, 50), {105, 50}, {105, 155}, {0, 155}};
  EXPECT_EQ(stages::quiet_zone(edge, at_edge, 7, o).dark_share, 0.0);
}

// bit_grid's local thresholds: a grey-on-grey marker with a soft shadow edge across it (steeply, as Coons' patch
// follows best), where the white cells in the shadow are darker than the black cells in the light. Otsu's one threshold misreads it; the thresholds spread
// in from the border and its quiet zone read every cell.
TEST(Stages, LocalThresholdsReadAMarkerAcrossAShadowEdge) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = canvas_with_marker(d, 321, 40, 50, 105);
  cv::Mat shaded(img.size(), CV_8UC1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      // Grey on grey (60 to 160), then the shadow: 0.45 of the light left of the line x + 0.3 y = 125, over 6 px.
      const double level = 60 + 100 * img.at<uint8_t>(y, x) / 255.0;
      const double shade = 1 - 0.55 * std::clamp((125 - x - 0.3 * y) / 6.0 + 0.5, 0.0, 1.0);
      shaded.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(level * shade);
    }
  const Quad q{cv::Point2f(40, 50), {145, 50}, {145, 155}, {40, 155}};
  DetectorParams p;
  const cv::Mat warp = stages::remove_perspective(shaded, q, 7, p);
  const cv::Mat global = stages::sample_bits(warp, 7, stages::otsu(warp).threshold, p);
  const int global_wrong = stages::border_errors(global) + cv::countNonZero(global(cv::Rect(1, 1, 5, 5)) != d.bits(321));
  EXPECT_GT(global_wrong, 0) << "one threshold reads it: the test shows nothing";
  const stages::LocalRead local = stages::read_local(shaded, q, warp, 7, p);
  ASSERT_TRUE(local.ok);
  EXPECT_EQ(stages::border_errors(local.bits), 0);
  EXPECT_EQ(cv::countNonZero(local.bits(cv::Rect(1, 1, 5, 5)) != d.bits(321)), 0);
  EXPECT_GT(local.median_step, 40);    // between the shaded step (45) and the lit one (100)
  EXPECT_LT(local.median_step, 105);

  // Lit evenly, or with a shadow of under a quarter of the border's step to its quiet zone: otsu's to read.
  EXPECT_FALSE(stages::read_local(img, q, stages::remove_perspective(img, q, 7, p), 7, p).ok);
  cv::Mat faint = img.clone();
  faint(cv::Rect(0, 100, 200, 100)) *= 0.8;
  EXPECT_FALSE(stages::read_local(faint, q, stages::remove_perspective(faint, q, 7, p), 7, p).ok);
  cv::Mat half = img.clone();
  half(cv::Rect(0, 100, 200, 100)) *= 0.6;
  EXPECT_TRUE(stages::read_local(half, q, stages::remove_perspective(half, q, 7, p), 7, p).ok);

  // The same marker with no quiet zone (a dark page around it): its border is no darker than beside it.
  cv::Mat dark = shaded.clone();
  cv::Mat outside(dark.size(), CV_8UC1, cv::Scalar(255));
  outside(cv::Rect(40, 50, 106, 106)).setTo(0);
  dark.setTo(30, outside);
  const stages::LocalRead none = stages::read_local(dark, q, stages::remove_perspective(dark, q, 7, p), 7, p);
  EXPECT_TRUE(!none.ok || stages::border_errors(none.bits) > 12);
  // A quiet zone off the image: nothing to compare the border with.
  const Quad off{cv::Point2f(0, 50), {105, 50}, {105, 155}, {0, 155}};
  EXPECT_FALSE(stages::read_local(shaded, off, stages::remove_perspective(shaded, off, 7, p), 7, p).ok);
}

// bit_grid's shading planes: a grey-on-grey marker (40 and 100) under a steep gradient (light 0.1 to 1 across it),
// where the white cells at its dark side are darker than the black ones at its light side. Otsu's one threshold
// misreads it; planes through the black and the white cells' levels read every cell.
TEST(Stages, ShadingPlanesReadAMarkerUnderAGradient) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = canvas_with_marker(d, 321, 40, 50, 105);
  cv::Mat lit(img.size(), CV_8UC1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x)
      lit.at<uint8_t>(y, x) =
          cv::saturate_cast<uint8_t>((40 + 60 * img.at<uint8_t>(y, x) / 255.0) * std::max(0.05, 0.1 + 0.9 * (x - 40) / 105.0));
  const Quad q{cv::Point2f(40, 50), {145, 50}, {145, 155}, {40, 155}};
  DetectorParams p;
  const cv::Mat warp = stages::remove_perspective(lit, q, 7, p);
  const cv::Mat global = stages::sample_bits(warp, 7, stages::otsu(warp).threshold, p);
  ASSERT_GT(cv::countNonZero(global(cv::Rect(1, 1, 5, 5)) != d.bits(321)), 0) << "one threshold reads it";
  const cv::Mat planes = stages::read_shaded(warp, 7, global, p);
  ASSERT_FALSE(planes.empty());
  EXPECT_EQ(stages::border_errors(planes), 0);
  EXPECT_EQ(cv::countNonZero(planes(cv::Rect(1, 1, 5, 5)) != d.bits(321)), 0);
  // No white cell inside to lay a plane through, or the planes within otsu_min_stddev: no reading.
  const cv::Mat black(7, 7, CV_8UC1, cv::Scalar(0));
  EXPECT_TRUE(stages::read_shaded(warp, 7, black, p).empty());
  const cv::Mat flat(warp.size(), CV_8UC1, cv::Scalar(120));
  EXPECT_TRUE(stages::read_shaded(flat, 7, global, p).empty());
}

// identification's bar check (bar_min_aspect_rate): ARUCO_ORIGINAL 1023's inside is one row repeated, bands running
// down the marker, as a bar's or an outlined rectangle's inside reads. On a quad 2.5 times as tall as wide the bands
// run along its length: no marker. Turned a quarter (bands across), or another id, the same quad is read.
TEST(Stages, AQuadReadAsStripesAlongItsLengthIsABarNotAMarker) {
  const Dictionary d = make_aruco_original();
  cv::Mat grid(7, 7, CV_8U, cv::Scalar(0));
  d.bits(1023).copyTo(grid(cv::Rect(1, 1, 5, 5)));
  ASSERT_EQ(stages::inner_stripes(grid), stages::Stripes::rows);
  cv::Mat rotated;
  cv::rotate(grid, rotated, cv::ROTATE_90_CLOCKWISE);
  EXPECT_EQ(stages::inner_stripes(rotated), stages::Stripes::columns);
  d.bits(321).copyTo(grid(cv::Rect(1, 1, 5, 5)));
  EXPECT_EQ(stages::inner_stripes(grid), stages::Stripes::none);

  const Quad tall{cv::Point2f(80, 30), {120, 30}, {120, 130}, {80, 130}};
  const Quad wide{cv::Point2f(30, 80), {130, 80}, {130, 120}, {30, 120}};
  auto detect = [&](int id, const Quad& q, const DetectorParams& p, FrameTrace* t = nullptr) {
    cv::Mat img(200, 200, CV_8UC1, cv::Scalar(255));
    draw_marker(img, d, id, q);
    return Detector({d}, p).detect(img, t, TraceLevel::full);
  };
  DetectorParams p;
  FrameTrace t;
  EXPECT_TRUE(detect(1023, tall, p, &t).empty());
  EXPECT_TRUE(std::any_of(t.candidates.begin(), t.candidates.end(), [](const CandidateRecord& c) {
    return c.fate.stage == Stage::identification && c.fate.param == "bar_min_aspect_rate" &&
           std::abs(c.fate.value - 2.5) < 0.1 && c.fate.message.find("id 1023 reads as stripes") == 0;
  }));
  EXPECT_EQ(detect(1023, wide, p).size(), 1u);
  EXPECT_EQ(detect(321, tall, p).size(), 1u);
  DetectorParams off;
  off.bar_min_aspect_rate = 0;
  EXPECT_EQ(detect(1023, tall, off).size(), 1u);
  DetectorParams steeper;
  steeper.bar_min_aspect_rate = 3;
  EXPECT_EQ(detect(1023, tall, steeper).size(), 1u);
}
