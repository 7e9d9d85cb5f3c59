// File > Export...'s Serve, in a real window (xvfb-run, Mesa): the bundle just written with its phone page is
// served on 127.0.0.1, the dialog shows its address as a QR code a phone can read (read back from the screenshot
// by ZBar), Stop serving stops it; a bundle written without the page is not served, and the dialog says why.
#include "support/qr_reader.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <regex>
#include <string>

namespace arwb {
namespace {

using test::RunResult;
using test::TempDir;

const std::string kMuseum = std::string(ARWB_SOURCE_DIR) + "/scripts/museum/museum.lua";

std::string serve_window_args(const TempDir& tmp, const std::string& actions) {
  return "--verbose --config-dir '" + tmp.str("config") + "' --source synthetic --scene '" + kMuseum +
         "' --frames 40 --stats --screenshot '" + tmp.str("dialog.png") + "' --actions '" + actions + "'";
}

TEST(WorkbenchServe, TheDialogServesTheBundleWrittenAndShowsItsAddressAsAQrCode) {
  TempDir tmp;
  const std::string out = tmp.str("museum-web");
  RunResult r = test::run_arwb_window(serve_window_args(
      tmp, "3:export_dialog=" + out + ";4:export_web=on;5:answer=export;6:export_wait;8:serve=on;9:export_wait"));
  ASSERT_EQ(r.status, 0) << r.err;
  auto stats = test::stats(r);
  const std::string url = stats["export"]["serving"].get<std::string>();
  EXPECT_TRUE(std::regex_match(url, std::regex(R"(http://127\.0\.0\.1:[0-9]+/)"))) << stats["export"].dump();
  EXPECT_EQ(stats["export"]["serve_error"], "");
  EXPECT_NE(r.err.find("serve: " + out + " at " + url), std::string::npos) << r.err;
  // What a phone's camera would read off the screen.
  EXPECT_EQ(test::read_qr(cv::imread(tmp.str("dialog.png"))), url);

  // Stopped: no address any more, and the log says after how many requests.
  r = test::run_arwb_window(serve_window_args(
      tmp, "3:export_dialog=" + out + ";3:export_force=on;4:export_web=on;5:answer=export;6:export_wait;8:serve=on;"
           "9:export_wait;12:serve=off"));
  ASSERT_EQ(r.status, 0) << r.err;
  stats = test::stats(r);
  EXPECT_EQ(stats["export"]["serving"], "") << stats["export"].dump();
  EXPECT_NE(r.err.find("serve: stopped serving http://127.0.0.1:"), std::string::npos) << r.err;
}

TEST(WorkbenchServe, ABundleWithoutThePhonePageIsNotServedAndTheDialogSaysWhy) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(serve_window_args(
      tmp, "3:export_dialog=" + tmp.str("plain") + ";5:answer=export;6:export_wait;8:serve=on;9:export_wait"));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto stats = test::stats(r);
  EXPECT_EQ(stats["export"]["serving"], "");
  EXPECT_EQ(stats["export"]["serve_error"], "export the bundle with 'add a web page for phones' first");
}

}  // namespace
}  // namespace arwb
