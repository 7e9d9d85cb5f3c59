// The Lab workspace, run for real under xvfb-run: a plan file read into the panel, run in the background to the
// end (lab_wait makes it independent of the machine's speed), its grid the same as `arwb lab` prints for the same
// plan and seed; a cell a detector missed a frame of opened in the live view on that very frame, with the marker's
// truth, and "Why not detected?" answering with a candidate and the stage that dropped it; a stopped run keeping
// its finished cells; a bad plan file named while the panel's plan and the window carry on.
#include "capture/video_reader.hpp"
#include "detect/dictionary.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>

#include <filesystem>
#include <map>
#include <vector>

#include <string>

namespace arwb {
namespace {

using test::RunResult;
using test::TempDir;
using Json = nlohmann::ordered_json;

using test::stats;

// Two sizes at two distances in one light, 6 frames a cell: 26 mm at 1 m (14 px) is missed often.
std::string small_plan(const TempDir& tmp) {
  const std::string path = tmp.str("small.yml");
  test::write_file(path, "%YAML:1.0\n---\nmarkers: 5\nsizes_mm: [65, 26]\ndistances_m: [0.5, 1]\nlux: [1000]\n"
                         "frames_per_cell: 6\n");
  return path;
}

TEST(LabWorkspace, TheGridIsTheCommandLinesTableAndAMissedFrameEndsInTheWhyPanel) {
  TempDir tmp;
  const std::string plan = small_plan(tmp);
  // The command line's run of the same plan and seed: its P_Rec per cell and each frame's verdict.
  const RunResult cli = test::run_arwb("lab --plan '" + plan + "' --detectors arwb,opencv --json");
  ASSERT_EQ(cli.status, 0) << cli.err;
  const Json want = test::parse(cli.out);
  ASSERT_EQ(want["cells"].size(), 4u);
  // A frame arwb missed, in the cell that misses most.
  int cell = -1, frame = -1;
  for (size_t c = 0; c < want["cells"].size() && cell < 0; ++c) {
    const std::string marks = want["cells"][c]["results"]["arwb"]["marks"];
    if (const size_t k = marks.find('M'); k != std::string::npos) {
      cell = int(c);
      frame = int(k);
    }
  }
  ASSERT_GE(cell, 0) << "no frame missed by arwb: " << cli.out;

  const RunResult r = test::run_arwb_window(
      "--config-dir '" + tmp.str("config") + "' --stats --frames 30 --actions '1:workspace=Lab;1:lab_plan=" + plan +
      ";2:lab_detectors=arwb,opencv;3:lab_run;3:lab_wait;5:lab_cell=" + std::to_string(cell) + "," +
      std::to_string(frame) + ";12:lab_why'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json s = stats(r);
  const Json lab = s["lab"];
  EXPECT_EQ(lab["plan"], "small");
  EXPECT_TRUE(lab["finished"].get<bool>()) << lab.dump();
  EXPECT_EQ(lab["cells_done"], 4);
  EXPECT_EQ(lab["frames_done"], lab["frames_total"]);
  for (const char* d : {"arwb", "opencv"}) {
    ASSERT_EQ(lab["p_rec"][d].size(), 4u) << lab.dump();
    for (size_t c = 0; c < 4; ++c) {
      EXPECT_DOUBLE_EQ(lab["p_rec"][d][c].get<double>(), want["cells"][c]["results"][d]["p_rec"].get<double>())
          << d << " cell " << c;
    }
    EXPECT_EQ(lab["cell_marks"][d], want["cells"][size_t(cell)]["results"][d]["marks"]) << d;
  }
  // The missed frame is in the live view, with its marker's truth, and nothing detected on it.
  EXPECT_EQ(lab["cell_open"], cell);
  EXPECT_EQ(lab["frame"], frame);
  EXPECT_EQ(s["source"].get<std::string>().rfind("lab: ", 0), 0u) << s["source"];
  EXPECT_EQ(s["markers"], 0) << "arwb found the marker the run says it missed";
  EXPECT_EQ(s["dictionaries"], Json::array({"ARUCO_ORIGINAL"}));
  // "Why not detected?" on it: the headline says nothing is detected there and names the candidate it follows.
  ASSERT_TRUE(s.contains("why")) << s.dump();
  const std::string why = s["why"]["summary"];
  EXPECT_NE(why.find("Nothing is detected here"), std::string::npos) << why;
  EXPECT_GE(s["why"]["candidate"].get<int>(), 0) << why;
  EXPECT_EQ(s["problems"], 0) << r.err;
}

TEST(LabWorkspace, AStoppedRunKeepsItsFinishedCells) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(
      "--config-dir '" + tmp.str("config") + "' --stats --frames 8 --actions '1:workspace=Lab;1:lab_frames=20;"
      "2:lab_detectors=arwb;3:lab_run;3:lab_wait=1;4:lab_stop;4:lab_wait'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json lab = stats(r)["lab"];
  EXPECT_FALSE(lab["running"].get<bool>());
  EXPECT_FALSE(lab["finished"].get<bool>());
  EXPECT_GE(lab["cells_done"].get<int>(), 1) << lab.dump();
  EXPECT_LT(lab["cells_done"].get<int>(), 27) << lab.dump();
  EXPECT_NE(lab["message"].get<std::string>().find("stopped after"), std::string::npos) << lab.dump();
  // The finished cells keep their rates; the others have none.
  int rated = 0;
  for (const Json& v : lab["p_rec"]["arwb"]) rated += !v.is_null();
  EXPECT_EQ(rated, lab["cells_done"].get<int>());
}

// A plan file named in Latin-1 (caf\xe9.yml: not UTF-8) run and saved from the panel: Save report made the whole
// window exit (nlohmann's type_error.316); the report's JSON now names the plan with U+FFFD for the bad byte.
TEST(LabWorkspace, SaveReportOfAPlanNamedInLatin1WritesUtf8AndTheWindowGoesOn) {
  TempDir tmp;
  const std::string plan = tmp.str("caf\xe9.yml");
  test::write_file(plan, "%YAML:1.0\n---\nsizes_mm: [65]\ndistances_m: [1]\nlux: [1000]\nframes_per_cell: 2\n");
  const RunResult r = test::run_arwb_window(
      "--config-dir '" + tmp.str("config") + "' --stats --frames 12 --actions '1:workspace=Lab;1:lab_plan=" + plan +
      ";2:lab_detectors=arwb;3:lab_run;3:lab_wait;4:lab_save=" + tmp.str("report") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json s = stats(r);
  EXPECT_EQ(s["lab"]["plan"], "caf\xef\xbf\xbd") << s["lab"].dump();
  EXPECT_EQ(s["problems"], 0) << r.err;
  const Json saved = Json::parse(test::read_file(tmp.str("report/results.json")));   // throws if not UTF-8
  EXPECT_EQ(saved["plan"]["name"], "caf\xef\xbf\xbd");
}

TEST(LabWorkspace, ABadPlanFileIsNamedAndThePlanAndTheWindowCarryOn) {
  TempDir tmp;
  const std::string bad = tmp.str("bad.yml");
  test::write_file(bad, "%YAML:1.0\n---\nsize_mm: [65]\n");
  const RunResult r = test::run_arwb_window("--config-dir '" + tmp.str("config") +
                                            "' --stats --frames 12 --actions '1:workspace=Lab;2:lab_plan=" + bad +
                                            ";3:lab_detectors=apriltag;4:lab_run'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json s = stats(r);
  // The second problem (apriltag cannot read ARUCO_ORIGINAL) is the panel's message now; both are in the log.
  EXPECT_NE(r.err.find("bad.yml: unknown field 'size_mm' (did you mean 'sizes_mm'?)"), std::string::npos) << r.err;
  EXPECT_NE(s["lab"]["message"].get<std::string>().find("apriltag reads the AprilTag families"), std::string::npos)
      << s["lab"].dump();
  EXPECT_EQ(s["lab"]["plan_set"], "paper") << "a bad file leaves the panel's plan as it was";
  EXPECT_FALSE(s["lab"]["running"].get<bool>());
  EXPECT_GT(s["markers"].get<int>(), 0) << "the live view goes on";
}

// A clip played in the live view, its span marked on the frames shown and saved as a row of videos.csv, which
// arwb lab --videos then reads: the paper's F_Num from the workbench.
TEST(LabWorkspace, AClipsSpanMarkedInTheWorkbenchIsWhatArwbLabVideosCounts) {
  TempDir d;
  const Dictionary dict = make_aruco_original();
  {
    cv::VideoWriter w(d.str("clip.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20.0, cv::Size(320, 240));
    ASSERT_TRUE(w.isOpened());
    // Long enough not to loop while a loaded machine's window takes its first frames.
    for (int i = 0; i < 90; ++i) {
      cv::Mat img(240, 320, CV_8UC3, cv::Scalar(200, 200, 200));
      draw_marker(img, dict, 5, Quad{{{100, 60}, {220, 60}, {220, 180}, {100, 180}}}, 1.0, 4, 20, 235);
      w.write(img);
    }
  }
  std::filesystem::copy_file(d.str("clip.avi"), d.str("other.avi"));
  // A list that is there already keeps its other rows and comments.
  test::write_file(d.str("videos.csv"), "file,id,dictionary,size_mm,distance_m,lux\n# old\nother.avi,3,ARUCO_ORIGINAL,39,2,500\n");
  const RunResult r = test::run_arwb_window("--config-dir '" + d.str("config") + "' --source '" + d.str("clip.avi") +
                                            "' --stats --frames 16 --actions '1:freeze;3:lab_span=start;4:next;6:next;"
                                            "8:next;10:lab_span=end;11:lab_clip=5,65,1,850'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json s = stats(r);
  EXPECT_NE(s["lab"]["message"].get<std::string>().find("clip.avi, marker 5, frames"), std::string::npos) << s["lab"];
  const std::string csv = test::read_file(d.str("videos.csv"));
  EXPECT_EQ(csv.rfind("file,id,dictionary,size_mm,distance_m,lux,first_frame,last_frame\n# old\n"
                      "other.avi,3,ARUCO_ORIGINAL,39,2,500\nclip.avi,5,ARUCO_ORIGINAL,65,1,850,",
                      0),
            0u)
      << csv;
  int first = -1, last = -1;
  ASSERT_EQ(std::sscanf(csv.c_str() + csv.find("clip.avi"), "clip.avi,5,ARUCO_ORIGINAL,65,1,850,%d,%d", &first, &last), 2)
      << csv;
  EXPECT_GE(first, 0) << csv;
  EXPECT_GE(last - first, 3) << "three frames stepped between the marks at least: " << csv;
  // arwb lab --videos counts exactly the span's frames.
  const RunResult lab = test::run_arwb("lab --videos '" + d.str() + "' --detectors arwb --json");
  ASSERT_EQ(lab.status, 0) << lab.err;
  const Json j = test::parse(lab.out);
  bool found = false;
  for (const Json& c : j["cells"]) {
    if (c["size_mm"] == 65 && c["distance_m"] == 1 && c["lux"] == 850) {
      found = true;
      EXPECT_EQ(c["results"]["arwb"]["frames"], last - first + 1) << c.dump() << csv << lab.err;
      EXPECT_EQ(c["results"]["arwb"]["detected"], last - first + 1) << c.dump();
    }
  }
  EXPECT_TRUE(found) << lab.out;
}

// Record with a video file as the source: the conditions typed once (a bad one refused before anything is filmed),
// the marker printed at its size, a clip stopped and one still recording when the window quits; each is the
// source's frames as taken (bit for bit, in order), listed in videos.csv, and arwb lab --videos counts them.
TEST(LabWorkspace, RecordFilmsTheSourceIntoClipsThatArwbLabVideosReads) {
  TempDir d;
  const Dictionary dict = make_aruco_original();
  // Frame i carries i in a band of 8 stripes above marker 5, so that a clip's frame names its source frame.
  constexpr int kFrames = 256;
  const cv::Size size(320, 240);
  const std::string clip = d.str("source.avi");
  {
    cv::VideoWriter w(clip, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 20.0, size);
    ASSERT_TRUE(w.isOpened());
    for (int i = 0; i < kFrames; ++i) {
      cv::Mat img(size, CV_8UC3, cv::Scalar(200, 200, 200));
      for (int bit = 0; bit < 8; ++bit)
        if (i >> bit & 1) img(cv::Rect(bit * 40, 0, 40, 40)).setTo(cv::Scalar::all(20));
      draw_marker(img, dict, 5, Quad{{{110, 70}, {210, 70}, {210, 170}, {110, 170}}}, 1.0, 4, 20, 235);
      w.write(img);
    }
  }
  std::vector<cv::Mat> source(1);
  {
    Result<VideoReader> r = VideoReader::open(clip, &source[0]);
    ASSERT_TRUE(r.ok()) << r.error();
    for (cv::Mat m; r->read(&m) == VideoReader::Read::frame;) source.push_back(m.clone());
  }
  ASSERT_EQ(int(source.size()), kFrames);
  const std::string dir = d.str("videos");
  const RunResult r = test::run_arwb_window("--config-dir '" + d.str("config") + "' --source '" + clip +
                                            "' --stats --frames 40 --actions '1:lab_record=2000,65,1,850," + dir +
                                            ";2:lab_record=5,65,1,850," + dir +
                                            ";3:lab_print;20:lab_record=stop;22:lab_record=5,39,2,500'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the clip's conditions: id 2000 is not a marker of ARUCO_ORIGINAL (0 to 1023)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(test::read_file(dir + "/marker_5_65mm.pdf").rfind("%PDF", 0), 0u) << "the marker printed at its size";
  const Json s = stats(r);
  EXPECT_FALSE(s["lab"]["clip"]["recording"].get<bool>()) << "quitting closed the clip";
  EXPECT_EQ(s["lab"]["clip"]["path"], dir + "/clips/m5_39mm_2m_500lx_1.mkv") << s["lab"];
  const std::string csv = test::read_file(dir + "/videos.csv");
  EXPECT_EQ(csv, "file,id,dictionary,size_mm,distance_m,lux,first_frame,last_frame\n"
                 "clips/m5_65mm_1m_850lx_1.mkv,5,ARUCO_ORIGINAL,65,1,850\n"
                 "clips/m5_39mm_2m_500lx_1.mkv,5,ARUCO_ORIGINAL,39,2,500\n");
  // Each clip: frames of the source exactly, later ones later.
  std::map<std::string, int> frames;
  for (const char* name : {"m5_65mm_1m_850lx_1.mkv", "m5_39mm_2m_500lx_1.mkv"}) {
    cv::Mat m;
    Result<VideoReader> rd = VideoReader::open(dir + "/clips/" + name, &m);
    ASSERT_TRUE(rd.ok()) << rd.error();
    int n = 0, last = -1;
    do {
      int i = 0;
      for (int bit = 0; bit < 8; ++bit)
        if (cv::mean(m(cv::Rect(bit * 40 + 10, 10, 20, 20)))[0] < 110) i |= 1 << bit;
      EXPECT_GT(i, last) << name << " frame " << n;
      EXPECT_EQ(cv::norm(m, source[size_t(i)], cv::NORM_INF), 0) << name << " frame " << n << " is source frame " << i;
      last = i;
      ++n;
    } while (rd->read(&m) == VideoReader::Read::frame);
    frames[name] = n;
  }
  EXPECT_EQ(s["lab"]["clip"]["frames"], frames["m5_39mm_2m_500lx_1.mkv"]);
  // arwb lab --videos: every frame of each clip counted, and read.
  const RunResult lab = test::run_arwb("lab --videos '" + dir + "' --detectors arwb --json");
  ASSERT_EQ(lab.status, 0) << lab.err;
  const Json j = test::parse(lab.out);
  int cells = 0;
  for (const Json& c : j["cells"]) {
    const std::string name = c["size_mm"] == 65 ? "m5_65mm_1m_850lx_1.mkv" : "m5_39mm_2m_500lx_1.mkv";
    if (!c.contains("results") || !c["results"].contains("arwb") || c["results"]["arwb"].value("frames", 0) == 0)
      continue;   // a cell of the grid no clip was filmed in
    ++cells;
    EXPECT_EQ(c["results"]["arwb"]["frames"], frames[name]) << c.dump();
    EXPECT_EQ(c["results"]["arwb"]["detected"], frames[name]) << c.dump();
  }
  EXPECT_EQ(cells, 2) << lab.out;
}

}  // namespace
}  // namespace arwb
