// arwb lab: the paper's table printed and written (text, CSV, JSON, plots), bad detectors and calibrations named.
#include "detect/dictionary.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <sys/stat.h>

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
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1 + 2 * 35) << "27 cells, and 8 for the curves";
  EXPECT_EQ(slurp(d.str("out/table.txt")), r.out.substr(r.out.find("arwb: P_Rec"), slurp(d.str("out/table.txt")).size()));
  const auto j = nlohmann::json::parse(slurp(d.str("out/results.json")), nullptr, false);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j["cells"].size(), 35u);
  EXPECT_TRUE(j["cells"][26]["curve"].is_null());
  EXPECT_EQ(j["cells"][27]["curve"], "blur");
  EXPECT_EQ(j["cells"][34]["curve"], "noise");
  EXPECT_EQ(j["plan"]["curve_at"], nlohmann::json({39, 1, 500}));
  // The curves under each detector's table, from the grid's cell at 39 mm, 1 m, 500 lx.
  EXPECT_NE(r.out.find(", and 8 cells for the blur and noise curves at 39 mm, 1 m, 500 lx,"), std::string::npos);
  EXPECT_NE(r.out.find("blur and noise at 39 mm, 1 m, 500 lx (22 px), on the same frames:\n  added blur     0  "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("\n  added noise   60  "), std::string::npos) << r.out;
  EXPECT_EQ(j["ids"].size(), 25u);
  EXPECT_EQ(j["plan"]["sizes_mm"], nlohmann::json({65, 39, 26}));
  EXPECT_TRUE(j["cells"][0]["results"].contains("opencv"));
  // The added axes at their defaults, always present; each frame's tilt.
  EXPECT_EQ(j["plan"]["occlusions"], nlohmann::json::array({0.0}));   // not json({0}): clang reads a lone 0 as null
  EXPECT_TRUE(j["cells"][0]["tilt_deg"].is_null());
  EXPECT_EQ(j["cells"][0]["tilts_deg"].size(), 2u);
  // The plots and report.pdf beside them (tests/lab/test_lab_report.cpp looks inside).
  EXPECT_NE(r.out.find("report.pdf and 14 PNG plots to " + d.str("out")), std::string::npos) << r.out;
  for (const char* name : {"report.pdf", "recall_by_side.png", "recall_by_light.png", "recall_by_tilt.png",
                           "recall_by_blur.png", "recall_at_added_blur.png", "recall_at_added_noise.png",
                           "heatmap_arwb.png", "heatmap_opencv.png", "heatmap_arwb_850lx.png"})
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

// Interrupted (the saved cells cut after ten, the last line half written): the run resumes from the ten and
// prints the same table.
TEST(LabCli, AnInterruptedRunIsResumed) {
  TempDir d;
  const std::string args = "lab --frames-per-cell 2 --detectors arwb --threads 2 --out " + d.str("out");
  const auto full = run_arwb(args);
  ASSERT_EQ(full.status, 0) << full.err;
  const std::string table = slurp(d.str("out/table.txt"));
  const std::string saved = slurp(d.str("out/cells.jsonl"));
  ASSERT_EQ(std::count(saved.begin(), saved.end(), '\n'), 35);
  size_t cut = 0;
  for (int i = 0; i < 10; ++i) cut = saved.find('\n', cut) + 1;
  test::write_file(d.str("out/cells.jsonl"), saved.substr(0, cut) + saved.substr(cut, 40));
  std::remove(d.str("out/table.txt").c_str());
  const auto resumed = run_arwb(args);
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("resuming: 10 of 35 cells"), std::string::npos) << resumed.err;
  EXPECT_EQ(slurp(d.str("out/table.txt")), table);
  // --restart forgets them.
  const auto again = run_arwb(args + " --restart");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(again.err.find("resuming"), std::string::npos) << again.err;
}

// A saved cell whose counts cannot be (edited by hand: the table printed -20000 %) is named and run again; a FIFO
// or a device in place of cells.jsonl is refused at once (it hung the lab in fopen, or read without end).
TEST(LabCli, ACellsFileThatCannotBeARunsIsNamedAndNotTaken) {
  TempDir d;
  test::write_file(d.str("one.yml"), "sizes_mm: [65]\ndistances_m: [1]\nlux: 800\nframes_per_cell: 2\n");
  const std::string args = "lab --plan " + d.str("one.yml") + " --detectors arwb --out " + d.str("out");
  ASSERT_EQ(run_arwb(args).status, 0);
  const std::string table = slurp(d.str("out/table.txt"));
  const std::string cells = d.str("out/cells.jsonl");
  nlohmann::json line = nlohmann::json::parse(slurp(cells));
  line["detectors"][0][1] = -20000;
  test::write_file(cells, line.dump() + "\n");
  const auto edited = run_arwb(args);
  ASSERT_EQ(edited.status, 0) << edited.err;
  EXPECT_NE(edited.err.find(cells + ":1: detected -20000 is negative; the cell is run again"), std::string::npos)
      << edited.err;
  EXPECT_EQ(edited.err.find("resuming"), std::string::npos) << edited.err;
  EXPECT_EQ(slurp(d.str("out/table.txt")), table) << "the cell run again gives the first run's table";

  std::remove(cells.c_str());
  ASSERT_EQ(::mkfifo(cells.c_str(), 0600), 0);
  const auto fifo = run_arwb(args);
  EXPECT_EQ(fifo.status, 1);
  EXPECT_EQ(fifo.err, "arwb lab: " + cells + ": not a regular file (a FIFO)\n");
  std::remove(cells.c_str());
  std::filesystem::create_symlink("/dev/zero", cells);
  const auto zero = run_arwb(args);
  EXPECT_EQ(zero.status, 1);
  EXPECT_EQ(zero.err, "arwb lab: " + cells + ": not a regular file (a character device)\n");
}

