// Video mode: search_regions searches around the markers of the frame before, at their scale, and the whole frame
// every full_search_interval frames (detect/video_search.hpp).
#include "detect/detector.hpp"
#include "inspect/diagnose.hpp"
#include "detect/pipeline.hpp"
#include "inspect/trace_view.hpp"
#include "detect/video_search.hpp"
#include "synth/synth.hpp"
#include "synth/synthetic_world.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>

using namespace arwb;

namespace {

Quad square(cv::Point2f c, float side) {
  const float h = side / 2;
  return Quad{cv::Point2f(c.x - h, c.y - h), {c.x + h, c.y - h}, {c.x + h, c.y + h}, {c.x - h, c.y + h}};
}

cv::Mat page(const Dictionary& d, const std::vector<std::pair<int, Quad>>& markers, cv::Size size = {640, 480}) {
  cv::Mat img(size, CV_8UC1, cv::Scalar(200));
  for (const auto& [id, q] : markers) draw_marker(img, d, id, q);
  return img;
}

// The synthetic world with `markers` markers moving, turning, coming and going.
SyntheticWorld moving_markers(cv::Size size, double focal_px, uint64_t seed, int markers) {
  SyntheticWorld world(size, focal_px, seed);
  SyntheticControls c = world.controls();
  c.markers = markers;
  world.set_controls(c);
  return world;
}

bool has_id(const std::vector<Marker>& found, int id) {
  for (const Marker& m : found)
    if (m.id == id) return true;
  return false;
}

}  // namespace

// The plan: one region per known marker, overlapping ones merged, each a whole number of decimated pixels, searched
// at the decimation that keeps the smallest known marker region_min_side_px a side.
TEST(SearchRegions, RegionsAroundKnownMarkersAtTheirScale) {
  DetectorParams p;
  const cv::Size frame(1280, 720);
  // Two 100 px markers side by side (their regions overlap) and one far away.
  const std::vector<Quad> known = {square({200, 200}, 100), square({330, 200}, 100), square({1000, 500}, 100)};
  const stages::SearchPlan plan = stages::plan_search(frame, known, p);
  EXPECT_FALSE(plan.whole);
  EXPECT_EQ(plan.factor, 3);   // 100 / 32
  ASSERT_EQ(plan.regions.size(), 2u);
  for (const cv::Rect& r : plan.regions) {
    EXPECT_EQ(r.x % plan.factor, 0);
    EXPECT_EQ(r.y % plan.factor, 0);
    EXPECT_EQ((r & cv::Rect(0, 0, frame.width, frame.height)), r);
  }
  // The merged region holds both markers and a side of margin around them.
  EXPECT_LE(plan.regions[0].x, 50);
  EXPECT_GE(plan.regions[0].br().x, 480);
  EXPECT_TRUE(plan.regions[1].contains({1000, 500}));
  EXPECT_LT(plan.regions[1].area(), 320 * 320);

  // A small marker known: the search keeps its pixels.
  const stages::SearchPlan small = stages::plan_search(frame, {square({600, 300}, 40)}, p);
  EXPECT_EQ(small.factor, 1);
  // No marker known: the whole frame at decimation_factor.
  const stages::SearchPlan none = stages::plan_search(frame, {}, p);
  EXPECT_TRUE(none.whole);
  ASSERT_EQ(none.regions.size(), 1u);
  EXPECT_EQ(none.regions[0], cv::Rect(0, 0, 1280, 720));
  // Markers all over the frame: one search over all of it, still at their scale.
  const stages::SearchPlan most =
      stages::plan_search(frame, {square({300, 250}, 300), square({900, 450}, 300)}, p);
  EXPECT_FALSE(most.whole);
  ASSERT_EQ(most.regions.size(), 1u);
  EXPECT_EQ(most.regions[0], cv::Rect(0, 0, 1280, 720));
  EXPECT_EQ(most.factor, 4);
}

