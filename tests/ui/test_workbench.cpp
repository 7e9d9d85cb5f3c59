// The workbench window, run for real under xvfb-run (Mesa's software OpenGL): what a person sees in the
// screenshot, the --stats line, switching panels and sources, surviving sources that fail, the layout kept
// between runs, snapshots, the "why not detected" sweep and the teaching tour.
#include "detect/dictionary.hpp"
#include "synth/synth.hpp"
#include "detect/trace.hpp"
#include "support/support.hpp"
#include "support/window.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <filesystem>
#include <regex>
#include <string>

#include <sys/stat.h>

namespace arwb {
namespace {

namespace fs = std::filesystem;
using test::RunResult;
using test::TempDir;

// The live view's outline colour for accepted markers (ui/widgets.cpp accepted_colour: 0.1, 1.0, 0.2).
bool accepted_green(const cv::Vec3b& bgr) { return bgr[1] > 225 && bgr[2] < 90 && bgr[0] < 110; }

// Green outline pixels inside a screen rectangle of the screenshot.
int green_pixels(const cv::Mat& shot, cv::Rect area) {
  area &= cv::Rect(0, 0, shot.cols, shot.rows);
  int n = 0;
  for (int y = area.y; y < area.br().y; ++y)
    for (int x = area.x; x < area.br().x; ++x) n += accepted_green(shot.at<cv::Vec3b>(y, x));
  return n;
}

using test::kLiveView;
using test::stats;

// A number of the --stats line (`group` names an object in it: "stages"), or -1 when it is missing.
double stat(const std::string& out, const std::string& key, const std::string& group = "") {
  const nlohmann::json s = stats(out);
  const nlohmann::json* in = &s;
  if (!group.empty()) in = s.is_object() && s.contains(group) ? &s[group] : nullptr;
  if (!in || !in->is_object() || !in->contains(key) || !(*in)[key].is_number()) return -1;
  return (*in)[key].get<double>();
}

// A string of the --stats line, or "" when it is missing.
std::string stat_text(const std::string& out, const std::string& key) {
  const nlohmann::json s = stats(out);
  return s.is_object() && s.contains(key) && s[key].is_string() ? s[key].get<std::string>() : "";
}

// A 640x480 photo-like image with ARUCO_ORIGINAL marker `id` in the middle, `side` px wide.
cv::Mat marker_image(int id, double side, int background = 170, int black = 0) {
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar::all(background));
  const Dictionary d = make_aruco_original();
  draw_marker(img, d, id, project_square({320, 240}, side, 12, 10, 0, 800), 1.0, 4, black, 255);
  return img;
}

using test::window_args;

TEST(Workbench, ScreenshotShowsTheSyntheticMarkersOutlined) {
  TempDir tmp;
  const RunResult r =
      test::run_arwb_window(window_args(tmp, "--frames 60 --screenshot '" + tmp.str("shot.png") + "' --stats"));
  ASSERT_EQ(r.status, 0) << r.err;
  const cv::Mat shot = cv::imread(tmp.str("shot.png"));
  ASSERT_FALSE(shot.empty()) << "no screenshot";
  EXPECT_EQ(shot.size(), cv::Size(1600, 900));
  EXPECT_GE(stat(r.out, "markers"), 1) << r.out;
  // The accepted markers' outlines are drawn in the live view, and nowhere else in this layout.
  EXPECT_GT(green_pixels(shot, kLiveView), 300) << r.out;
}

TEST(Workbench, NoOutlineWhenThereIsNoMarker) {
  TempDir tmp;
  cv::imwrite(tmp.str("blank.png"), cv::Mat(480, 640, CV_8UC3, cv::Scalar(120, 140, 160)));
  const RunResult r = test::run_arwb_window(window_args(
      tmp, "--source '" + tmp.str("blank.png") + "' --frames 40 --screenshot '" + tmp.str("shot.png") + "' --stats"));
  ASSERT_EQ(r.status, 0) << r.err;
  const cv::Mat shot = cv::imread(tmp.str("shot.png"));
  ASSERT_FALSE(shot.empty());
  EXPECT_EQ(stat(r.out, "markers"), 0) << r.out;
  EXPECT_LT(green_pixels(shot, kLiveView), 20);
}

TEST(Workbench, StatsLineHasTheFramesRatesAndEveryStage) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(window_args(tmp, "--frames 45 --stats"));
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(r.out.front(), '{') << r.out;
  EXPECT_EQ(stat(r.out, "frames"), 45);
  EXPECT_GT(stat(r.out, "ui_fps"), 0);
  EXPECT_GT(stat(r.out, "detect_fps"), 0);
  EXPECT_GT(stat(r.out, "detected"), 0);
  for (int i = 0; i < kStageCount; ++i) {
    const std::string name(stage_name(static_cast<Stage>(i)));
    EXPECT_GE(stat(r.out, name, "stages"), 0) << name << " missing in " << r.out;
  }
  EXPECT_EQ(stat_text(r.out, "source"), "synthetic");
}

