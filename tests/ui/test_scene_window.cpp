// Scenes in the real workbench window (xvfb-run, Mesa): the media composited onto the live view, switched off
// and on, and a click on a web card opening the URL through the opener (a recorder here, never a shell).
#include "support/support.hpp"
#include "support/samples.hpp"
#include "support/window.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <chrono>
#include <filesystem>
#include <thread>

namespace arwb {
namespace {

using test::RunResult;
using test::TempDir;
using test::write_file;

using test::kLiveView;
using test::kSample;

int magenta_pixels(const cv::Mat& shot, cv::Rect area) {
  area &= cv::Rect(0, 0, shot.cols, shot.rows);
  int n = 0;
  for (int y = area.y; y < area.br().y; ++y)
    for (int x = area.x; x < area.br().x; ++x) {
      const cv::Vec3b p = shot.at<cv::Vec3b>(y, x);
      n += p[0] > 220 && p[2] > 220 && p[1] < 40;
    }
  return n;
}

using test::window_args;

TEST(SceneWindow, MediaAreProjectedOnTheLiveViewAndCanBeHidden) {
  TempDir tmp;
  cv::imwrite(tmp.str("magenta.png"), cv::Mat(64, 64, CV_8UC3, cv::Scalar(255, 0, 255)));
  write_file(tmp.str("scene.lua"),
             "marker({from = 843, to = 950}, { media = image \"magenta.png\", place = on_marker { fit = \"stretch\" } })\n");
  const std::string common = "--source '" + kSample + "' --scene '" + tmp.str("scene.lua") + "' --frames 40 --stats";
  RunResult r = test::run_arwb_window(window_args(tmp, common + " --screenshot '" + tmp.str("on.png") + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto stats = test::stats(r);
  ASSERT_TRUE(stats.is_object()) << r.out;
  EXPECT_EQ(stats["scene_ok"], true) << r.out;
  EXPECT_EQ(stats["overlays"], 2) << r.out;
  const cv::Mat on = cv::imread(tmp.str("on.png"));
  ASSERT_FALSE(on.empty());
  // Two markers of about 40 and 55 px in a 640x480 frame shown ~560 px wide: a thousand media pixels or more.
  EXPECT_GT(magenta_pixels(on, kLiveView), 1000);

  r = test::run_arwb_window(
      window_args(tmp, common + " --screenshot '" + tmp.str("off.png") + "' --actions '0:media=off'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(magenta_pixels(cv::imread(tmp.str("off.png")), kLiveView), 0);
}

TEST(SceneWindow, ClickingAWebCardOpensItsUrlAsOneArgument) {
  TempDir tmp;
  // The opener records its arguments, one per line; a shell would have run the $(...) or split at the ;.
  write_file(tmp.str("opener.sh"), "#!/bin/sh\nfor a in \"$@\"; do printf '%s\\n' \"$a\" >> '" + tmp.str("opened.txt") + "'; done\n");
  std::filesystem::permissions(tmp.str("opener.sh"), std::filesystem::perms::owner_all);
  const std::string url = "https://example.org/a?b=1;c=$(touch%20x)";
  write_file(tmp.str("scene.lua"), "marker(950, { media = web \"" + url + "\", place = on_marker { fit = \"stretch\" } })\n");
  setenv("ARWB_URL_OPENER", tmp.str("opener.sh").c_str(), 1);
  // Marker 950's centre in the sample image is near (281, 340).
  const RunResult r = test::run_arwb_window(window_args(
      tmp, "--source '" + kSample + "' --scene '" + tmp.str("scene.lua") + "' --frames 60 --actions '30:click=281,340'"));
  unsetenv("ARWB_URL_OPENER");
  ASSERT_EQ(r.status, 0) << r.err;
  // The opener runs detached; give it a moment.
  std::string opened;
  for (int i = 0; i < 50 && opened.empty(); ++i) {
    opened = test::read_file(tmp.str("opened.txt"));
    if (opened.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(opened, url + "\n");

  // A click beside the card opens nothing.
  const RunResult miss = test::run_arwb_window(window_args(
      tmp, "--source '" + kSample + "' --scene '" + tmp.str("scene.lua") + "' --frames 40 --actions '20:click=600,40'"));
  ASSERT_EQ(miss.status, 0) << miss.err;
  EXPECT_EQ(test::read_file(tmp.str("opened.txt")), url + "\n");
}

}  // namespace
}  // namespace arwb
