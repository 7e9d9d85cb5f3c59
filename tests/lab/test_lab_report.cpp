// The lab's plots and report.pdf (PLplot) from results made by hand: every file is written, the PNGs decode at
// their size with the detectors' colours in them, the PDF has a page per plot and a title page, and folders or
// files that cannot be written are errors naming them.
#include "lab/report.hpp"
#include "lab/sensor.hpp"

#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <set>
#include <sys/wait.h>
#include <thread>

namespace arwb::lab {
namespace {

namespace fs = std::filesystem;

// Two detectors on a 2x2x2 plan. arwb sees every frame of the big near marker and none of the small far one;
// opencv does a little worse everywhere; light costs both a few frames. Frame k of a cell is tilted 1.5 k degrees
// and the frames missed are the last (the most tilted); the far cells are the blurrier.
LabResults made_up_results() {
  LabResults r;
  r.plan.sizes_mm = {65, 26};
  r.plan.distances_m = {2, 0.5};
  r.plan.lux = {1000, 500};
  r.plan.frames_per_cell = 40;
  r.options.detectors = {"arwb", "opencv"};
  r.options.seed = 7;
  r.ids = {3, 14, 159};
  r.seconds = 12.5;
  const double f = r.options.camera.camera_matrix(0, 0);
  for (const Cell& c : r.plan.cells(f)) {
    CellResult cr;
    cr.cell = c;
    cr.side_px = marker_side_px(c.size_mm, c.distance_m, f);
    cr.blur_px = c.distance_m == 2 ? 2.5 : 1.2;
    for (int k = 0; k < 40; ++k) cr.tilts_deg.push_back(1.5f * float(k));
    const bool big = c.size_mm == 65, near = c.distance_m == 0.5, bright = c.lux == 1000;
    int arwb = big && near ? 40 : !big && !near ? 0 : (big ? 30 : 20) - (bright ? 0 : 4);
    int opencv = std::max(0, arwb - 6);
    for (int detected : {arwb, opencv}) {
      DetectorTally t;
      t.frames = 40;
      t.detected = detected;
      t.marks = std::string(size_t(detected), 'D') + std::string(size_t(40 - detected), 'M');
      cr.detectors.push_back(t);
    }
    r.cells.push_back(cr);
  }
  return r;
}

int distinct_colours(const cv::Mat& img) {
  std::set<int> seen;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      seen.insert(p[0] << 16 | p[1] << 8 | p[2]);
    }
  return int(seen.size());
}

// Pixels within `tol` (each channel) of an RGB colour.
int pixels_near(const cv::Mat& img, int r, int g, int b, int tol = 12) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      n += std::abs(p[2] - r) <= tol && std::abs(p[1] - g) <= tol && std::abs(p[0] - b) <= tol;
    }
  return n;
}

// Pages of a PDF: "/Type /Page" dictionaries, not the "/Type /Pages" tree.
int pdf_pages(const std::string& pdf) {
  int n = 0;
  const std::string key = "/Type /Page";
  for (size_t at = pdf.find(key); at != std::string::npos; at = pdf.find(key, at + 1))
    n += at + key.size() >= pdf.size() || pdf[at + key.size()] != 's';
  return n;
}