TEST(Workbench, SwitchesPanelsAndSourcesWhileRunning) {
  TempDir tmp;
  cv::imwrite(tmp.str("one.png"), marker_image(37, 160));
  fs::create_directories(tmp.str("folder"));
  cv::imwrite(tmp.str("folder/a.png"), marker_image(5, 120));
  cv::imwrite(tmp.str("folder/b.png"), marker_image(6, 140));
  {
    cv::VideoWriter w(tmp.str("clip.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20, {640, 480});
    ASSERT_TRUE(w.isOpened());
    for (int i = 0; i < 30; ++i) w.write(marker_image(9, 100 + 2 * i));
  }
  // Each source waited for before the next: the worker takes only the newest source asked for meanwhile.
  const std::string actions = "5:open=all;10:source=" + tmp.str("one.png") + ";10:source_wait;35:stage=otsu;40:source=" +
                              tmp.str("folder") + ";40:source_wait;70:close=all;71:open=live_view;75:source=" +
                              tmp.str("clip.avi") + ";75:source_wait;90:freeze;95:next;100:next";
  const RunResult r = test::run_arwb_window(window_args(
      tmp, "--frames 110 --verbose --stats --screenshot '" + tmp.str("shot.png") + "' --actions '" + actions + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("source: " + tmp.str("one.png")), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("source: " + tmp.str("folder")), std::string::npos) << r.err;
  EXPECT_EQ(stat_text(r.out, "source"), tmp.str("clip.avi")) << r.out;
  EXPECT_EQ(stat(r.out, "problems"), 0) << r.err;
  EXPECT_EQ(stat(r.out, "markers"), 1) << r.out;   // the video's marker, id 9
  // The live view's label and the Source panel's slider name the same frame of the video.
  EXPECT_EQ(stat_text(r.out, "frame_label"), "frame " + std::to_string(int(stat(r.out, "source_position")))) << r.out;
  EXPECT_EQ(stat_text(r.out, "working_size"), "640x480") << r.out;
  EXPECT_GT(green_pixels(cv::imread(tmp.str("shot.png")), kLiveView), 100);
}

TEST(Workbench, SurvivesSourcesThatFail) {
  TempDir tmp;
  // A file that looks like an MP4 but is not one, a folder with a corrupt image, a camera that is not there.
  test::write_file(tmp.str("broken.mp4"), std::string("\0\0\0\x18" "ftypmp42", 12) + std::string(4000, 'x'));
  fs::create_directories(tmp.str("folder"));
  cv::imwrite(tmp.str("folder/a.png"), marker_image(5, 120));
  test::write_file(tmp.str("folder/b.png"), "\x89PNG\r\n\x1a\n garbage");
  const std::string actions = "5:source=" + tmp.str("missing.mp4") + ";10:source=" + tmp.str("broken.mp4") +
                              ";15:source=camera:97;20:source=" + tmp.str("folder") + ";25:next";
  const RunResult r = test::run_arwb_window(window_args(
      tmp, "--frames 120 --stats --screenshot '" + tmp.str("shot.png") + "' --actions '" + actions + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("missing.mp4"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("broken.mp4"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("camera:97"), std::string::npos) << r.err;
  EXPECT_GE(stat(r.out, "problems"), 3) << r.out;
  // Still running and detecting: the folder's good image is shown.
  EXPECT_EQ(stat_text(r.out, "source"), tmp.str("folder")) << r.out;
  EXPECT_FALSE(cv::imread(tmp.str("shot.png")).empty());
}

TEST(Workbench, FallsBackToTheSyntheticSceneWhenTheSourceCannotOpen) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(window_args(tmp, "--source camera:97 --frames 40 --stats"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("camera:97"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("synthetic"), std::string::npos) << r.err;
  EXPECT_EQ(stat_text(r.out, "source"), "synthetic");
  EXPECT_GE(stat(r.out, "markers"), 1);
}

TEST(Workbench, KeepsTheLayoutBetweenRuns) {
  TempDir tmp;
  RunResult r = test::run_arwb_window(window_args(tmp, "--frames 20 --actions '5:close=timings;6:open=dictionary'"));
  ASSERT_EQ(r.status, 0) << r.err;
  std::string file = test::read_file(tmp.str("config/workspaces.json"));
  EXPECT_NE(file.find("\"live_view\""), std::string::npos) << file;
  EXPECT_EQ(file.find("\"timings\""), file.rfind("\"timings\"")) << file;   // left in the presentation tree only
  // A second run without actions starts from that layout and keeps it.
  r = test::run_arwb_window(window_args(tmp, "--frames 10 --stats"));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json l = stats(r.out)["layout"];
  const std::string regions = l["regions"].dump();
  EXPECT_EQ(regions.find("timings"), std::string::npos) << regions;
  EXPECT_NE(regions.find("dictionary"), std::string::npos) << regions;
}

TEST(Workbench, SnapshotSavesTheFrameEveryStageAndTheTrace) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(window_args(tmp, "--frames 40 --actions '30:snapshot'"));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(tmp.str("snaps"))) dirs.push_back(e.path());
  ASSERT_EQ(dirs.size(), 1u);
  EXPECT_TRUE(fs::exists(dirs[0] / "frame.png"));
  const auto trace = nlohmann::json::parse(test::read_file((dirs[0] / "trace.json").string()), nullptr, false);
  ASSERT_TRUE(trace.is_object());
  EXPECT_TRUE(std::any_of(trace["stages"].begin(), trace["stages"].end(),
                          [](const nlohmann::json& s) { return s["name"] == "adaptive_threshold"; }));
  for (int i = 0; i < kStageCount; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "%02d_%s.png", i, std::string(stage_name(static_cast<Stage>(i))).c_str());
    EXPECT_TRUE(fs::exists(dirs[0] / name)) << name;
  }
}

TEST(Workbench, WhyNotDetectedFindsTheParameterToChange) {
  TempDir tmp;
  // A faint marker (black printed at 120 on a 170 page) with a threshold offset too high to see it.
  cv::imwrite(tmp.str("faint.png"), marker_image(12, 150, 170, 120));
  test::write_file(tmp.str("strict.yml"), "threshold_offset: 60\n");
  const RunResult r = test::run_arwb_window(
      window_args(tmp, "--source '" + tmp.str("faint.png") + "' --params '" + tmp.str("strict.yml") +
                           "' --frames 200 --verbose --stats --actions '5:region=220,140,200,200;6:sweep'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(stat(r.out, "markers"), 0) << r.out;
  // The smallest change relative to each parameter's range; which parameter wins is the sweep's call.
  EXPECT_TRUE(std::regex_search(r.err, std::regex("sweep: [a-z_]+ [0-9.]+ -> [0-9.]+.* finds ARUCO_ORIGINAL id 12")))
      << r.err;
}

TEST(Workbench, BadPresetIsReportedAndTheWorkbenchGoesOn) {
  TempDir tmp;
  test::write_file(tmp.str("bad.yml"), "threshold_offset: 7\nno_such_param: 3\nmin_perimeter_px: -5\n");
  const RunResult r = test::run_arwb_window(
      window_args(tmp, "--frames 40 --stats --actions '5:preset=" + tmp.str("bad.yml") + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("no_such_param"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad.yml"), std::string::npos) << r.err;
  EXPECT_GE(stat(r.out, "markers"), 1) << r.out;   // the parameters were left as they were
}

// A preset nested 40,000 deep crashed the workbench in OpenCV's YAML parser; a FIFO as a preset froze it.
TEST(Workbench, HostilePresetsAreRefusedByNameAndTheWorkbenchGoesOn) {
  TempDir tmp;
  test::write_file(tmp.str("deep.yml"), "threshold_offset: 7\nx: " + std::string(40000, '[') + "\n");
  ASSERT_EQ(::mkfifo(tmp.str("fifo.yml").c_str(), 0600), 0);
  const RunResult r = test::run_arwb_window(window_args(
      tmp, "--frames 40 --stats --actions '5:preset=" + tmp.str("deep.yml") + ";6:preset=" + tmp.str("fifo.yml") + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("preset: " + tmp.str("deep.yml") + ":2: nested deeper than 32 levels"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("preset: " + tmp.str("fifo.yml") + ": not a regular file (a FIFO)"), std::string::npos) << r.err;
  EXPECT_GE(stat(r.out, "markers"), 1) << r.out;
}

// ImGui read its layout file with fopen: a FIFO in its place kept the window from opening, and writing it at
// quit waited for a reader. Both are refused by name and the workbench runs and quits.
TEST(Workbench, AFifoAsTheLayoutFileNeitherBlocksStartNorQuit) {
  TempDir tmp;
  std::filesystem::create_directories(tmp.str("config"));
  ASSERT_EQ(::mkfifo(tmp.str("config/imgui.ini").c_str(), 0600), 0);
  const RunResult r = test::run_arwb_window(window_args(tmp, "--frames 5 --stats"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find(tmp.str("config/imgui.ini") + ": not a regular file (a FIFO) (the default layout is used; "),
            std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the layout is not saved"), std::string::npos) << r.err;
}

TEST(Workbench, TourAndPresentationModeRun) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(
      window_args(tmp, "--frames 40 --stats --screenshot '" + tmp.str("shot.png") +
                           "' --actions '5:tour=4;6:presentation;7:fullscreen=on;10:tour=otsu;12:tour=otsuu;13:tour=99'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("tour:"), std::string::npos) << r.err;   // the shipped tour loads cleanly
  EXPECT_FALSE(cv::imread(tmp.str("shot.png")).empty());
  // A step by its name; a name or number the tour does not have is said, and the step shown stays.
  EXPECT_EQ(stat_text(r.out, "tour_step"), "otsu") << r.out;
  EXPECT_NE(r.err.find("tour=otsuu: no step of that name; the steps are overview, acquisition, "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("tour=99: the tour has "), std::string::npos) << r.err;
  EXPECT_EQ(stats(r.out)["fullscreen"], true) << r.out;
}

TEST(Workbench, BrokenTourFileIsReportedWithItsLine) {
  TempDir tmp;
  test::write_file(tmp.str("tour.txt"), "[overview]\ntitle: Hello\nText.\n\n[otsuu]\ntitle: x\ny\n");
  const RunResult r = test::run_arwb_window(
      window_args(tmp, "--frames 10 --tour '" + tmp.str("tour.txt") + "' --actions '2:tour'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("tour.txt:5:"), std::string::npos) << r.err;
}

TEST(Workbench, BadOptionsAreOneLineErrors) {
  TempDir tmp;
  RunResult r = test::run_arwb(window_args(tmp, "--frames many"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--frames"), std::string::npos) << r.err;
  r = test::run_arwb(window_args(tmp, "--source /no/such/file.mp4"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("/no/such/file.mp4"), std::string::npos) << r.err;
  r = test::run_arwb(window_args(tmp, "--actions '5:explode'"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("explode"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arwb
