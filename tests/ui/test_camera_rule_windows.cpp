// One rule for the camera (calibration/camera_rule.hpp), in the window's consumers: the workbench with the
// camera loaded and its undistorted view shown, and a bundle exported with it played. Each extreme camera the
// reader accepts runs to the end with no problem logged. The command-line consumers: tests/cli/test_camera_rule.cpp.
#include "support/extreme_cameras.hpp"
#include "support/samples.hpp"
#include "support/support.hpp"
#include "support/window.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

namespace arwb {
namespace {

using test::q;
using test::TempDir;

TEST(CameraRuleWindows, EveryExtremeTheReaderAcceptsRunsInTheWorkbenchAndThePlayer) {
  TempDir d;
  test::write_file(d.str("scene.lua"), "marker(843, { media = text \"843\", place = on_marker {} })\n");
  for (const test::ExtremeCamera& c : test::extreme_cameras()) {
    const std::string calib = test::write_extreme_camera(d, c), name = c.name;
    auto r = test::run_arwb_window(test::window_args(d, "--source " + q(test::kSample) + " --calib " + q(calib) +
                                                            " --frames 20 --stats --actions '1:workspace=Calibrate;2:undistort=on'"));
    ASSERT_EQ(r.status, 0) << name << ": " << r.err;
    const nlohmann::json s = test::stats(r);
    EXPECT_EQ(s["problems"], 0) << name << ": " << r.err;
    EXPECT_NE(s["calibration"]["loaded"].get<std::string>().find(name), std::string::npos) << s.dump();
    r = test::run_arwb("export --scene " + q(d.str("scene.lua")) + " --calib " + q(calib) + " --out " +
                       q(d.str(name + ".arwb")));
    if (r.status != 0) continue;   // a refused self-test is the command-line test's to judge
    r = test::run_arwb_window("play " + q(d.str(name + ".arwb")) + " --source " + q(test::kSample) + " --frames 4 --stats");
    EXPECT_EQ(r.status, 0) << name << ": " << r.err;
  }
}

}  // namespace
}  // namespace arwb
