// The trace tells the truth: each stage's time and counts are its own, in the order the stages run. Times are
// compared as medians of interleaved runs with large work ratios, so a loaded 2-core machine does not flip them.
#include "detect/detector.hpp"
#include "synth/synth.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

using namespace arwb;

namespace {

// A page of cols x rows markers, slightly blurred so that corner refinement has edges to work on.
cv::Mat marker_page(const Dictionary& d, int cols, int rows, float side, cv::Size size) {
  cv::Mat img(size, CV_8UC3, cv::Scalar(235, 235, 235));
  const double cw = double(size.width) / cols, ch = double(size.height) / rows;
  int id = 3;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const float x0 = float(c * cw + (cw - side) / 2), y0 = float(r * ch + (ch - side) / 2);
      while (!unambiguous(d, id)) ++id;
      draw_marker(img, d, id++, Quad{cv::Point2f(x0, y0), {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}});
    }
  cv::GaussianBlur(img, img, cv::Size(0, 0), 1.2);
  return img;
}

using StageMs = std::array<double, kStageCount>;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

// Per stage, the median over `runs` of its time; the runs of all the given jobs are interleaved so that a burst
// of load elsewhere hits them alike.
std::vector<StageMs> median_stage_ms(const std::vector<std::function<void(FrameTrace&)>>& jobs, int runs) {
  std::vector<std::array<std::vector<double>, kStageCount>> samples(jobs.size());
  for (int r = 0; r < runs; ++r)
    for (size_t j = 0; j < jobs.size(); ++j) {
      FrameTrace t;
      jobs[j](t);
      for (const StageRecord& s : t.stages) samples[j][size_t(s.stage)].push_back(s.ms);
    }
  std::vector<StageMs> out(jobs.size());
  for (size_t j = 0; j < jobs.size(); ++j)
    for (int s = 0; s < kStageCount; ++s) out[j][size_t(s)] = median(samples[j][size_t(s)]);
  return out;
}

int fates_at(const FrameTrace& t, Stage s) {
  return int(std::count_if(t.candidates.begin(), t.candidates.end(),
                           [&](const CandidateRecord& c) { return c.fate.stage == s; }));
}

}  // namespace

// The trace lists every stage once, in the order of the Stage enum, which is the order the detector runs them:
// the corners are refined before the warp reads the cells.
TEST(TraceTruth, StagesAreRecordedInTheOrderTheyRun) {
  const std::vector<std::string_view> expected = {
      "acquisition", "search_regions", "decimation", "adaptive_threshold", "contours", "coarse_search", "size_filter",
      "quad_fit", "nested_filter", "corner_refinement", "perspective_removal", "otsu", "bit_grid", "border_check",
      "identification", "fine_search", "duplicates"};
  ASSERT_EQ(expected.size(), size_t(kStageCount));
  const Dictionary d = make_aruco_original();
  FrameTrace t;
  Detector({d}).detect(marker_page(d, 3, 2, 60, {320, 240}), &t, TraceLevel::summary);
  ASSERT_EQ(t.stages.size(), size_t(kStageCount));
  for (int s = 0; s < kStageCount; ++s) {
    EXPECT_EQ(stage_name(t.stages[size_t(s)].stage), expected[size_t(s)]);
    EXPECT_EQ(stage_name(static_cast<Stage>(s)), expected[size_t(s)]);
  }
  // The parameter table follows the same order: the detector's stages, then the tracker's (after the detector
  // in the data flow, and not a stage of the detector's trace).
  int last = -1;
  bool tracking = false;
  for (const ParamInfo& info : param_table()) {
    Stage s;
    if (std::string_view(info.stage) == kTrackingStage) {
      tracking = true;
      continue;
    }
    EXPECT_FALSE(tracking) << info.name << " (a detector stage's) comes after the tracking rows";
    ASSERT_TRUE(stage_from_name(info.stage, &s)) << info.name;
    EXPECT_GE(int(s), last) << info.name << " is out of stage order";
    last = int(s);
  }
}