// On the synthetic world's moving markers, video mode finds what a whole search finds on every frame, with corners
// as precise, while searching the whole frame only every full_search_interval frames.
TEST(VideoSearch, FindsWhatAWholeSearchFindsAndSearchesWholeEveryInterval) {
  const SyntheticWorld world = moving_markers({640, 480}, 600, 3, 3);
  const Detector det({make_aruco_original()});
  ASSERT_EQ(det.params().full_search_interval, 5);
  VideoSearch video;
  int region_frames = 0, found_whole = 0, found_video = 0;
  for (int k = 0; k < 30; ++k) {
    const SyntheticFrame f = world.render(k / 20.0);
    FrameTrace t;
    const std::vector<Marker> v = video.detect(det, f.image, &t, TraceLevel::summary);
    const std::vector<Marker> w = det.detect(f.image);
    ASSERT_NE(t.stage(Stage::search_regions), nullptr);
    if (!t.search.whole) {
      ++region_frames;
      EXPECT_GT(t.search.known, 0);
      EXPECT_FALSE(t.search.regions.empty());
      // Each region frame follows a whole one by fewer than full_search_interval frames.
      EXPECT_GE(video.frames_since_whole(), 1);
      EXPECT_LE(video.frames_since_whole(), 4);
    } else {
      EXPECT_EQ(video.frames_since_whole(), 0);
    }
    found_whole += int(w.size());
    found_video += int(v.size());
    for (const Marker& m : v)
      for (const Marker& n : w)
        if (m.id == n.id) {
          for (int j = 0; j < 4; ++j)
            EXPECT_LT(cv::norm(m.corners[size_t(j)] - n.corners[size_t(j)]), 0.35) << "frame " << k << " id " << m.id;
        }
  }
  EXPECT_GE(region_frames, 20);   // 4 of every 5 frames, unless a marker was lost
  EXPECT_GE(found_whole, 80);
  EXPECT_GE(found_video, found_whole - 2) << "video mode lost markers a whole search finds";
}

// A marker that comes into view away from the known ones is found at the next whole search, not before, and no
// later than full_search_interval frames; a marker that jumps out of its region makes the next frame whole.
TEST(VideoSearch, ANewMarkerIsFoundWithinTheIntervalAndALostOneBringsAWholeSearch) {
  const Dictionary d = make_aruco_original();
  Detector det({d});
  DetectorParams p = det.params();
  p.full_search_interval = 4;
  det.set_params(p);
  VideoSearch video;
  const Quad a = square({150, 150}, 90), b = square({500, 360}, 90);
  const cv::Mat only_a = page(d, {{12, a}}), both = page(d, {{12, a}, {77, b}});
  FrameTrace t;
  ASSERT_TRUE(has_id(video.detect(det, only_a, &t), 12));
  EXPECT_TRUE(t.search.whole);
  ASSERT_TRUE(has_id(video.detect(det, only_a, &t), 12));
  EXPECT_FALSE(t.search.whole);
  // 77 appears: the region frames do not see it; the whole search, at most 4 frames after the last, does.
  int seen_at = -1;
  for (int k = 0; k < 4 && seen_at < 0; ++k) {
    const std::vector<Marker> found = video.detect(det, both, &t);
    EXPECT_TRUE(has_id(found, 12));
    if (has_id(found, 77)) {
      seen_at = k;
      EXPECT_TRUE(t.search.whole);
      EXPECT_NE(t.search.why.find("full_search_interval"), std::string::npos) << t.search.why;
    } else {
      EXPECT_FALSE(t.search.whole);
      // The Why panel says why nothing is found there.
      const RegionReport why = explain_region(t, cv::Rect2f(480, 340, 40, 40));
      EXPECT_EQ(why.lost_at, Stage::search_regions) << why.summary;
    }
  }
  EXPECT_EQ(seen_at, 2);   // frames 0 (whole) and 1 had passed; 2 and 3 were regions; this is the 4th
  // Both known now. 12 jumps far out of its region: lost on this frame, searched whole on the next.
  const cv::Mat moved = page(d, {{12, square({150, 400}, 90)}, {77, b}});
  std::vector<Marker> found = video.detect(det, moved, &t);
  EXPECT_FALSE(t.search.whole);
  EXPECT_FALSE(has_id(found, 12));
  found = video.detect(det, moved, &t);
  EXPECT_TRUE(t.search.whole);
  EXPECT_NE(t.search.why.find("lost"), std::string::npos) << t.search.why;
  EXPECT_TRUE(has_id(found, 12));
  EXPECT_TRUE(has_id(found, 77));
}