// A plan file changes the axes (here another dictionary, which AprilTag reads); a bad one is named with its field.
// A plan named in Latin-1 (caf\xe9_plan.yml: not UTF-8), whose file name names the plan: the run goes to the end and
// it names the plan with U+FFFD for the bad byte everywhere (it stopped at once with nlohmann's type_error.316).
TEST(LabCli, APlanNamedInLatin1RunsAndItsJsonIsUtf8) {
  TempDir d;
  const std::string plan = d.str("caf\xe9_plan.yml");
  test::write_file(plan, "sizes_mm: [65]\ndistances_m: [1]\nlux: [850]\nframes_per_cell: 1\n");
  const auto r = run_arwb("lab --plan " + test::q(plan) + " --detectors arwb --out " + test::q(d.str("out")));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string json = slurp(d.str("out/results.json"));
  const nlohmann::json j = nlohmann::json::parse(json);   // throws on text that is not UTF-8
  EXPECT_EQ(j["plan"]["name"], "caf\xef\xbf\xbd_plan") << json.substr(0, 400);
  // The terminal and the plots say it alike (PLplot printed "UTF-8 string is malformed" and dropped the title).
  EXPECT_NE(r.out.find("Plan caf\xef\xbf\xbd_plan: 1 cells"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("PLPLOT"), std::string::npos) << r.err;
}

TEST(LabCli, PlanFilesAndTheirMistakes) {
  TempDir d;
  test::write_file(d.str("tags.yml"), "sizes_mm: [50]\ndistances_m: [0.5, 3]\nlux: 800\nframes_per_cell: 3\n"
                                      "dictionary: APRILTAG_36h11\nmarkers: 5\n");
  auto r = run_arwb("lab --plan " + d.str("tags.yml") + " --detectors arwb,apriltag");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("Plan tags: 2 cells x 3 frames (and 1 without a marker), markers APRILTAG_36h11"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("apriltag: P_Rec"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" 50 mm  0.5 m   55 px"), std::string::npos) << r.out;
  const std::pair<const char*, const char*> bad[] = {
      {"sizes_mm: [65, -5]\n", "bad.yml: sizes_mm: value 2 (-5) must be a size in mm from 1 to 2000"},
      {"size_mm: [65]\n", "bad.yml: unknown field 'size_mm' (did you mean 'sizes_mm'?)"},
      {"dictionary: NOPE\n", "bad.yml: dictionary: unknown 'NOPE'"},
      {"lux: [a, 2]\n", "bad.yml: lux: value 1 is not a number"},
      {"frames_per_cell: 0\n", "bad.yml: frames_per_cell: 0 must be from 1 to 100000"},
      {"frames_per_cell: 1.9\n", "bad.yml: frames_per_cell: 1.9 is not a whole number"},
      {"frames_per_cell: .nan\n", "bad.yml: frames_per_cell: not a finite number"},
      {"sizes_mm: [65, .nan]\n", "bad.yml: sizes_mm: value 2 is not a finite number"},
      {"markers: 60\ndictionary: \"4X4_50\"\n", "bad.yml: markers: 60 distinct ids, but 4X4_50 has 50"},
      {"sides_px: [20]\nsizes_mm: [65]\n",
       "bad.yml: sides_px and sizes_mm: give one of them (sides_px derives the printed size)"},
      {"occlusions: [0.9]\n", "bad.yml: occlusions: value 1 (0.9) must be a share of the marker's area from 0 to 0.5"},
  };
  // The added axes: rows name their values, the CSV and JSON carry them, and the frames' tilts are in the JSON.
  test::write_file(d.str("added.yml"), "sizes_mm: [65]\ndistances_m: [1]\nlux: 1000\nframes_per_cell: 2\n"
                                       "tilts_deg: [0, 60]\nblurs_px: [0, 1.5]\n");
  r = run_arwb("lab --plan " + d.str("added.yml") + " --detectors arwb --out " + d.str("added"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("Plan added: 4 cells x 2 frames"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\n 65 mm  1.0 m   36 px tilt 60 blur 1.5  "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\n 65 mm  1.0 m   36 px tilt 0  blur 0    "), std::string::npos) << r.out;
  EXPECT_NE(slurp(d.str("added/table.csv")).find("arwb,65,1,1000,36.0,2,"), std::string::npos);
  EXPECT_NE(slurp(d.str("added/table.csv")).find(",60,1.5,0,0,"), std::string::npos) << slurp(d.str("added/table.csv"));
  const auto added = nlohmann::json::parse(slurp(d.str("added/results.json")), nullptr, false);
  ASSERT_TRUE(added.is_object());
  EXPECT_EQ(added["plan"]["tilts_deg"], nlohmann::json({0, 60}));
  EXPECT_EQ(added["cells"][3]["tilt_deg"], 60);
  EXPECT_EQ(added["cells"][3]["added_blur_px"], 1.5);
  EXPECT_EQ(added["cells"][3]["tilts_deg"], nlohmann::json({60, 60}));
  for (const auto& [text, message] : bad) {
    test::write_file(d.str("bad.yml"), text);
    r = run_arwb("lab --plan " + d.str("bad.yml"));
    EXPECT_EQ(r.status, 2) << text;
    EXPECT_NE(r.err.find(message), std::string::npos) << text << "\n" << r.err;
  }
}

// Real videos: clips of one marker listed with their conditions; the visible frames are the whole clip or its span.
// Here clip a shows marker 5 large in every frame, clip b shows marker 5 only in its first 4 of 10 frames (the span
// says 0-3), and clip c is listed as marker 6 while it shows 5: never recognised.
TEST(LabCli, VideosGiveThePapersMeasure) {
  TempDir d;
  const Dictionary dict = make_aruco_original();
  auto clip = [&](const std::string& name, int with_marker, int frames) {
    cv::VideoWriter w(d.str(name), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20.0, cv::Size(320, 240));
    ASSERT_TRUE(w.isOpened());
    for (int i = 0; i < frames; ++i) {
      cv::Mat img(240, 320, CV_8UC3, cv::Scalar(200, 200, 200));
      if (i < with_marker)
        draw_marker(img, dict, 5, Quad{{{100, 60}, {220, 60}, {220, 180}, {100, 180}}}, 1.0, 4, 20, 235);
      w.write(img);
    }
  };
  clip("a.avi", 8, 8);
  clip("b.avi", 4, 10);
  clip("c.avi", 6, 6);
  test::write_file(d.str("videos.csv"),
                   "file,id,dictionary,size_mm,distance_m,lux,first_frame,last_frame\n"
                   "# a comment\n"
                   "a.avi,5,ARUCO_ORIGINAL,65,0.5,1000,0,7\n"
                   "b.avi,5,ARUCO_ORIGINAL,65,1,1000,0,3\n"
                   "c.avi,6,ARUCO_ORIGINAL,39,1,1000,0,5\n");
  const auto r = run_arwb("lab --videos " + d.str() + " --detectors arwb,opencv --out " + d.str("out"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("3 clips, 18 frames with the marker in view, 4 cells"), std::string::npos) << r.out;
  const std::string csv = slurp(d.str("out/table.csv"));
  EXPECT_NE(csv.find("arwb,65,1,1000,36.0,4,4,100.00"), std::string::npos) << csv;
  EXPECT_NE(csv.find("arwb,65,0.5,1000,72.1,8,8,100.00"), std::string::npos) << csv;
  EXPECT_NE(csv.find("arwb,39,1,1000,21.6,6,0,0.00"), std::string::npos) << csv;
  EXPECT_NE(csv.find("opencv,65,0.5,1000,72.1,8,8,100.00"), std::string::npos) << csv;
  // The cell no clip was filmed in (39 mm at 0.5 m) shows a dash, not 0 %.
  EXPECT_NE(r.out.find(" 39 mm  0.5 m   43 px      -"), std::string::npos) << r.out;
  // Mistakes in the list are one line naming it.
  const std::pair<const char*, const char*> bad[] = {
      {"file,id\n", "videos.csv:1: the header must be file,id,dictionary,size_mm,distance_m,lux"},
      {"file,id,dictionary,size_mm,distance_m,lux\n../x.avi,5,ARUCO_ORIGINAL,65,1,1000\n",
       "videos.csv:2: ../x.avi: leaves the videos' folder"},
      {"file,id,dictionary,size_mm,distance_m,lux\na.avi,5,ARUCO_ORIGINAL,big,1,1000\n",
       "videos.csv:2: size_mm 'big' is not a number"},
      {"file,id,dictionary,size_mm,distance_m,lux\na.avi,2000,ARUCO_ORIGINAL,65,1,1000\n",
       "videos.csv:2: id 2000 is not a marker of ARUCO_ORIGINAL (0 to 1023)"},
      {"file,id,dictionary,size_mm,distance_m,lux\nmissing.avi,5,ARUCO_ORIGINAL,65,1,1000\n",
       "videos.csv:2: missing.avi: no such file"},
  };
  for (const auto& [text, message] : bad) {
    test::write_file(d.str("videos.csv"), text);
    const auto e = run_arwb("lab --videos " + d.str());
    EXPECT_EQ(e.status, 2) << text;
    EXPECT_NE(e.err.find(message), std::string::npos) << text << "\n" << e.err;
  }
}

}  // namespace
}  // namespace arwb