TEST(LabReport, WritesEveryPlotAndAPdfWithATitlePage) {
  // PLplot must find its own data files (fonts, palettes) where Debian puts them, without help.
  ::unsetenv("PLPLOT_LIB");
  ::unsetenv("PLPLOT_DRV_DIR");
  const LabResults r = made_up_results();
  test::TempDir dir;
  const std::string out = dir.str("plots");   // created by the report
  const Status s = write_lab_report(r, out);
  ASSERT_TRUE(s) << s.error();

  const std::vector<std::string> pngs = lab_report_png_names(r);
  // A heatmap per detector pooled over light, and one under each light (the plan has two).
  ASSERT_EQ(pngs, (std::vector<std::string>{"recall_by_side.png", "recall_by_light.png", "recall_by_tilt.png",
                                            "recall_by_blur.png", "heatmap_arwb.png", "heatmap_arwb_1000lx.png",
                                            "heatmap_arwb_500lx.png", "heatmap_opencv.png",
                                            "heatmap_opencv_1000lx.png", "heatmap_opencv_500lx.png"}));
  for (const std::string& name : pngs) {
    SCOPED_TRACE(name);
    const cv::Mat img = cv::imread(out + "/" + name, cv::IMREAD_COLOR);
    ASSERT_FALSE(img.empty());
    EXPECT_EQ(img.cols, kPlotWidthPx);
    EXPECT_EQ(img.rows, kPlotHeightPx);
    EXPECT_GT(distinct_colours(img), 20);   // text, lines and fills, antialiased: far from a blank page
    EXPECT_GT(pixels_near(img, 255, 255, 255), img.total() / 4);   // white paper
  }
  // The curves are drawn in the detectors' colours (arwb blue, opencv orange).
  for (const char* name : {"recall_by_side.png", "recall_by_light.png", "recall_by_tilt.png", "recall_by_blur.png"}) {
    SCOPED_TRACE(name);
    const cv::Mat img = cv::imread(out + "/" + name, cv::IMREAD_COLOR);
    EXPECT_GT(pixels_near(img, 31, 119, 180), 200);
    EXPECT_GT(pixels_near(img, 230, 120, 10), 200);
  }
  // arwb's heatmap has a cell of 0 % (red) and one of 100 % (green): the colour map's two ends, filling cells.
  const cv::Mat heat = cv::imread(out + "/heatmap_arwb.png", cv::IMREAD_COLOR);
  EXPECT_GT(pixels_near(heat, 245, 110, 66, 6), 5000);
  EXPECT_GT(pixels_near(heat, 115, 204, 115, 6), 5000);

  const std::string pdf = test::read_file(out + "/report.pdf");
  ASSERT_GE(pdf.size(), 5u);
  EXPECT_EQ(pdf.substr(0, 5), "%PDF-");
  EXPECT_EQ(pdf_pages(pdf), 1 + 2 + int(pngs.size())) << "the title, the table of each detector, the plots";
  // Nothing but the report's files is left in the folder (no temporary ".arwb-saving" files).
  int files = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    ++files;
    EXPECT_EQ(e.path().extension() == ".arwb-saving", false) << e.path();
  }
  EXPECT_EQ(files, int(pngs.size()) + 1);
}

TEST(LabReport, PdfinfoCountsThePagesToo) {
  if (std::system("command -v pdfinfo >/dev/null 2>&1") != 0) GTEST_SKIP() << "pdfinfo (poppler-utils) is missing";
  test::TempDir dir;
  ASSERT_TRUE(write_lab_report(made_up_results(), dir.str()));
  const std::string info = dir.str("info.txt");
  ASSERT_EQ(std::system(("pdfinfo '" + dir.str("report.pdf") + "' > '" + info + "'").c_str()), 0);
  const std::string text = test::read_file(info);
  EXPECT_TRUE(std::regex_search(text, std::regex("Pages:\\s+13\\n"))) << text;
  EXPECT_NE(text.find("842 x 595 pts"), std::string::npos) << text;
}

TEST(LabReport, DetectorsWhoseNamesReadAlikeGetAHeatmapEach) {
  LabResults r = made_up_results();
  r.options.detectors = {"a b", "a_b", "a/b"};
  r.plan.lux = {1000};   // one light: no heatmaps per light
  EXPECT_EQ(lab_report_png_names(r), (std::vector<std::string>{"recall_by_side.png", "recall_by_light.png",
                                                               "recall_by_tilt.png", "recall_by_blur.png",
                                                               "heatmap_a_b.png", "heatmap_a_b_2.png",
                                                               "heatmap_a_b_3.png"}));
}

