// The Lab workspace's two pieces below the window: a run in the background whose snapshots fill in cell by cell
// (and end as run_lab's own result), and a cell as a frame source that shows exactly the frames the run judged.
#include "lab/cell_source.hpp"
#include "lab/detectors.hpp"
#include "lab/session.hpp"
#include "lab_test_util.hpp"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <chrono>
#include <thread>

namespace arwb::lab {
namespace {

LabPlan small_plan() {
  LabPlan p;
  p.name = "small";
  p.markers = 5;
  p.sizes_mm = {65};
  p.distances_m = {0.5, 2};
  p.lux = {1000};
  p.frames_per_cell = 6;
  return p;
}

std::shared_ptr<const LabProgress> wait_end(const LabSession& s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < end) {
    auto p = s.snapshot();
    if (!p->running) return p;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return s.snapshot();
}

TEST(LabSession, ARunInTheBackgroundEndsAsRunLabsOwnResult) {
  LabOptions o;
  o.detectors = {"arwb", "opencv"};
  LabSession s;
  ASSERT_TRUE(s.start(small_plan(), o));
  const auto p = wait_end(s);
  ASSERT_TRUE(p->finished) << p->error;
  ASSERT_TRUE(p->complete);
  EXPECT_EQ(p->cells_done(), 2);
  EXPECT_EQ(p->frames_done, p->frames_total);
  const Result<LabResults> direct = run_lab(small_plan(), o);
  ASSERT_TRUE(direct) << direct.error();
  EXPECT_EQ(without_times(lab_table_csv(*p->complete)), without_times(lab_table_csv(*direct)));
  for (size_t c = 0; c < 2; ++c) {
    for (size_t d = 0; d < 2; ++d) {
      EXPECT_EQ(p->results[c]->detectors[d].marks, direct->cells[c].detectors[d].marks);
      // A mark per frame: the marker frames, then the empty ones.
      EXPECT_EQ(p->results[c]->detectors[d].marks.size(),
                size_t(small_plan().frames_per_cell + small_plan().empty_frames_per_cell()));
    }
  }
}

TEST(LabSession, AStoppedRunKeepsTheCellsItFinishedAndSaysSo) {
  LabPlan plan = small_plan();
  plan.distances_m = {0.5, 1, 2};
  plan.lux = {1000, 500};
  plan.frames_per_cell = 30;
  LabOptions o;
  o.detectors = {"arwb"};
  LabSession s;
  ASSERT_TRUE(s.start(plan, o));
  // Wait for the first cell, then stop.
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (s.snapshot()->cells_done() < 1 && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  s.stop();
  const auto p = wait_end(s);
  EXPECT_FALSE(p->running);
  EXPECT_FALSE(p->finished);
  EXPECT_FALSE(p->complete);
  EXPECT_GE(p->cells_done(), 1);
  EXPECT_LT(p->cells_done(), 6);
  EXPECT_NE(p->error.find("stopped after"), std::string::npos) << p->error;
}

TEST(LabSession, APlanTheDetectorsCannotReadIsRefusedAtOnce) {
  LabOptions o;
  o.detectors = {"apriltag"};
  LabSession s;
  const Status st = s.start(small_plan(), o);
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().find("apriltag reads the AprilTag families"), std::string::npos) << st.error();
  EXPECT_FALSE(s.running());
  o.detectors = {};
  EXPECT_FALSE(s.start(small_plan(), o));
}

TEST(LabCellSource, ShowsTheFramesTheRunJudgedWithTheirTruth) {
  const LabPlan plan = small_plan();
  LabOptions o;
  o.detectors = {"arwb"};
  const Result<LabResults> r = run_lab(plan, o);
  ASSERT_TRUE(r) << r.error();
  const size_t cell = 1;   // 65 mm at 2 m: some frames missed
  const std::string& marks = r->cells[cell].detectors[0].marks;
  LabCellSource src(plan, o, r->ids, cell);
  EXPECT_EQ(src.info().kind, SourceKind::lab);
  EXPECT_EQ(src.info().name, "lab: 65 mm at 2 m, 1000 lx");
  EXPECT_EQ(src.info().count, int(marks.size()));
  auto detect = make_detector("arwb", plan.dictionary, o.params);
  ASSERT_TRUE(detect);
  LabFrameRenderer renderer(plan, o, r->ids);
  for (int k = 0; k < int(marks.size()); ++k) {
    src.seek(k);
    cv::Mat img;
    ASSERT_EQ(src.next(0, img).status, FrameStatus::ok) << k;
    EXPECT_EQ(src.next(0, img).status, FrameStatus::same) << "paused: the frame stands";
    const LabFrame f = renderer.render(cell, k);
    if (f.image.empty()) continue;
    EXPECT_EQ(cv::norm(img, f.image, cv::NORM_INF), 0) << "frame " << k << " is not the run's";
    // The same verdict as the run's mark for this frame.
    EXPECT_EQ(frame_mark(f, (*detect)(img), r->cells[cell].side_px), marks[size_t(k)]) << "frame " << k;
    if (f.empty) {
      EXPECT_TRUE(src.truth().empty());
      EXPECT_NE(src.info().item.find("no marker"), std::string::npos);
    } else {
      ASSERT_EQ(src.truth().size(), 1u);
      EXPECT_EQ(src.truth()[0].id, f.id);
      EXPECT_EQ(src.truth()[0].dict, "ARUCO_ORIGINAL");
      EXPECT_NE(src.info().item.find("id " + std::to_string(f.id)), std::string::npos) << src.info().item;
    }
  }
  // Stepping pauses and wraps at the ends when looping (as the source panel's Loop says).
  src.seek(0);
  src.step(-1);
  EXPECT_EQ(src.info().position, int(marks.size()) - 1);
}

}  // namespace
}  // namespace arwb::lab