// Corner refinement off against many passes on a page of 30 markers: corner_refinement's own time grows by the
// refinement work, and no other stage's time moves by anything like it.
TEST(TraceTruth, CornerRefinementTimeIsChargedToCornerRefinement) {
  const Dictionary d = make_aruco_original();
  const cv::Mat page = marker_page(d, 6, 5, 90, {960, 720});
  DetectorParams off, heavy;
  off.corner_refinement = 0;
  heavy.subpix_max_iterations = 50;
  heavy.subpix_epsilon_px = 0.001;
  heavy.unrefined_miss_rate = 1;  // each quad read once, as with refinement off
  heavy.subpix_window_px = 20;
  const Detector det_off({d}, off), det_heavy({d}, heavy);
  ASSERT_EQ(det_heavy.detect(page).size(), 30u);
  ASSERT_EQ(det_off.detect(page).size(), 30u);
  const auto ms = median_stage_ms({[&](FrameTrace& t) { det_off.detect(page, &t, TraceLevel::summary); },
                                   [&](FrameTrace& t) { det_heavy.detect(page, &t, TraceLevel::summary); }},
                                  15);
  const double grown = ms[1][size_t(Stage::corner_refinement)] - ms[0][size_t(Stage::corner_refinement)];
  EXPECT_GT(ms[1][size_t(Stage::corner_refinement)], 0.5) << "refining 30 markers takes time";
  EXPECT_GT(grown, 5 * ms[0][size_t(Stage::corner_refinement)] + 0.2);
  for (int s = 0; s < kStageCount; ++s) {
    if (static_cast<Stage>(s) == Stage::corner_refinement) continue;
    EXPECT_LT(std::abs(ms[1][size_t(s)] - ms[0][size_t(s)]), 0.3 * grown + 0.25 * ms[0][size_t(s)] + 0.05)
        << stage_name(static_cast<Stage>(s)) << " moved with corner refinement: " << ms[0][size_t(s)] << " -> "
        << ms[1][size_t(s)] << " ms, corner_refinement +" << grown << " ms";
  }
}

// Acquisition's resize is timed in acquisition: resizing a small frame up to a large working size costs
// acquisition much more than the grey conversion of the small frame alone, and more than the grey conversion of
// a frame already that large; adaptive_threshold on the same working size costs the same either way.
TEST(TraceTruth, AcquisitionTimeCoversTheResize) {
  const Dictionary d = make_aruco_original();
  const cv::Mat small = marker_page(d, 3, 2, 60, {320, 240});
  Detector plain({d}), resizing({d});
  AcquisitionSettings a;
  a.size = {2560, 1920};
  resizing.set_acquisition(a);
  cv::Mat large;
  FrameTrace t;
  resizing.detect(small, &t, TraceLevel::summary, 1, &large);
  ASSERT_EQ(large.size(), cv::Size(2560, 1920));
  EXPECT_EQ(t.work_width, 2560);
  EXPECT_EQ(t.work_height, 1920);
  EXPECT_EQ(t.width, 2560) << "with the acquired image asked for, the trace is in its pixels";
  EXPECT_EQ(t.scale_x, 1.0);
  const auto ms = median_stage_ms(
      {[&](FrameTrace& tr) { plain.detect(small, &tr, TraceLevel::summary); },
       [&](FrameTrace& tr) {
         cv::Mat out;
         resizing.detect(small, &tr, TraceLevel::summary, 1, &out);
       },
       [&](FrameTrace& tr) { plain.detect(large, &tr, TraceLevel::summary); }},
      7);
  const size_t acq = size_t(Stage::acquisition), thr = size_t(Stage::adaptive_threshold);
  EXPECT_GT(ms[1][acq], 10 * ms[0][acq]) << "resize 320x240 -> 2560x1920 against none";
  EXPECT_GT(ms[1][acq], 1.3 * ms[2][acq]) << "resize and grey against grey alone at 2560x1920";
  EXPECT_LT(ms[1][thr], 2.0 * ms[2][thr] + 0.5) << "the resize leaked into adaptive_threshold";
  EXPECT_GT(ms[1][thr], 0.5 * ms[2][thr] - 0.5);
}

