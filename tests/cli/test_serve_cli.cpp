// `arwb serve`: what it prints for a person (the address, its QR code, the way to a phone), the requests it logs,
// and the one-line refusals: a bundle without the phone page, a bad port.
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <string>

namespace {

using arwb::test::run_arwb;
using arwb::test::TempDir;

const std::string kMuseum = std::string(ARWB_SOURCE_DIR) + "/scripts/museum/museum.lua";

// Serves for a moment, on any free port, and says how to reach it; stopping says how many requests it answered.
TEST(ServeCli, PrintsTheAddressItsQrCodeAndTheWayToAPhone) {
  TempDir out;
  const std::string bundle = out.str("museum.arwb");
  ASSERT_EQ(run_arwb("export --scene '" + kMuseum + "' --out '" + bundle + "' --web --title 'Museum room' --quiet")
                .status,
            0);
  const auto r = run_arwb("serve '" + bundle + "' --port 0 --seconds 0.5");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* part : {"Serving \"Museum room\" (", "museum.arwb: 3 markers of ARUCO_ORIGINAL,",
                           "    http://127.0.0.1:", "\u2588\u2580\u2580\u2580\u2580\u2580\u2588", "adb reverse tcp:",
                           "static HTTPS host", "Ctrl+C stops."})
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  EXPECT_EQ(r.out.find('\x1b'), std::string::npos) << "no colour codes when stdout is not a terminal";
  EXPECT_EQ(r.err, "arwb serve: stopped after 0 requests\n");
}

TEST(ServeCli, RefusalsAreOneLine) {
  TempDir out;
  const std::string bundle = out.str("plain");
  ASSERT_EQ(run_arwb("export --scene '" + kMuseum + "' --out '" + bundle + "' --quiet").status, 0);
  auto r = run_arwb("serve '" + bundle + "' --port 0");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "arwb serve: " + bundle + ": has no web page; export it again with --web\n");
  EXPECT_EQ(r.out, "");

  r = run_arwb("serve '" + out.str("none") + "'");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("arwb serve: " + out.str("none")), std::string::npos) << r.err;

  r = run_arwb("serve '" + bundle + "' --port 70000");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--port"), std::string::npos) << r.err;
}

}  // namespace
