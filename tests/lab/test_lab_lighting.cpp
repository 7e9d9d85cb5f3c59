// The light beyond its level (lighting.hpp): shadow edges and glints by the paper's three conditions, their
// geometry in pixels, and what they do to the paper's table outdoors against indoors.
#include "lab/lighting.hpp"
#include "lab/run.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace arwb::lab {
namespace {

const Quad kMarker{cv::Point2f(280, 200), cv::Point2f(360, 200), cv::Point2f(360, 280), cv::Point2f(280, 280)};

TEST(LabLighting, OnlySunlightCastsShadowsAndGlints) {
  const SceneLight l;
  EXPECT_DOUBLE_EQ(direct_share(l, 1000), l.direct_outdoor);
  EXPECT_DOUBLE_EQ(direct_share(l, 850), l.direct_indoor);
  EXPECT_DOUBLE_EQ(direct_share(l, 500), 0.0);
  // In the evening's diffuse light nothing happens, whatever the draws.
  SceneLight always = l;
  always.shadow_chance = always.glare_chance = 100;
  for (unsigned seed = 0; seed < 20; ++seed) {
    cv::Mat1f levels(480, 640, 200.f);
    std::mt19937 rng(seed);
    const LightEvents ev = apply_scene_light(levels, always, 0.5, 500, 554, kMarker, rng);
    EXPECT_FALSE(ev.shadow || ev.glare);
    EXPECT_EQ(cv::norm(levels, cv::Mat1f(480, 640, 200.f), cv::NORM_INF), 0);
  }
}

TEST(LabLighting, AShadowLeavesTheDiffuseShareBehindASoftEdgeAcrossTheMarker) {
  SceneLight l;
  l.shadow_chance = 100;
  l.glare_chance = 0;
  cv::Mat1f levels(480, 640, 200.f);
  std::mt19937 rng(3);
  ASSERT_TRUE(apply_scene_light(levels, l, 0.5, 1000, 554, kMarker, rng).shadow);
  double lo = 0, hi = 0;
  cv::minMaxLoc(levels, &lo, &hi);
  EXPECT_NEAR(lo, 200 * (1 - l.direct_outdoor), 1e-3);   // in the shadow: the diffuse light only
  EXPECT_NEAR(hi, 200, 1e-3);
  // The edge crosses the marker: both sides are inside its box.
  const cv::Mat1f box = levels(cv::Rect(280, 200, 81, 81));
  cv::minMaxLoc(box, &lo, &hi);
  EXPECT_LT(lo, 100);
  EXPECT_GT(hi, 150);
  // The penumbra is the sun's angular diameter in pixels: about 5 px at f = 554 (pixels strictly between).
  int between = 0;
  for (int y = 0; y < levels.rows; y += 60)
    for (int x = 0; x < levels.cols; ++x) between += levels(y, x) > 52 && levels(y, x) < 198;
  EXPECT_GT(between, 0);
  EXPECT_LT(between, 8 * 8 * 2);   // a few pixels per row sampled, even for a steep edge
}

TEST(LabLighting, AGlintIsTheSameSizeInPixelsAtAnyDistanceSoItCoversAFarMarker) {
  SceneLight l;
  l.shadow_chance = 0;
  l.glare_chance = 100;
  auto glint = [&](double distance) {
    cv::Mat1f levels(480, 640, 100.f);
    std::mt19937 rng(5);
    EXPECT_TRUE(apply_scene_light(levels, l, distance, 1000, 554, kMarker, rng).glare);
    return levels;
  };
  const cv::Mat1f near = glint(0.5), far = glint(2);
  EXPECT_EQ(cv::norm(near, far, cv::NORM_INF), 0);
  double hi = 0;
  cv::minMaxLoc(near, nullptr, &hi);
  EXPECT_GT(hi, 255) << "a glint outshines the paper's white";
  // Its radius (half the peak) is about f tan(4 deg) / 2 x 1.18 = 23 px.
  int bright = 0;
  for (int x = 0; x < near.cols; ++x) {
    for (int y = 0; y < near.rows; ++y) {
      if (near(y, x) > 100 + (hi - 100) / 2) {
        ++bright;
        break;
      }
    }
  }
  EXPECT_NEAR(bright, 2 * 554 * std::tan(4 * CV_PI / 180) / 2 * 1.177, 4);
}

// The chances come from geometry, not from the paper's outcome: a shadow edge of a user 0.43 m wide crosses a
// 65 mm marker at 0.5 m in 2 s d / (pi (d^2 + w^2/4)) = 7 % of frames, less far away and for smaller markers; the
// camera is inside a 4-degree glint lobe in 1 - cos 4 deg = 0.24 % of them. A pixel of 1.4 um behind f/2 collects
// 74 electrons per lux-second.
TEST(LabLighting, ChancesAndSensitivityFollowFromGeometryAndOptics) {
  const SceneLight l;
  EXPECT_NEAR(shadow_edge_chance(l, 0.065, 0.5), 2 * 0.065 * 0.5 / (CV_PI * (0.25 + 0.43 * 0.43 / 4)), 1e-12);
  EXPECT_NEAR(shadow_edge_chance(l, 0.065, 0.5), 0.070, 0.001);
  EXPECT_LT(shadow_edge_chance(l, 0.065, 2), shadow_edge_chance(l, 0.065, 1));
  EXPECT_LT(shadow_edge_chance(l, 0.026, 0.5), shadow_edge_chance(l, 0.065, 0.5));
  EXPECT_NEAR(glint_chance(l), 0.00244, 0.00001);
  EXPECT_NEAR(SensorModel{}.sensitivity, 74.4, 0.1);
  SceneLight forced;
  forced.shadow_chance = 0.5;
  forced.glare_chance = 0;
  EXPECT_EQ(shadow_edge_chance(forced, 0.065, 0.5), 0.5);
  EXPECT_EQ(glint_chance(forced), 0);
}

// The mechanism the paper blames (5.2 against 5.3): with a shadow edge on every outdoor frame, the near cell
// loses what indoors keeps; without the sun's share it keeps its rate too.
TEST(LabLighting, OutdoorShadowsCostTheNearCellWhatIndoorsKeeps) {
  LabPlan plan;
  plan.sizes_mm = {65};
  plan.distances_m = {0.5};
  plan.lux = {1000, 850};
  plan.frames_per_cell = 30;
  LabOptions o;
  o.detectors = {"arwb"};
  o.light.shadow_chance = 1;
  o.light.direct_indoor = 0;
  const Result<LabResults> r = run_lab(plan, o);
  ASSERT_TRUE(r) << r.error();
  const double outdoors = r->cells[0].detectors[0].p_rec(), indoors = r->cells[1].detectors[0].p_rec();
  EXPECT_GT(indoors, outdoors + 15);
  o.light.direct_outdoor = 0;
  plan.lux = {1000};
  const Result<LabResults> flat = run_lab(plan, o);
  ASSERT_TRUE(flat);
  EXPECT_GT(flat->cells[0].detectors[0].p_rec(), outdoors + 15) << "65 mm at 0.5 m, 1000 lx";
}

}  // namespace
}  // namespace arwb::lab