// Counts: each stage's `in` is the previous stage's `out` (corner_refinement also re-reads inner quads of merged
// pairs whose outer quad was no marker; quad_fit also fits the parts of the shapes it split at thin lines), and
// every item a stage drops is a candidate whose fate names that stage.
// On a decimated search, fine_search's quads are read by the per-candidate stages listed before it.
TEST(TraceTruth, CountsChainAndDropsMatchFates) {
  const Dictionary d = make_aruco_original();
  SynthOptions opt;
  opt.dictionaries = {d};
  opt.size = {640, 480};
  DetectorParams decimated;
  decimated.decimation_factor = 2;
  int checked = 0, drops_seen = 0, fine_drops = 0, fine_quads = 0;
  for (int i = 0; i < 32; ++i) {
    const Detector det({d}, i < 16 ? DetectorParams{} : decimated);
    const SynthImage s = synth_photo(opt, 3, i);
    FrameTrace t;
    const auto markers = det.detect(s.image, &t, TraceLevel::full);
    ASSERT_EQ(t.stages.size(), size_t(kStageCount));
    auto rec = [&](Stage st) { return *t.stage(st); };
    EXPECT_EQ(rec(Stage::acquisition).in, 1);
    EXPECT_EQ(rec(Stage::acquisition).out, 1);
    for (int k = 1; k < kStageCount; ++k) {
      const StageRecord& prev = t.stages[size_t(k - 1)];
      const StageRecord& cur = t.stages[size_t(k)];
      if (cur.stage == Stage::contours || cur.stage == Stage::fine_search) continue;  // their own searches
      if (cur.stage == Stage::duplicates) EXPECT_EQ(cur.in, rec(Stage::identification).out) << "image " << i;
      else if (cur.stage == Stage::corner_refinement || cur.stage == Stage::quad_fit)
        EXPECT_GE(cur.in, prev.out) << "image " << i;
      else EXPECT_EQ(cur.in, prev.out) << "image " << i << ": " << stage_name(cur.stage);
    }
    EXPECT_EQ(rec(Stage::corner_refinement).in, rec(Stage::corner_refinement).out) << "it drops nothing";
    EXPECT_EQ(rec(Stage::perspective_removal).in, rec(Stage::perspective_removal).out) << "it drops nothing";
    for (Stage st : {Stage::size_filter, Stage::quad_fit, Stage::otsu, Stage::bit_grid, Stage::border_check,
                     Stage::identification, Stage::duplicates}) {
      EXPECT_EQ(fates_at(t, st), rec(st).in - rec(st).out) << "image " << i << ": " << stage_name(st);
      drops_seen += rec(st).in - rec(st).out;
    }
    // Merged inner quads that were not re-read keep the nested_filter fate; fine_search's contours that made no
    // quad to read keep its own.
    EXPECT_EQ(fates_at(t, Stage::nested_filter) + fates_at(t, Stage::fine_search),
              rec(Stage::nested_filter).in + rec(Stage::fine_search).in - rec(Stage::corner_refinement).in)
        << "image " << i;
    if (i < 16) {
      EXPECT_EQ(rec(Stage::fine_search).in, 0) << "it runs only on a decimated search";
    }
    fine_drops += fates_at(t, Stage::fine_search);
    fine_quads += rec(Stage::fine_search).out;
    EXPECT_EQ(fates_at(t, Stage::accepted), rec(Stage::duplicates).out);
    EXPECT_EQ(int(markers.size()), rec(Stage::duplicates).out);
    ++checked;
  }
  EXPECT_EQ(checked, 32);
  EXPECT_GT(drops_seen, 100) << "the set should exercise the drops";
  EXPECT_GT(fine_drops, 0) << "and the fine search's";
  EXPECT_GT(fine_quads, 0);
}

// Nothing is left out: the stages' times add up to most of the detector's own total.
TEST(TraceTruth, StageTimesAddUpToTheTotal) {
  const Dictionary d = make_aruco_original();
  const cv::Mat page = marker_page(d, 6, 5, 90, {960, 720});
  const Detector det({d});
  std::vector<double> share;
  for (int r = 0; r < 9; ++r) {
    FrameTrace t;
    det.detect(page, &t, TraceLevel::summary);
    double sum = 0;
    for (const StageRecord& s : t.stages) sum += s.ms;
    EXPECT_LE(sum, t.total_ms * 1.001 + 1e-3);
    share.push_back(sum / t.total_ms);
  }
  EXPECT_GT(median(share), 0.8);
}
