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
  always.shadow_chance_half_metre = always.glare_chance = 100;
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
  l.shadow_chance_half_metre = 100;
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
  l.shadow_chance_half_metre = 0;
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

TEST(LabLighting, OutdoorsTheNearAndFarCellsLoseWhatIndoorsKeeps) {
  LabPlan plan;
  plan.sizes_mm = {65};
  plan.lux = {1000, 850};
  plan.frames_per_cell = 30;
  LabOptions o;
  o.detectors = {"arwb"};
  const Result<LabResults> r = run_lab(plan, o);
  ASSERT_TRUE(r) << r.error();
  auto p = [&](double d, double lux) {
    for (const CellResult& c : r->cells)
      if (c.cell.distance_m == d && c.cell.lux == lux) return c.detectors[0].p_rec();
    return -1.0;
  };
  // The paper's section 5.2 against 5.3: outdoors the near cell loses to shadows what indoors keeps, and every
  // distance loses something on average (glints at the far ones).
  EXPECT_GT(p(0.5, 850), p(0.5, 1000) + 15);
  EXPECT_GT(p(0.5, 850) + p(1, 850) + p(2, 850), p(0.5, 1000) + p(1, 1000) + p(2, 1000) + 30);
  // Without the sun's share the outdoor near cell keeps its rate too.
  o.light.direct_outdoor = 0;
  plan.distances_m = {0.5};
  plan.lux = {1000};
  const Result<LabResults> flat = run_lab(plan, o);
  ASSERT_TRUE(flat);
  EXPECT_GT(flat->cells[0].detectors[0].p_rec(), p(0.5, 1000) + 20) << "65 mm at 0.5 m, 1000 lx";
}

}  // namespace
}  // namespace arwb::lab
