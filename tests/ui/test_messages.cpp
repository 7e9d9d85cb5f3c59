// Messages that reach the user, in the real window (xvfb-run, Mesa): "Why not detected?" on a real photograph of
// 6X6_250 markers names the dictionary and its button's action finds them; a scene's skipped mapping and its
// runtime error show in the Scene panel's rows (--stats scene_mappings), the Log's error count and the status bar.
#include "support/support.hpp"
#include "support/samples.hpp"
#include "support/window.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <string>

namespace arwb {
namespace {

using test::RunResult;
using test::TempDir;
using test::write_file;

// OpenCV's tutorial photograph (Debian's opencv-doc, third_party/setup): 640x480, six DICT_6X6_250 markers, ids
// 23, 40, 62, 98, 124, 203; marker 23's corners lie about (297,185)-(335,212).
const std::string kPhoto = "/usr/share/doc/opencv-doc/opencv4/html/singlemarkersoriginal.jpg";
using test::kSample;
using test::stats;
using test::window_args;

// The status bar's red text (1, 0.35, 0.3) along the window's bottom 30 px.
int status_bar_red(const cv::Mat& shot) {
  int n = 0;
  for (int y = std::max(0, shot.rows - 30); y < shot.rows; ++y)
    for (int x = 0; x < shot.cols; ++x) {
      const cv::Vec3b p = shot.at<cv::Vec3b>(y, x);
      n += p[2] > 200 && p[1] > 60 && p[1] < 120 && p[0] > 50 && p[0] < 110;
    }
  return n;
}

TEST(Messages, WhyNamesTheDictionaryOfAPhotographedMarkerAndAddingItDetectsThem) {
  TempDir tmp;
  const std::string common = "--source '" + kPhoto + "' --frames 50 --stats --actions '5:region=290,178,52,42";
  RunResult r = test::run_arwb_window(window_args(tmp, common + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json s = stats(r);
  EXPECT_EQ(s["markers"], 0) << r.out;   // ARUCO_ORIGINAL, the default, finds none
  ASSERT_TRUE(s.contains("why")) << r.out;
  EXPECT_EQ(s["why"]["other_dictionary"], "6X6_250") << r.out;
  EXPECT_EQ(s["why"]["other_id"], 23) << r.out;
  const std::string summary = s["why"]["summary"];
  EXPECT_EQ(summary.rfind("This is a 6X6_250 marker, id 23", 0), 0u) << summary;
  EXPECT_EQ(summary.find("would let it through"), std::string::npos) << summary;   // no parameter advice

  // The panel's button: the dictionary is searched too, and the six markers are found.
  r = test::run_arwb_window(window_args(tmp, common + ";20:add_dictionary=6X6_250'"));
  ASSERT_EQ(r.status, 0) << r.err;
  s = stats(r);
  EXPECT_EQ(s["markers"], 6) << r.out;
  EXPECT_EQ(s["why"]["dictionaries"], nlohmann::json({"ARUCO_ORIGINAL", "6X6_250"})) << r.out;
  EXPECT_FALSE(s["why"].contains("other_dictionary")) << r.out;
  EXPECT_NE(s["why"]["summary"].get<std::string>().find("6X6_250 id 23 is detected here"), std::string::npos) << r.out;
}

TEST(Messages, AScenesMissingMediaFileKeepsItsRowAndReachesTheLogAndStatusBar) {
  TempDir tmp;
  write_file(tmp.str("scene.lua"), "marker(843, { media = image \"logo.png\" })\n"
                                   "marker(950, { media = text \"hello\" })\n");
  RunResult r = test::run_arwb_window(window_args(
      tmp, "--source '" + kSample + "' --scene '" + tmp.str("scene.lua") + "' --frames 40 --stats --screenshot '" +
               tmp.str("shot.png") + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json s = stats(r);
  EXPECT_EQ(s["scene_ok"], true) << r.out;
  ASSERT_EQ(s["scene_mappings"].size(), 2u) << r.out;
  const auto& bad = s["scene_mappings"][0];
  EXPECT_EQ(bad["ids"], "843");
  EXPECT_EQ(bad["health"], "skipped");
  EXPECT_EQ(bad["line"], 1);
  EXPECT_NE(bad["reason"].get<std::string>().find("logo.png: no such file"), std::string::npos) << r.out;
  EXPECT_EQ(s["scene_mappings"][1]["health"], "ok");
  EXPECT_EQ(s["overlays"], 1) << r.out;
  EXPECT_EQ(s["log_errors"], 1) << r.out;   // once, not once a frame
  EXPECT_GE(s["problems"].get<int>(), 1) << r.out;
  // The status bar keeps saying so in red.
  EXPECT_GT(status_bar_red(cv::imread(tmp.str("shot.png"))), 200);
}

TEST(Messages, AScenesRuntimeErrorMarksItsRowWithTheFailingLineAndReachesTheLog) {
  TempDir tmp;
  write_file(tmp.str("scene.lua"), "marker(843, { media = text \"fine\" })\n"
                                   "marker(950, {\n"
                                   "  media = text \"hi\",\n"
                                   "  on_update = function(m, dt)\n"
                                   "    local t = nil\n"
                                   "    return t.field\n"
                                   "  end,\n"
                                   "})\n");
  // A still image is detected once: the error is on that frame.
  RunResult r = test::run_arwb_window(window_args(
      tmp, "--source '" + kSample + "' --scene '" + tmp.str("scene.lua") + "' --frames 40 --stats --screenshot '" +
               tmp.str("shot.png") + "' --actions '2:open=script'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json s = stats(r);
  ASSERT_EQ(s["scene_mappings"].size(), 2u) << r.out;
  EXPECT_EQ(s["scene_mappings"][0]["health"], "ok");
  const auto& bad = s["scene_mappings"][1];
  EXPECT_EQ(bad["health"], "error") << r.out;
  EXPECT_EQ(bad["line"], 6) << r.out;   // the failing statement, the line the editor marks
  EXPECT_NE(bad["reason"].get<std::string>().find("attempt to index a nil value"), std::string::npos) << r.out;
  EXPECT_GE(s["log_errors"].get<int>(), 1) << r.out;
  EXPECT_GT(status_bar_red(cv::imread(tmp.str("shot.png"))), 200);
}

}  // namespace
}  // namespace arwb