TEST(LabReport, AFolderThatCannotBeMadeIsAnErrorNamingIt) {
  test::TempDir dir;
  test::write_file(dir.str("a-file"), "not a folder");
  const std::string out = dir.str("a-file") + "/plots";
  const Status s = write_lab_report(made_up_results(), out);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().find(out), std::string::npos) << s.error();
  EXPECT_EQ(s.error().find('\n'), std::string::npos) << s.error();
}

TEST(LabReport, AFileThatCannotBeReplacedIsAnErrorNamingIt) {
  // A folder where report.pdf should go: the plots are written, the PDF cannot replace it.
  test::TempDir dir;
  fs::create_directories(dir.path() / "report.pdf" / "inside");
  const Status s = write_lab_report(made_up_results(), dir.str());
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().find(dir.str("report.pdf")), std::string::npos) << s.error();
  EXPECT_TRUE(fs::is_regular_file(dir.path() / "recall_by_side.png"));
  EXPECT_FALSE(fs::exists(dir.path() / "report.pdf.arwb-saving"));
}

TEST(LabReport, ResultsWithoutCellsOrDetectorsAreAnError) {
  test::TempDir dir;
  LabResults r = made_up_results();
  r.cells.clear();
  EXPECT_FALSE(write_lab_report(r, dir.str()));
  r = made_up_results();
  r.options.detectors.clear();
  EXPECT_FALSE(write_lab_report(r, dir.str()));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(LabReport, AMissingCairoDriverIsAnErrorNamingIt) {
  // PLplot's other drivers (libplplot17's) without plplot-driver-cairo's, through PLplot's own variable for the
  // drivers' folder; in a child process, as PLplot reads its driver table once per process.
  const fs::path drivers = "/usr/lib/x86_64-linux-gnu/plplot5.15.0/drivers";
  if (!fs::is_directory(drivers)) GTEST_SKIP() << drivers << " is not there (not Debian's PLplot 5.15)";
  test::TempDir dir;
  fs::create_directories(dir.path() / "drivers");
  for (const auto& e : fs::directory_iterator(drivers))
    if (e.path().stem() != "cairo") fs::copy(e.path(), dir.path() / "drivers" / e.path().filename());
  const std::string out = dir.str("out");
  const std::string cmd = "PLPLOT_DRV_DIR='" + dir.str("drivers") + "' '" + ARWB_BINARY +
                          "' lab --frames-per-cell 1 --detectors arwb --out '" + out + "' </dev/null >/dev/null 2>'" +
                          dir.str("err.txt") + "'";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const std::string err = test::read_file(dir.str("err.txt"));
  EXPECT_NE(err.find("PLplot has no pngcairo device"), std::string::npos) << err;
  EXPECT_NE(err.find("plplot-driver-cairo"), std::string::npos) << err;
  EXPECT_TRUE(fs::exists(out + "/table.csv"));   // the tables are written before the plots
  EXPECT_FALSE(fs::exists(out + "/recall_by_side.png"));
}

TEST(LabReport, TwoThreadsDrawTheSamePlotsAsOne) {
  // PLplot's state is global: reports drawn at once must not draw into each other's files.
  const LabResults r = made_up_results();
  test::TempDir alone, a, b;
  ASSERT_TRUE(write_lab_report(r, alone.str()));
  Status sa, sb;
  std::thread ta([&] { sa = write_lab_report(r, a.str()); });
  std::thread tb([&] { sb = write_lab_report(r, b.str()); });
  ta.join();
  tb.join();
  ASSERT_TRUE(sa) << sa.error();
  ASSERT_TRUE(sb) << sb.error();
  for (const std::string& name : lab_report_png_names(r)) {
    SCOPED_TRACE(name);
    const std::string want = test::read_file(alone.str(name));
    EXPECT_EQ(test::read_file(a.str(name)), want);
    EXPECT_EQ(test::read_file(b.str(name)), want);
  }
}

}  // namespace
}  // namespace arwb::lab
