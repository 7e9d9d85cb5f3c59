// explain_region and sweep_region on synthetic frames whose markers are known, and on a real photograph of
// markers of a dictionary that is not searched.
#include "detect/detector.hpp"
#include "inspect/diagnose.hpp"
#include "synth/synth.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <atomic>
#include <cstdio>

using namespace arwb;

namespace {

// A 640x480 grey frame with marker `id` drawn square at `centre`, side `side` px.
cv::Mat frame_with_marker(const Dictionary& d, int id, cv::Point2d centre, double side, int black = 0,
                          int white = 255) {
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  draw_marker(img, d, id, project_square(centre, side, 0, 0, 0, 800), 1.0, 4, black, white);
  return img;
}

cv::Rect2f around(cv::Point2d c, double half) {
  return {float(c.x - half), float(c.y - half), float(2 * half), float(2 * half)};
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// OpenCV's tutorial photograph (Debian's opencv-doc, third_party/setup): 640x480, six DICT_6X6_250 markers, ids
// 23, 40, 62, 98, 124 and 203. Marker 23's corners lie about (297,185)-(335,212).
const char* const kPhoto = "/usr/share/doc/opencv-doc/opencv4/html/singlemarkersoriginal.jpg";
const cv::Rect2f kAround23(290, 178, 52, 42);

float box_iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  const float inter = (a & b).area();
  return inter / (a.area() + b.area() - inter);
}

cv::Rect2f box_of(const CandidateRecord& c) {
  if (!c.has_quad) return cv::Rect2f(c.bbox);
  std::vector<cv::Point2f> pts(c.quad.begin(), c.quad.end());
  return cv::boundingRect(pts);
}

}  // namespace

// --- explain_region

TEST(ExplainRegion, TheHeadlineIsTheCandidateTheRegionIsDrawnAroundNotTheLargestOverlappingIt) {
  // Two uniform black squares, both stopped at otsu: a large one whose edge the region touches, and the small
  // one it is drawn around.
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar::all(128));
  cv::rectangle(img, cv::Rect(100, 100, 200, 200), cv::Scalar::all(0), cv::FILLED);
  cv::rectangle(img, cv::Rect(312, 200, 40, 40), cv::Scalar::all(0), cv::FILLED);
  FrameTrace t;
  ASSERT_TRUE(Detector({make_aruco_original()}).detect(img, &t, TraceLevel::full).empty());
  const RegionReport rep = explain_region(t, cv::Rect2f(295, 190, 65, 60));
  ASSERT_GE(rep.candidates.size(), 2u);
  const CandidateRecord& head = t.candidates[size_t(rep.candidates.front().index)];
  EXPECT_EQ(head.fate.stage, Stage::otsu);
  EXPECT_LT(box_of(head).width, 60) << rep.summary;
  EXPECT_TRUE(has(rep.summary, "the one covering the region")) << rep.summary;
}

TEST(ExplainRegion, NamesTheDictionaryOfAPhotographedMarkerThatIsNotSearched) {
  const cv::Mat img = cv::imread(kPhoto);
  ASSERT_FALSE(img.empty()) << kPhoto << " (opencv-doc, third_party/setup)";
  const Detector det({make_aruco_original()});
  FrameTrace t;
  ASSERT_TRUE(det.detect(img, &t, TraceLevel::full).empty());
  const RegionReport rep = explain_region(t, kAround23, det.params(), {"ARUCO_ORIGINAL"});
  ASSERT_FALSE(rep.other_dictionaries.empty()) << rep.summary;
  // 6X6_50 ... 6X6_1000 share their first ids: the smallest that reads all six markers of the photograph.
  EXPECT_EQ(rep.other_dictionaries[0].dict, "6X6_250");
  EXPECT_EQ(rep.other_dictionaries[0].id, 23);
  EXPECT_EQ(rep.other_dictionaries[0].in_frame, 6);
  EXPECT_EQ(rep.summary.rfind("This is a 6X6_250 marker, id 23", 0), 0u) << rep.summary;
  EXPECT_TRUE(has(rep.summary, "add that dictionary")) << rep.summary;
  // No parameter advice: none would help.
  EXPECT_FALSE(has(rep.summary, "would let it through")) << rep.summary;
  // With 6X6_250 searched it is detected, and nothing else is advised.
  const Detector with({make_aruco_original(), *dictionary_by_name("6X6_250")});
  FrameTrace t2;
  ASSERT_EQ(with.detect(img, &t2, TraceLevel::full).size(), 6u);
  const RegionReport found = explain_region(t2, kAround23, with.params(), {"ARUCO_ORIGINAL", "6X6_250"});
  EXPECT_TRUE(found.other_dictionaries.empty());
  EXPECT_TRUE(has(found.summary, "6X6_250 id 23 is detected here")) << found.summary;
}