// full_search_interval 1 searches every frame whole; a different frame size starts again with a whole search.
TEST(VideoSearch, IntervalOneAndANewSizeSearchWhole) {
  const Dictionary d = make_aruco_original();
  Detector det({d});
  const cv::Mat img = page(d, {{5, square({320, 240}, 120)}});
  VideoSearch video;
  FrameTrace t;
  video.detect(det, img, &t);
  video.detect(det, img, &t);
  EXPECT_FALSE(t.search.whole);
  EXPECT_EQ(t.search.factor, 3);
  cv::Mat bigger;
  cv::resize(img, bigger, {1280, 960});
  EXPECT_EQ(video.detect(det, bigger, &t).size(), 1u);
  EXPECT_TRUE(t.search.whole);
  EXPECT_NE(t.search.why.find("size"), std::string::npos) << t.search.why;
  DetectorParams p = det.params();
  p.full_search_interval = 1;
  det.set_params(p);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(video.detect(det, bigger, &t).size(), 1u);
    EXPECT_TRUE(t.search.whole);
  }
}

// The same sequence gives the same markers, to the bit, for any thread count.
TEST(VideoSearch, SameResultsForAnyThreadCount) {
  const SyntheticWorld world = moving_markers({1280, 720}, 1200, 5, 6);
  const Detector det({make_aruco_original()});
  VideoSearch one, three;
  for (int k = 0; k < 12; ++k) {
    const SyntheticFrame f = world.render(k / 20.0);
    const auto a = one.detect(det, f.image, nullptr, TraceLevel::off, 1);
    const auto b = three.detect(det, f.image, nullptr, TraceLevel::off, 3);
    ASSERT_EQ(a.size(), b.size()) << "frame " << k;
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].id, b[i].id);
      for (int j = 0; j < 4; ++j) EXPECT_EQ(a[i].corners[size_t(j)], b[i].corners[size_t(j)]);
    }
  }
}

// The full trace of a region frame: the stage's picture shows the frame bright in the regions and dimmed outside;
// the search's pictures are black outside the regions; a contour cut by a region's edge stops at size_filter,
// naming region_margin_rate.
TEST(Trace, SearchRegionsPictureShowsWhereTheSearchLooked) {
  const Dictionary d = make_aruco_original();
  const Detector det({d});
  cv::Mat img = page(d, {{9, square({160, 160}, 96)}});
  // A dark bar reaching out of 9's region, to be cut by its edge.
  cv::rectangle(img, cv::Rect(260, 150, 300, 14), cv::Scalar(20), cv::FILLED);
  VideoSearch video;
  FrameTrace t;
  video.detect(det, img, &t, TraceLevel::full);
  video.detect(det, img, &t, TraceLevel::full);
  ASSERT_FALSE(t.search.whole);
  ASSERT_EQ(t.search.regions.size(), 1u);
  const cv::Rect r = t.search.regions[0];
  EXPECT_EQ(t.markers.size(), 1u);
  std::array<cv::Mat, kStageCount> views;
  render_stage_views(cv::Mat(), t, views);
  const cv::Mat& shown = views[size_t(Stage::search_regions)];
  ASSERT_EQ(shown.size(), img.size());
  cv::Mat grey;
  cv::cvtColor(shown, grey, cv::COLOR_BGR2GRAY);
  const cv::Point inside(r.x + 4, r.y + 4), outside(600, 450);
  EXPECT_NEAR(grey.at<uint8_t>(inside), 200, 3);       // the page as it is
  EXPECT_LT(grey.at<uint8_t>(outside), 100);           // dimmed
  const StageRecord* th = t.stage(Stage::adaptive_threshold);
  ASSERT_NE(th, nullptr);
  ASSERT_FALSE(th->image.empty());
  EXPECT_EQ(cv::countNonZero(th->image(cv::Rect(400 / t.search.factor, 300 / t.search.factor, 40, 40))), 0);
  bool cut = false;
  for (const CandidateRecord& c : t.candidates)
    if (c.fate.param == "region_margin_rate") {
      cut = true;
      EXPECT_EQ(c.fate.stage, Stage::size_filter);
      EXPECT_GE(c.bbox.br().x, r.br().x - 2 * t.search.factor);
    }
  EXPECT_TRUE(cut);
}
