// arwb lab: the paper's table printed and written (text, CSV, JSON, plots), bad detectors and calibrations named.
#include "support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>

namespace arwb {
namespace {

using test::run_arwb;
using test::TempDir;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(LabCli, PrintsAndWritesThePapersTable) {
  TempDir d;
  const auto r = run_arwb("lab --frames-per-cell 2 --detectors arwb,opencv --out " + d.str("out"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("The paper's plan: 27 cells x 2 frames"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("arwb: P_Rec % [95% interval]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("opencv: P_Rec % [95% interval]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" 26 mm  2.0 m    7 px"), std::string::npos) << r.out;
  const std::string csv = slurp(d.str("out/table.csv"));
  EXPECT_EQ(csv.rfind("detector,size_mm,distance_m,lux,side_px,frames,detected,p_rec,ci_low,ci_high,", 0), 0u);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 * 27);
  EXPECT_EQ(slurp(d.str("out/table.txt")), r.out.substr(r.out.find("arwb: P_Rec"), slurp(d.str("out/table.txt")).size()));
  const auto j = nlohmann::json::parse(slurp(d.str("out/results.json")), nullptr, false);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["cells"].size(), 27u);
  EXPECT_EQ(j["ids"].size(), 25u);
  EXPECT_EQ(j["plan"]["sizes_mm"], nlohmann::json({65, 39, 26}));
  EXPECT_TRUE(j["cells"][0]["results"].contains("opencv"));
  // The plots and report.pdf beside them (tests/lab/test_lab_report.cpp looks inside).
  EXPECT_NE(r.out.find("report.pdf and 4 PNG plots to " + d.str("out")), std::string::npos) << r.out;
  for (const char* name : {"report.pdf", "recall_by_side.png", "recall_by_light.png", "heatmap_arwb.png",
                           "heatmap_opencv.png"})
    EXPECT_GT(slurp(d.str("out/") + name).size(), 1000u) << name;
}

TEST(LabCli, BadDetectorsAndCalibrationsAreOneLine) {
  auto r = run_arwb("lab --frames-per-cell 1 --detectors arwb,apriltag");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("apriltag reads the AprilTag families, not ARUCO_ORIGINAL"), std::string::npos) << r.err;
  r = run_arwb("lab --frames-per-cell 1 --calib /nonexistent/cam.yml");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("/nonexistent/cam.yml"), std::string::npos) << r.err;
  r = run_arwb("lab --frames-per-cell 0");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--frames-per-cell"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arwb