TEST(ExplainRegion, TheHeadlineIsTheCandidateCoveringTheRegionBest) {
  const cv::Mat img = cv::imread(kPhoto);
  ASSERT_FALSE(img.empty()) << kPhoto;
  FrameTrace t;
  ASSERT_TRUE(Detector({make_aruco_original()}).detect(img, &t, TraceLevel::full).empty());
  const RegionReport rep = explain_region(t, kAround23);
  ASSERT_GT(rep.candidates.size(), 1u);
  const int head = rep.candidates.front().index;
  const float head_iou = box_iou(box_of(t.candidates[size_t(head)]), kAround23);
  for (const RegionCandidate& c : rep.candidates)
    EXPECT_LE(box_iou(box_of(t.candidates[size_t(c.index)]), kAround23), head_iou + 1e-4f) << c.line;
  // It is marker 23's outline, and the summary names it.
  EXPECT_GT(box_iou(box_of(t.candidates[size_t(head)]), cv::Rect2f(297, 185, 38, 27)), 0.6f);
  char tag[32];
  std::snprintf(tag, sizeof tag, "#%d (", head);
  EXPECT_TRUE(has(rep.summary, tag)) << rep.summary;
}

TEST(ExplainRegion, ListsTheDetectedMarkerAsAccepted) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 12, {320, 240}, 100);
  FrameTrace t;
  ASSERT_EQ(Detector({d}).detect(img, &t, TraceLevel::full).size(), 1u);
  const RegionReport rep = explain_region(t, around({320, 240}, 60));
  ASSERT_FALSE(rep.candidates.empty());
  const RegionCandidate& first = rep.candidates.front();
  EXPECT_EQ(first.fate.stage, Stage::accepted);
  EXPECT_EQ(first.marker_id, 12);
  EXPECT_EQ(t.candidates[size_t(first.index)].marker, 0);
  EXPECT_TRUE(has(first.line, "accepted")) << first.line;
  EXPECT_TRUE(has(first.line, "id 12")) << first.line;
  EXPECT_EQ(rep.lost_at, Stage::accepted);
  EXPECT_TRUE(has(rep.summary, "ARUCO_ORIGINAL id 12 is detected here")) << rep.summary;
  // The region comes back clipped to the frame.
  const RegionReport edge = explain_region(t, cv::Rect2f(600, 400, 100, 100));
  EXPECT_FLOAT_EQ(edge.region.width, 40);
  EXPECT_FLOAT_EQ(edge.region.height, 80);
}

TEST(ExplainRegion, AnEmptyPatchIsLostAtAdaptiveThreshold) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 12, {320, 240}, 100);
  FrameTrace t;
  Detector({d}).detect(img, &t, TraceLevel::full);
  const RegionReport rep = explain_region(t, around({80, 80}, 40));
  EXPECT_TRUE(rep.candidates.empty());
  EXPECT_EQ(rep.lost_at, Stage::adaptive_threshold);
  EXPECT_TRUE(has(rep.summary, "adaptive_threshold")) << rep.summary;
  EXPECT_TRUE(has(rep.summary, "threshold_offset")) << rep.summary;
}

TEST(ExplainRegion, ATooSmallMarkerStopsAtSizeFilterNamingMinPerimeter) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 12, {320, 240}, 6);   // a border of about 24 px < 32
  FrameTrace t;
  EXPECT_TRUE(Detector({d}).detect(img, &t, TraceLevel::full).empty());
  const RegionReport rep = explain_region(t, around({320, 240}, 8));
  const bool at_size_filter = !rep.candidates.empty() && rep.candidates.front().fate.stage == Stage::size_filter &&
                              rep.candidates.front().fate.param == "min_perimeter_px";
  EXPECT_TRUE(at_size_filter || rep.lost_at == Stage::contours) << rep.summary;
  EXPECT_TRUE(has(rep.summary, "min_perimeter_px")) << rep.summary;
  for (const auto& c : rep.candidates) EXPECT_TRUE(has(c.line, "size_filter")) << c.line;
}

