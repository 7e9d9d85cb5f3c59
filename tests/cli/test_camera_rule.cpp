// One rule for the camera (calibration/camera_rule.hpp): every camera at the edges of what the reader accepts goes
// through every command that takes --calib (detect's poses, render, export and its self-test, the lab) without
// crashing and without a figure that is not a number; what the rule refuses is refused by each with its reason.
// The window's consumers (the workbench, play) are in tests/ui/test_camera_rule_windows.cpp.
#include "support/extreme_cameras.hpp"
#include "support/samples.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <string>

namespace arwb {
namespace {

using test::q;
using test::run_arwb;
using test::TempDir;

// Every number under `j` finite (nlohmann writes NaN and infinities as null).
void expect_no_null(const nlohmann::json& j, const std::string& where) {
  if (j.is_null()) ADD_FAILURE() << where << ": null (a NaN or an infinity)";
  if (j.is_structured())
    for (auto it = j.begin(); it != j.end(); ++it) expect_no_null(*it, where);
}

TEST(CameraRule, EveryExtremeTheReaderAcceptsGoesThroughDetectRenderExportAndTheLab) {
  TempDir d;
  test::write_file(d.str("scene.lua"), "marker(843, { media = text \"843\", place = on_marker {} })\n");
  test::write_file(d.str("plan.yml"), "name: tiny\nsizes_mm: [65]\ndistances_m: [1]\nlux: [850]\nframes_per_cell: 1\n");
  for (const test::ExtremeCamera& c : test::extreme_cameras()) {
    const std::string calib = test::write_extreme_camera(d, c), name = c.name;
    auto r = run_arwb("detect " + q(test::kSample) + " --calib " + q(calib) + " --marker-size 50 --json");
    ASSERT_EQ(r.status, 0) << name << ": " << r.err;
    const nlohmann::json j = test::parse(r.out);
    ASSERT_EQ(j["markers"].size(), 2u) << name;
    for (const auto& m : j["markers"]) expect_no_null(m, name);   // a marker without a pose has no "pose"
    r = run_arwb("detect " + q(test::kSample) + " --calib " + q(calib) + " --marker-size 50");
    EXPECT_EQ(r.status, 0) << name << ": " << r.err;
    EXPECT_EQ(test::lines(r.out).size(), 5u) << name << ": a pose line per marker, or why there is none\n" << r.out;
    r = run_arwb("render --scene " + q(d.str("scene.lua")) + " --input " + q(test::kSample) + " --calib " + q(calib) +
                 " --out " + q(d.str(name + "_frames")));
    EXPECT_EQ(r.status, 0) << name << ": " << r.err;
    EXPECT_TRUE(std::filesystem::exists(d.str(name + "_frames/frame_000000.png"))) << name;
    // The self-test renders the scene through the camera: it passes, or says in one line why not.
    r = run_arwb("export --scene " + q(d.str("scene.lua")) + " --calib " + q(calib) + " --out " +
                 q(d.str(name + ".arwb")));
    if (r.status != 0) {
      EXPECT_EQ(r.status, 1) << name << ": " << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << name << ": " << r.err;
    }
    r = run_arwb("lab --plan " + q(d.str("plan.yml")) + " --calib " + q(calib) + " --detectors arwb --out " +
                 q(d.str("lab_" + name)));
    EXPECT_EQ(r.status, 0) << name << ": " << r.err;
    EXPECT_EQ(r.out.find("nan"), std::string::npos) << name << ": " << r.out;
  }
}

// The rule's refusals, each from the reader (or, for a file without a size, at the source's size) with the reason,
// the same in every command.
TEST(CameraRule, WhatTheRuleRefusesEachCommandRefusesWithTheReason) {
  TempDir d;
  const std::string head = "%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ ";
  test::write_file(d.str("tiny_focal.yml"), head + "1e-300, 0, 320, 0, 1e-300, 240, 0, 0, 1 ]\ndistortion_coefficients: [0, 0, 0, 0]\n");
  test::write_file(d.str("k4.yml"), head + "560, 0, 322, 0, 555, 236, 0, 0, 1 ]\ndistortion_coefficients: "
                                           "[-0.25, 0.08, 0, 0, 0, 1e6, 0, 0]\n");
  const std::string sized = "image_width: 640\nimage_height: 480\n";
  test::write_file(d.str("k4_sized.yml"), head + "560, 0, 322, 0, 555, 236, 0, 0, 1 ]\ndistortion_coefficients: "
                                                 "[-0.25, 0.08, 0, 0, 0, 1e6, 0, 0]\n" + sized);
  test::write_file(d.str("scene.lua"), "marker(843, { media = text \"843\", place = on_marker {} })\n");
  const std::string focal = "camera_matrix: focal length fx 1e-300 is not 1 to 1e+07 pixels";
  const std::string undone = "its distortion cannot be undone at pixel (0, 0) of a 640x480 picture";
  for (const auto& [file, why] : {std::pair{"tiny_focal.yml", focal}, std::pair{"k4.yml", undone},
                                  std::pair{"k4_sized.yml", undone}}) {
    const std::string calib = d.str(file);
    auto r = run_arwb("detect " + q(test::kSample) + " --calib " + q(calib) + " --marker-size 50");
    EXPECT_NE(r.err.find(why), std::string::npos) << file << ": " << r.err;
    r = run_arwb("render --scene " + q(d.str("scene.lua")) + " --input " + q(test::kSample) + " --calib " + q(calib) +
                 " --out " + q(d.str("rendered")));
    EXPECT_NE(r.status, 0) << file;
    EXPECT_NE(r.err.find(why), std::string::npos) << file << ": " << r.err;
  }
  // The lab needs the size, so reads it with the file: refused before any cell.
  auto r = run_arwb("lab --calib " + q(d.str("k4_sized.yml")) + " --detectors arwb --frames-per-cell 1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(undone), std::string::npos) << r.err;
  r = run_arwb("export --scene " + q(d.str("scene.lua")) + " --calib " + q(d.str("k4_sized.yml")) + " --out " +
               q(d.str("b.arwb")));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find(undone), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(d.str("b.arwb")));
  // A strip of 1x65536 pixels keeps the rule; the export's self-test cannot render a frame of that shape and says
  // so, where OpenCV's "Failed to allocate 80530636800 bytes" came out.
  test::write_file(d.str("strip.yml"), head + "500, 0, 0, 0, 500, 32768, 0, 0, 1 ]\ndistortion_coefficients: "
                                              "[0, 0, 0, 0]\nimage_width: 1\nimage_height: 65536\n");
  r = run_arwb("export --scene " + q(d.str("scene.lua")) + " --calib " + q(d.str("strip.yml")) + " --out " +
               q(d.str("s.arwb")));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("made for 1x65536, a shape the self-test cannot render (640 pixels wide, a frame of it would "
                       "be 640x41943040)"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("allocate"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arwb
