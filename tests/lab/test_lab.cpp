// The lab's physics on its own (a marker's size in pixels, light to signal-to-noise), its statistics, and runs
// of the paper's plan: extreme cells behave, and the same seed gives the same table.
#include "lab/plan.hpp"
#include "lab_test_util.hpp"
#include "lab/cell_source.hpp"
#include "lab/cells_file.hpp"
#include "lab/run.hpp"
#include "lab/sensor.hpp"
#include "lab/stats.hpp"
#include "synth/marker_view.hpp"
#include "detect/detector.hpp"
#include "detect/dictionary.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>

namespace arwb::lab {
namespace {

TEST(LabPhysics, A65mmMarkerAtHalfAMetreSpansWhatThePinholeSays) {
  const SynthCamera cam = default_lab_camera();
  const double f = cam.camera_matrix(0, 0);
  EXPECT_NEAR(f, 554.26, 0.01);   // 320 / tan(30 degrees)
  EXPECT_NEAR(marker_side_px(65, 0.5, f), 72.05, 0.01);
  EXPECT_NEAR(marker_side_px(26, 2.0, f), 7.2, 0.01);
  // Rendered facing the camera at the centre: its corners are that far apart.
  MarkerRenderer r(cam, SynthMarker{"ARUCO_ORIGINAL", 7, 0.065, 1.5});
  cv::Vec3d rvec;
  cv::Rodrigues(cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1), rvec);
  MarkerView v;
  r.render_levels(rvec, {0, 0, 0.5}, &v);
  EXPECT_NEAR(cv::norm(v.corners[1] - v.corners[0]), 72.05, 0.1);
  EXPECT_TRUE(v.all_inside);
}

TEST(LabPhysics, DarkerLightGivesLowerSignalToNoise) {
  const SensorModel s;
  // Auto-exposure holds the picture's level until the exposure and then the gain run out; past the exposure,
  // fewer electrons mean more relative noise.
  const Exposure bright = auto_exposure(s, 1000), dim = auto_exposure(s, 500);
  EXPECT_LE(bright.exposure_s, s.max_exposure_s);
  EXPECT_GT(dim.gain, bright.gain);
  for (double r : {0.12, 0.86}) {
    EXPECT_GT(snr(s, 1000, r), snr(s, 850, r));
    EXPECT_GT(snr(s, 850, r), snr(s, 500, r));
    EXPECT_GT(snr(s, 500, r), snr(s, 50, r));
  }
  // The exposed picture's noise is the model's: a flat grey card's measured mean over deviation.
  for (double lux : {1000.0, 200.0}) {
    std::mt19937 rng(3);
    const cv::Mat img = expose(cv::Mat1f(200, 200, 0.5f * 255), s, lux, rng);
    cv::Scalar mean, dev;
    cv::meanStdDev(img, mean, dev);
    EXPECT_NEAR(mean[0] / dev[0], snr(s, lux, 0.5), 0.15 * snr(s, lux, 0.5)) << lux << " lx";
  }
}

TEST(LabPhysics, DefocusAndShakeGrowAsTheyShould) {
  const SensorModel s;
  const double f = default_lab_camera().camera_matrix(0, 0);
  EXPECT_NEAR(defocus_sigma_px(s, s.focus_m, f), 0, 1e-12);   // in focus
  EXPECT_GT(defocus_sigma_px(s, 0.3, f), defocus_sigma_px(s, 0.5, f));
  EXPECT_GT(shake_length_px(s, 0.05, f), shake_length_px(s, 0.01, f));
  EXPECT_NEAR(shake_length_px(s, 0.05, f), f * std::tan(s.shake_deg_s * CV_PI / 180 * 0.05), 1e-9);
}

TEST(LabStats, WilsonIntervalsAtTheEdgesAndInTheMiddle) {
  auto [lo0, hi0] = wilson_interval(0, 10);
  EXPECT_DOUBLE_EQ(lo0, 0);
  EXPECT_NEAR(hi0, 0.2775, 1e-3);
  auto [lo1, hi1] = wilson_interval(10, 10);
  EXPECT_NEAR(lo1, 0.7225, 1e-3);
  EXPECT_DOUBLE_EQ(hi1, 1);
  auto [lo, hi] = wilson_interval(5, 10);
  EXPECT_NEAR(lo, 0.2366, 1e-3);
  EXPECT_NEAR(hi, 0.7634, 1e-3);
  auto [n0, n1] = wilson_interval(0, 0);
  EXPECT_EQ(n0, 0);
  EXPECT_EQ(n1, 1);
}

TEST(LabRun, ExtremeCellsBehaveForEveryDetector) {
  LabOptions o;
  LabPlan near = one_cell(20);
  Result<LabResults> r = run_lab(near, o);
  ASSERT_TRUE(r) << r.error();
  ASSERT_EQ(r->cells.size(), 1u);
  for (size_t d = 0; d < o.detectors.size(); ++d) {
    EXPECT_EQ(r->cells[0].detectors[d].frames, 20) << o.detectors[d];
    // A quarter as many frames without a marker (cluttered, decoys included), for false positives.
    EXPECT_EQ(r->cells[0].detectors[d].empty_frames, 5) << o.detectors[d];
    EXPECT_LE(r->cells[0].detectors[d].fp_per_frame(), 1.0) << o.detectors[d];
    EXPECT_GE(r->cells[0].detectors[d].p_rec(), 80) << o.detectors[d] << ": 65 mm at 0.5 m";
  }
  LabPlan far = near;
  far.sizes_mm = {26};
  far.distances_m = {2};
  r = run_lab(far, o);
  ASSERT_TRUE(r) << r.error();
  for (size_t d = 0; d < o.detectors.size(); ++d)
    EXPECT_LE(r->cells[0].detectors[d].p_rec(), 10) << o.detectors[d] << ": 26 mm at 2 m";
}

// Cameras the calibration reader accepts crashed the lab's renderer (SIGSEGV in render_levels): a focal length of
// 1e-300, a rational model with k4 = 1e6, denormals, a huge k14, and an ordinary camera far from the default one.
// Each now runs to the end; the ordinary one sees the marker.
TEST(LabRun, EveryCameraTheReaderAcceptsRunsToTheEnd) {
  struct Case {
    const char* what;
    SynthCamera camera;
    bool sees;   // the marker is in view in some frame
  };
  const std::vector<Case> cases = {
      {"fx 1e-300", {{640, 480}, {1e-300, 0, 320, 0, 1e-300, 240, 0, 0, 1}, {0, 0, 0, 0}}, false},
      {"k4 1e6", {{640, 480}, {560, 0, 322, 0, 555, 236, 0, 0, 1}, {-0.25, 0.08, 0, 0, 0, 1e6, 0, 0}}, false},
      {"denormals", {{640, 480}, {560, 0, 322, 0, 555, 236, 0, 0, 1}, {4e-320, -4e-320, 1e-310, 0, 0}}, true},
      {"k14 1e12", {{640, 480}, {560, 0, 322, 0, 555, 236, 0, 0, 1}, std::vector<double>(13, 0.0)}, false},
      {"1920x1080 wide", {{1920, 1080}, {1400, 0, 960, 0, 1400, 540, 0, 0, 1}, {-0.3, 0.1, 0, 0, 0}}, true},
  };
  for (Case c : cases) {
    if (c.camera.distortion.size() == 13) c.camera.distortion.push_back(1e12);
    LabOptions o;
    o.detectors = {"arwb"};
    o.camera = c.camera;
    const Result<LabResults> r = run_lab(one_cell(4), o);
    ASSERT_TRUE(r.ok()) << c.what << ": " << r.error();
    ASSERT_EQ(r->cells.size(), 1u) << c.what;
    if (c.sees) {
      EXPECT_GT(r->cells[0].detectors[0].frames, 0) << c.what;
    }
  }
}

TEST(LabRun, TheSameSeedGivesTheSameTableAndAnotherSeedAnother) {
  LabPlan p = one_cell(6);
  p.distances_m = {1, 2};
  LabOptions o;
  o.detectors = {"arwb", "opencv"};
  const auto a = run_lab(p, o), b = run_lab(p, o);
  ASSERT_TRUE(a && b);
  // Times differ run to run; everything before the median time does not.
  auto strip = [](const std::string& csv) {
    std::string out;
    std::stringstream in(csv);
    for (std::string line; std::getline(in, line);) out += line.substr(0, line.rfind(',')) + "\n";
    return out;
  };
  EXPECT_EQ(strip(lab_table_csv(*a)), strip(lab_table_csv(*b)));
  EXPECT_EQ(a->ids, b->ids);
  o.seed = 2;
  const auto c = run_lab(p, o);
  ASSERT_TRUE(c);
  EXPECT_NE(a->ids, c->ids);
}

TEST(LabRun, AnyThreadCountAndAResumedRunGiveTheSameTable) {
  LabPlan p = one_cell(8);
  p.distances_m = {1, 2};
  p.lux = {1000, 500};
  LabOptions o;
  o.detectors = {"arwb", "opencv"};
  auto strip = [](const std::string& csv) {   // everything but the times
    std::string out;
    std::stringstream in(csv);
    for (std::string line; std::getline(in, line);) out += line.substr(0, line.rfind(',')) + "\n";
    return out;
  };
  std::vector<std::string> lines;
  const std::string key = lab_run_key(p, o);
  o.on_cell = [&](size_t i, const CellResult& c) { lines.push_back(cell_to_line(key, i, c)); };
  const auto one = run_lab(p, o);
  ASSERT_TRUE(one) << one.error();
  ASSERT_EQ(lines.size(), 4u);
  o.threads = 2;
  o.on_cell = {};
  const auto two = run_lab(p, o);
  ASSERT_TRUE(two);
  EXPECT_EQ(strip(lab_table_csv(*one)), strip(lab_table_csv(*two)));
  // Interrupted after two cells: those are read back and the other two run again; the table is the same, with
  // the saved cells' times as they were.
  o.threads = 1;
  o.finished.resize(4);
  for (size_t i = 0; i < 2; ++i) {
    auto c = cell_from_line(key, lines[i], o.detectors.size());
    ASSERT_TRUE(c);
    o.finished[c->first] = std::make_shared<const CellResult>(c->second);
  }
  int calls = 0;
  o.on_cell = [&](size_t, const CellResult&) { ++calls; };
  const auto resumed = run_lab(p, o);
  ASSERT_TRUE(resumed);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(strip(lab_table_csv(*one)), strip(lab_table_csv(*resumed)));
  EXPECT_EQ(resumed->cells[0].detectors[0].ms, one->cells[0].detectors[0].ms);
  // Its time is this run's and all its cells': the saved cells' own times are read back.
  EXPECT_EQ(resumed->resumed, 2);
  EXPECT_EQ(resumed->cells[0].seconds, one->cells[0].seconds);
  double all = 0;
  for (const CellResult& c : resumed->cells) all += c.seconds;
  char said[160];
  std::snprintf(said, sizeof said, " here; all its cells took %.1f s (2 of 4 from an earlier run)", all);
  EXPECT_NE(lab_time_text(*resumed).find(said), std::string::npos) << lab_time_text(*resumed);
  EXPECT_GT(all, resumed->seconds);
  EXPECT_EQ(lab_time_text(*one).find("earlier"), std::string::npos) << lab_time_text(*one);
  // A saved cell without its time (an older arwb's) is still taken; the time says it is not recorded.
  std::string old_line = lines[0];
  const size_t at = old_line.find(",\"seconds\":");
  ASSERT_NE(at, std::string::npos);
  old_line.erase(at, old_line.find(',', at + 1) - at);
  auto old = cell_from_line(key, old_line, o.detectors.size());
  ASSERT_TRUE(old) << old_line;
  o.finished[old->first] = std::make_shared<const CellResult>(old->second);
  const auto older = run_lab(p, o);
  ASSERT_TRUE(older);
  EXPECT_NE(lab_time_text(*older).find("2 of 4 cells from an earlier run, time not recorded"),
            std::string::npos) << lab_time_text(*older);
  // A saved cell of another plan or seed, or a line cut short, is not taken.
  LabOptions other = o;
  other.seed = 9;
  EXPECT_FALSE(cell_from_line(lab_run_key(p, other), lines[0], o.detectors.size()));
  EXPECT_FALSE(cell_from_line(key, lines[0].substr(0, lines[0].size() / 2), o.detectors.size()));
  EXPECT_FALSE(cell_from_line(key, lines[0], 3));
}

TEST(LabRun, DetectorsThatCannotRunAreNamed) {
  LabOptions o;
  o.detectors = {"arwb", "yolo"};
  auto r = run_lab(one_cell(1), o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("unknown detector 'yolo' (arwb, opencv, opencv-aruco3, apriltag)"), std::string::npos)
      << r.error();
  o.detectors = {"apriltag"};
  r = run_lab(one_cell(1), o);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error(), "apriltag reads the AprilTag families, not ARUCO_ORIGINAL");
}