TEST(ExplainRegion, ARejectedQuadIsListedWithStageParameterAndNumbers) {
  // A plain black square on white: its quad is found, its frontal view is uniform.
  const Dictionary d = make_aruco_original();
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::rectangle(img, cv::Rect(300, 220, 40, 40), cv::Scalar(0, 0, 0), -1);
  FrameTrace t;
  EXPECT_TRUE(Detector({d}).detect(img, &t, TraceLevel::full).empty());
  const RegionReport rep = explain_region(t, around({320, 240}, 25));
  ASSERT_FALSE(rep.candidates.empty());
  const RegionCandidate& first = rep.candidates.front();
  EXPECT_EQ(first.fate.stage, Stage::otsu);
  EXPECT_EQ(first.fate.param, "otsu_min_stddev");
  EXPECT_LT(first.fate.value, first.fate.limit);
  EXPECT_EQ(first.marker_id, -1);
  EXPECT_TRUE(has(first.line, "quad")) << first.line;
  EXPECT_TRUE(has(first.line, "otsu_min_stddev")) << first.line;
  EXPECT_EQ(rep.lost_at, Stage::accepted);  // something was there; the candidates say what became of it
  EXPECT_TRUE(has(rep.summary, "otsu")) << rep.summary;
  EXPECT_TRUE(has(rep.summary, "Lowering otsu_min_stddev")) << rep.summary;
}

TEST(ExplainRegion, ForegroundWithoutATracedBorderIsLostAtContours) {
  // A hand-made full trace: a speck of foreground that find_contours skipped and nobody recorded.
  FrameTrace t;
  t.level = TraceLevel::full;
  t.width = t.work_width = 100;
  t.height = t.work_height = 80;
  cv::Mat binary = cv::Mat::zeros(80, 100, CV_8UC1);
  binary.at<uint8_t>(40, 50) = 255;
  t.stages.push_back(StageRecord{Stage::adaptive_threshold, 0, 1, 1, binary});
  const RegionReport rep = explain_region(t, cv::Rect2f(45, 35, 10, 10));
  EXPECT_EQ(rep.lost_at, Stage::contours);
  EXPECT_TRUE(has(rep.summary, "min_perimeter_px")) << rep.summary;
  EXPECT_EQ(explain_region(t, cv::Rect2f(0, 0, 10, 10)).lost_at, Stage::adaptive_threshold);

  // After a decimated search the binary image is half the frame's size: the region is looked up in its pixels.
  cv::Mat half = cv::Mat::zeros(40, 50, CV_8UC1);
  half.at<uint8_t>(30, 40) = 255;  // under the frame's (80, 60) .. (81, 61)
  t.stages.back().image = half;
  EXPECT_EQ(t.search_factor(), 2);
  EXPECT_EQ(explain_region(t, cv::Rect2f(76, 56, 10, 10)).lost_at, Stage::contours);
  EXPECT_EQ(explain_region(t, cv::Rect2f(45, 35, 10, 10)).lost_at, Stage::adaptive_threshold);
}

TEST(ExplainRegion, SummaryAndOffTracesSayWhatTheyCannotTell) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 12, {320, 240}, 100);
  const Detector det({d});
  FrameTrace t;
  det.detect(img, &t, TraceLevel::summary);
  const RegionReport empty = explain_region(t, around({80, 80}, 40));
  EXPECT_TRUE(empty.candidates.empty());
  EXPECT_TRUE(has(empty.summary, "summary-level")) << empty.summary;
  EXPECT_TRUE(has(empty.summary, "full trace")) << empty.summary;
  // Quads are recorded at summary level, so the marker is still explained.
  const RegionReport marker = explain_region(t, around({320, 240}, 60));
  ASSERT_FALSE(marker.candidates.empty());
  EXPECT_EQ(marker.candidates.front().marker_id, 12);

  det.detect(img, &t, TraceLevel::off);
  EXPECT_TRUE(has(explain_region(t, around({320, 240}, 60)).summary, "id 12"));
  EXPECT_TRUE(has(explain_region(t, around({80, 80}, 40)).summary, "level off"));
}

// --- sweep_region

TEST(SweepRegion, AddsTheDictionaryOfAPhotographedMarkerBeforeAnyParameter) {
  const cv::Mat img = cv::imread(kPhoto);
  ASSERT_FALSE(img.empty()) << kPhoto;
  const SweepResult r = sweep_region(img, Detector({make_aruco_original()}), kAround23);
  ASSERT_TRUE(r.found) << r.message;
  EXPECT_EQ(r.add_dictionary, "6X6_250");
  EXPECT_TRUE(r.changes.empty());
  EXPECT_EQ(r.marker.id, 23);
  EXPECT_EQ(r.marker.dict, "6X6_250");
  EXPECT_EQ(r.runs, 2);   // the plain run and one full trace: no parameter was tried
  EXPECT_TRUE(has(r.message, "6X6_250")) << r.message;
}

TEST(SweepRegion, SaysSoWhenTheMarkerIsAlreadyDetected) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 12, {320, 240}, 100);
  const SweepResult r = sweep_region(img, Detector({d}), around({320, 240}, 60));
  EXPECT_TRUE(r.found);
  EXPECT_TRUE(r.changes.empty());
  EXPECT_EQ(r.marker.id, 12);
  EXPECT_EQ(r.runs, 1);
  EXPECT_TRUE(has(r.message, "already detected")) << r.message;
}

