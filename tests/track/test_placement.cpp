// Placement geometry against corners computed by hand, and against a pinhole camera for tilted markers: what a
// scene author's on_marker, beside, billboard and screen mean in pixels.
#include "track/placement.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace arwb {
namespace {

Quad square(float x, float y, float s) { return {{{x, y}, {x + s, y}, {x + s, y + s}, {x, y + s}}}; }

void expect_corners(const MediaQuad& q, std::array<cv::Point2d, 4> want, double tol = 1e-6) {
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(q.corners[i].x, want[i].x, tol) << "corner " << i;
    EXPECT_NEAR(q.corners[i].y, want[i].y, tol) << "corner " << i;
  }
}

cv::Point2d map(const cv::Matx33d& H, cv::Point2d p) {
  const cv::Vec3d r = H * cv::Vec3d(p.x, p.y, 1);
  return {r[0] / r[2], r[1] / r[2]};
}

TEST(Placement, OnMarkerStretchCoversTheMarkerExactly) {
  PlaceSpec s;
  s.fit = Fit::stretch;
  auto q = place(s, square(100, 100, 100), 2.0, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{100, 100}, {200, 100}, {200, 200}, {100, 200}}});
}

TEST(Placement, OnMarkerFitKeepsTheAspectCentred) {
  auto q = place(PlaceSpec{}, square(100, 100, 100), 2.0, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{100, 125}, {200, 125}, {200, 175}, {100, 175}}});
  // A tall media: full height, half width.
  q = place(PlaceSpec{}, square(100, 100, 100), 0.5, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{125, 100}, {175, 100}, {175, 200}, {125, 200}}});
}

TEST(Placement, OnMarkerFillCoversAndCropsTheMedia) {
  PlaceSpec s;
  s.fit = Fit::fill;
  auto q = place(s, square(100, 100, 100), 2.0, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{100, 100}, {200, 100}, {200, 200}, {100, 200}}});
  EXPECT_NEAR(q->uv_min.x, 0.25, 1e-12);
  EXPECT_NEAR(q->uv_max.x, 0.75, 1e-12);
  // The homography covers the whole media: its centre column lands on the marker's centre.
  const cv::Point2d c = map(q->H, {0.5, 0.5});
  EXPECT_NEAR(c.x, 150, 1e-9);
  EXPECT_NEAR(c.y, 150, 1e-9);
}

TEST(Placement, OnMarkerScaleAndRotateTurnClockwiseAboutTheCentre) {
  PlaceSpec s;
  s.fit = Fit::stretch;
  s.scale = 0.5;
  s.rotate_deg = 90;
  auto q = place(s, square(100, 100, 100), 1.0, {640, 480});
  ASSERT_TRUE(q);
  // A half-size square turned a quarter clockwise: the media's top-left goes to the top-right.
  expect_corners(*q, {{{175, 125}, {175, 175}, {125, 175}, {125, 125}}}, 1e-9);
}

TEST(Placement, BesideRightUsesMarkerSidesForGapAndSize) {
  PlaceSpec s = PlaceSpec::defaults(PlaceKind::beside);
  s.side = Side::right;
  s.gap = 0.25;
  s.size = 1.5;   // width for left and right; height from the aspect 1.5 -> 1 side
  auto q = place(s, square(100, 100, 100), 1.5, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{225, 100}, {375, 100}, {375, 200}, {225, 200}}});
}

TEST(Placement, BesideTopAndBottomUseSizeAsHeight) {
  PlaceSpec s = PlaceSpec::defaults(PlaceKind::beside);
  s.side = Side::top;
  s.gap = 0.5;
  s.size = 0.5;
  auto q = place(s, square(100, 100, 100), 2.0, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{100, 0}, {200, 0}, {200, 50}, {100, 50}}});
  s.side = Side::bottom;
  q = place(s, square(100, 100, 100), 2.0, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{100, 250}, {200, 250}, {200, 300}, {100, 300}}});
  s.side = Side::left;
  q = place(s, square(100, 100, 100), 2.0, {640, 480});   // width 0.5, height 0.25
  ASSERT_TRUE(q);
  expect_corners(*q, {{{0, 137.5}, {50, 137.5}, {50, 162.5}, {0, 162.5}}});
}