// The paper's plan's frame `frame` of cell `cell`, as the run renders it, or an empty image when that is not one
// of the frames without a marker.
cv::Mat paper_empty_frame(size_t cell, int frame) {
  const LabPlan plan = paper_plan();
  const LabOptions o;
  LabCellSource src(plan, o, lab_marker_ids(plan, o.seed), cell, frame);
  cv::Mat img;
  src.next(0, img);
  return src.frame().empty ? img : cv::Mat();
}

}  // namespace
// The paper's plan, cell 25 (26 mm at 0.5 m, 850 lx), frame 438: an empty frame with a checkerboard patch whose
// squares touch at their corners. With cut_thin_lines a 51x17 px sliver across one row of it was cut from them as
// a quad with a line's stub and read as ARUCO_ORIGINAL 1023; a quad cut from thin lines must not be that thin.
TEST(LabRun, ACheckerboardsRowIsNotAMarkerWithAStub) {
  const cv::Mat img = paper_empty_frame(25, 438);
  ASSERT_FALSE(img.empty()) << "one of the cell's frames without a marker";
  const std::vector<Marker> found = Detector({*dictionary_by_name("ARUCO_ORIGINAL")}).detect(img);
  EXPECT_TRUE(found.empty()) << found.size() << " markers, the first " << found[0].id;
}