TEST(SweepRegion, FindsALowContrastMarkerByLoweringThresholdOffset) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 12, {320, 240}, 80, 110, 150);
  DetectorParams p;
  p.threshold_offset = 20;  // too high for a contrast of 40 grey levels
  const Detector det({d}, p);
  ASSERT_TRUE(det.detect(img).empty());
  const SweepResult r = sweep_region(img, det, around({320, 240}, 50));
  ASSERT_TRUE(r.found) << r.message;
  ASSERT_EQ(r.changes.size(), 1u) << r.message;
  EXPECT_EQ(r.changes[0].param, "threshold_offset");
  EXPECT_EQ(r.changes[0].from, 20);
  EXPECT_LT(r.changes[0].to, 20);
  EXPECT_GE(r.changes[0].to, 7);  // the nearest value that works, not the far end
  EXPECT_EQ(r.marker.id, 12);
  EXPECT_TRUE(has(r.message, "threshold_offset 20 -> ")) << r.message;
  EXPECT_TRUE(has(r.message, "finds ARUCO_ORIGINAL id 12")) << r.message;
  // The change it names does find the marker.
  p.threshold_offset = r.changes[0].to;
  EXPECT_EQ(Detector({d}, p).detect(img).size(), 1u);
}

TEST(SweepRegion, FindsASmallMarkerByLoweringMinPerimeter) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 7, {200, 300}, 30);
  DetectorParams p;
  p.min_perimeter_px = 200;  // the marker's border is about 120 px
  const Detector det({d}, p);
  ASSERT_TRUE(det.detect(img).empty());
  const SweepResult r = sweep_region(img, det, around({200, 300}, 25));
  ASSERT_TRUE(r.found) << r.message;
  ASSERT_EQ(r.changes.size(), 1u) << r.message;
  EXPECT_EQ(r.changes[0].param, "min_perimeter_px");
  EXPECT_LT(r.changes[0].to, 125);
  EXPECT_GT(r.changes[0].to, 48);
  EXPECT_EQ(r.marker.id, 7);
  EXPECT_TRUE(has(r.message, "min_perimeter_px 200 -> ")) << r.message;
  // A region elsewhere does not claim it.
  const SweepResult elsewhere = sweep_region(img, det, around({500, 100}, 25), {}, nullptr);
  EXPECT_FALSE(elsewhere.found);
}

TEST(SweepRegion, TriesPairsWhenNoSingleChangeIsEnough) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 12, {320, 240}, 40, 110, 150);
  DetectorParams p;
  p.threshold_offset = 20;
  p.min_perimeter_px = 300;
  const SweepResult r = sweep_region(img, Detector({d}, p), around({320, 240}, 25));
  ASSERT_TRUE(r.found) << r.message;
  ASSERT_EQ(r.changes.size(), 2u) << r.message;
  EXPECT_EQ(r.changes[0].param, "threshold_offset");
  EXPECT_EQ(r.changes[1].param, "min_perimeter_px");
  EXPECT_TRUE(has(r.message, " and ")) << r.message;
  p.threshold_offset = r.changes[0].to;
  p.min_perimeter_px = r.changes[1].to;
  EXPECT_EQ(Detector({d}, p).detect(img).size(), 1u);
}

TEST(SweepRegion, GivesUpOnAnEmptyRegionWithinItsBudget) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 12, {320, 240}, 100);
  double last = -1;
  bool monotonic = true;
  const SweepResult r = sweep_region(img, Detector({d}), around({80, 80}, 40), [&](double f) {
    monotonic = monotonic && f >= last && f <= 1;
    last = f;
  });
  EXPECT_FALSE(r.found);
  EXPECT_TRUE(r.changes.empty());
  EXPECT_GT(r.runs, 300);
  EXPECT_LE(r.runs, 500);
  EXPECT_TRUE(monotonic);
  EXPECT_EQ(last, 1.0);
  EXPECT_TRUE(has(r.message, "threshold_offset")) << r.message;
}

TEST(SweepRegion, StopsWhenCancelled) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = frame_with_marker(d, 12, {320, 240}, 100);
  std::atomic<bool> cancel{false};
  int calls = 0;
  const SweepResult r = sweep_region(img, Detector({d}), around({80, 80}, 40), [&](double) {
    if (++calls == 5) cancel = true;
  }, &cancel);
  EXPECT_FALSE(r.found);
  EXPECT_LE(r.runs, 7);   // the plain run, the other dictionaries' run, and the five trials
  EXPECT_TRUE(has(r.message, "cancelled")) << r.message;
  std::atomic<bool> already{true};
  EXPECT_EQ(sweep_region(img, Detector({d}), around({80, 80}, 40), {}, &already).runs, 1);
}