TEST(Placement, BesideFollowsTheMarkersOwnOrientation) {
  // The marker turned a quarter clockwise in the image: corner 0 top-right, its right (corner 0 -> 1) points
  // down the image. Marker point (x, y) is at (200 - 100 y, 100 + 100 x).
  const Quad turned{{{200, 100}, {200, 200}, {100, 200}, {100, 100}}};
  PlaceSpec s = PlaceSpec::defaults(PlaceKind::beside);
  s.side = Side::right;
  s.gap = 0.25;
  s.size = 1.0;
  auto q = place(s, turned, 1.0, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{200, 225}, {200, 325}, {100, 325}, {100, 225}}}, 1e-6);
  s.side = Side::top;   // the marker's top is the image's right
  q = place(s, turned, 1.0, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{325, 100}, {325, 200}, {225, 200}, {225, 100}}}, 1e-6);
}

// A pinhole camera looking at a marker tilted about its x axis: corners projected from 3D, independently of
// any homography code.
struct Camera {
  double f = 600, cx = 320, cy = 240;
  double tilt_deg = 50, dist = 0.6, side = 0.1;
  cv::Point2d project(double mx, double my) const {   // marker-frame point (units of side) -> image
    const double t = tilt_deg * CV_PI / 180;
    // Marker plane centred on the optical axis, rotated about the camera's x axis.
    const double X = (mx - 0.5) * side, Yp = (my - 0.5) * side;
    const double Y = Yp * std::cos(t), Z = dist + Yp * std::sin(t);
    return {cx + f * X / Z, cy + f * Y / Z};
  }
  Quad marker() const {
    Quad q;
    const double pts[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int i = 0; i < 4; ++i) {
      const cv::Point2d p = project(pts[i][0], pts[i][1]);
      q[i] = cv::Point2f(float(p.x), float(p.y));
    }
    return q;
  }
};

TEST(Placement, BesideOnATiltedMarkerMatchesTheProjectedPlane) {
  const Camera cam;
  PlaceSpec s = PlaceSpec::defaults(PlaceKind::beside);
  for (Side side : {Side::right, Side::left, Side::top, Side::bottom}) {
    s.side = side;
    s.gap = 0.25;
    s.size = 1.0;
    auto q = place(s, cam.marker(), 1.0, {640, 480});
    ASSERT_TRUE(q) << side_name(side);
    double x0 = 0, y0 = 0;
    if (side == Side::right) x0 = 1.25, y0 = 0;
    if (side == Side::left) x0 = -1.25, y0 = 0;
    if (side == Side::top) x0 = 0, y0 = -1.25;
    if (side == Side::bottom) x0 = 0, y0 = 1.25;
    const double want[4][2] = {{x0, y0}, {x0 + 1, y0}, {x0 + 1, y0 + 1}, {x0, y0 + 1}};
    for (int i = 0; i < 4; ++i) {
      const cv::Point2d p = cam.project(want[i][0], want[i][1]);
      // Corners come from float detections; a few thousandths of a pixel of rounding.
      EXPECT_NEAR(q->corners[i].x, p.x, 0.01) << side_name(side) << " corner " << i;
      EXPECT_NEAR(q->corners[i].y, p.y, 0.01) << side_name(side) << " corner " << i;
    }
    // Perspective, not an affine guess: the media's centre is where the plane's centre projects, which is not
    // the mean of its corners.
    const cv::Point2d centre = map(q->H, {0.5, 0.5});
    const cv::Point2d truth = cam.project(x0 + 0.5, y0 + 0.5);
    EXPECT_NEAR(centre.x, truth.x, 0.01);
    EXPECT_NEAR(centre.y, truth.y, 0.01);
    const cv::Point2d mean = (q->corners[0] + q->corners[1] + q->corners[2] + q->corners[3]) * 0.25;
    if (side == Side::top || side == Side::bottom) {
      EXPECT_GT(std::abs(mean.y - truth.y), 0.5);
    }
  }
}