// The paper's plan, cell 21 (26 mm at 1 m, 1000 lx), frame 432: an empty frame with a rectangle drawn in outline and
// crossed by a thin line. Cut from the line, the outline's quad read as ARUCO_ORIGINAL 341 (the line darkens cells
// inside it) with white border cells; a quad cut from thin lines is read only with a wholly black border.
TEST(LabRun, AnOutlinedRectangleCrossedByALineIsNotAMarker) {
  const cv::Mat img = paper_empty_frame(21, 432);
  ASSERT_FALSE(img.empty()) << "one of the cell's frames without a marker";
  FrameTrace t;
  const std::vector<Marker> found = Detector({*dictionary_by_name("ARUCO_ORIGINAL")}).detect(img, &t);
  EXPECT_TRUE(found.empty()) << found.size() << " markers, the first " << found[0].id;
  bool refused = false;
  for (const auto& c : t.candidates)
    refused = refused ||
              (c.fate.stage == Stage::border_check && c.fate.message.find("cut_thin_lines") != std::string::npos);
  EXPECT_TRUE(refused) << "border_check turned the cut quad down";
}

// Empty frames that bit_grid's local thresholds once read as markers, from the paper's plan: cell 19 (26 mm at 2 m,
// 850 lx) frame 420, a tall rectangle drawn in outline whose border cells along the short sides are dark only
// along their outer edge (their mean against the quiet zone read them black: ARUCO_ORIGINAL 1023), and cell 7
// (65 mm at 0.5 m, 850 lx) frame 444 and cell 23 (26 mm at 1 m, 500 lx) frame 471, a square outlined in white and a
// light line across a gradient, whose quads the patch read as a stripe (ARUCO_ORIGINAL 0).
TEST(LabRun, OutlinesAndLightLinesAreNotMarkersWithLocalThresholds) {
  for (const auto& [cell, frame] : std::vector<std::pair<size_t, int>>{{19, 420}, {7, 444}, {23, 471}}) {
    SCOPED_TRACE("cell " + std::to_string(cell) + ", frame " + std::to_string(frame));
    const cv::Mat img = paper_empty_frame(cell, frame);
    ASSERT_FALSE(img.empty()) << "one of the cell's frames without a marker";
    const std::vector<Marker> found = Detector({*dictionary_by_name("ARUCO_ORIGINAL")}).detect(img);
    EXPECT_TRUE(found.empty()) << found.size() << " markers, the first " << found[0].id;
  }
}

}  // namespace arwb::lab