TEST(Placement, BesideReachingTheHorizonIsRefused) {
  Camera cam;
  cam.tilt_deg = 80;   // nearly edge-on: the plane's horizon is a few sides above the marker
  PlaceSpec s = PlaceSpec::defaults(PlaceKind::beside);
  s.side = Side::top;
  s.size = 20;
  std::string why;
  EXPECT_FALSE(place(s, cam.marker(), 1.0, {640, 480}, &why));
  EXPECT_NE(why.find("horizon"), std::string::npos) << why;
  s.side = Side::bottom;   // towards the camera: fine
  s.size = 1;
  EXPECT_TRUE(place(s, cam.marker(), 1.0, {640, 480}, &why)) << why;
}

TEST(Placement, BillboardStandsUprightAboveTheMarker) {
  // A marker turned 30 degrees: the billboard stays axis-aligned, above its bounding box.
  Quad q;
  const double r = 30 * CV_PI / 180;
  for (int i = 0; i < 4; ++i) {
    const double ang = r + i * CV_PI / 2 - 3 * CV_PI / 4;
    q[i] = cv::Point2f(float(300 + 50 * std::sqrt(2.0) * std::cos(ang)), float(240 + 50 * std::sqrt(2.0) * std::sin(ang)));
  }
  PlaceSpec s = PlaceSpec::defaults(PlaceKind::billboard);   // top, size 0.6, gap 0.25
  auto m = place(s, q, 2.0, {640, 480});
  ASSERT_TRUE(m);
  double top = 1e9;
  for (auto p : q) top = std::min(top, double(p.y));
  // side 100 px: height 60, width 120, gap 25, centred on x = 300.
  expect_corners(*m, {{{240, top - 85}, {360, top - 85}, {360, top - 25}, {240, top - 25}}}, 1e-3);
}

TEST(Placement, ScreenPinsToAFrameCorner) {
  PlaceSpec s = PlaceSpec::defaults(PlaceKind::screen);   // size 0.25 of the width, margin 16
  auto q = place(s, square(10, 10, 50), 2.0, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{464, 16}, {624, 16}, {624, 96}, {464, 96}}});
  s.corner = ScreenCorner::bottom_left;
  q = place(s, square(10, 10, 50), 2.0, {640, 480});
  ASSERT_TRUE(q);
  expect_corners(*q, {{{16, 384}, {176, 384}, {176, 464}, {16, 464}}});
}

TEST(Placement, BadValuesAreRefusedWithTheirName) {
  PlaceSpec s;
  s.size = std::nan("");
  s.kind = PlaceKind::beside;
  std::string why;
  EXPECT_FALSE(place(s, square(0, 0, 100), 1.0, {640, 480}, &why));
  EXPECT_EQ(why, "size must be a finite number > 0 (got nan)");
  s = PlaceSpec{};
  s.opacity = 2;
  EXPECT_NE(s.validate().find("opacity"), std::string::npos);
  // A collapsed marker.
  EXPECT_FALSE(place(PlaceSpec{}, square(5, 5, 1), 1.0, {640, 480}, &why));
  EXPECT_FALSE(place(PlaceSpec{}, square(5, 5, 100), 0.0, {640, 480}, &why));
}

TEST(Placement, ContainsTellsClicksInsideTheQuad) {
  auto q = place(PlaceSpec{}, square(100, 100, 100), 1.0, {640, 480});
  ASSERT_TRUE(q);
  EXPECT_TRUE(q->contains({150, 150}));
  EXPECT_FALSE(q->contains({250, 150}));
}

TEST(Placement, NamesRoundTrip) {
  Side s;
  EXPECT_TRUE(parse_side("bottom", &s));
  EXPECT_EQ(s, Side::bottom);
  EXPECT_FALSE(parse_side("diagonal", &s));
  Fit f;
  EXPECT_TRUE(parse_fit("fill", &f));
  ScreenCorner c;
  EXPECT_TRUE(parse_screen_corner("bottom_right", &c));
  PlaceSpec b = PlaceSpec::defaults(PlaceKind::beside);
  b.size = 1.5;
  EXPECT_EQ(b.describe(), "beside right gap 0.25 size 1.5");
}

}  // namespace
}  // namespace arwb
