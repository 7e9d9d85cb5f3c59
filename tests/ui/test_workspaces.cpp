// The tiled workspaces (ui/workspace.hpp), run for real under xvfb-run: each shipped workspace at 1280x720,
// 1600x900 and 1920x1080, in normal and presentation mode, has no regions overlapping and nothing cut off (the
// --stats "layout" audit, built on ImGui's own rectangles), shows the live view with its marker outlines (the
// screenshot), and gives presentation mode large text and most of the screen to the image; the arrangement is
// kept between runs; a user's own workspace is saved; a bad workspaces file falls back to the shipped ones.
#include "support/support.hpp"
#include "synth/chessboard_view.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace arwb {
namespace {

using Json = nlohmann::ordered_json;
using test::RunResult;
using test::TempDir;

Json layout_of(const RunResult& r) {
  const Json s = test::stats(r);
  if (s.contains("layout")) return s["layout"];
  ADD_FAILURE() << "no layout in the --stats line: " << r.out;
  return Json::object();
}

// The region (its JSON) showing panel `key`, or null.
const Json* region_with(const Json& layout, const std::string& key) {
  if (!layout.contains("regions")) return nullptr;
  for (const Json& r : layout["regions"]) {
    for (const Json& p : r["panels"])
      if (p == key) return &r;
  }
  return nullptr;
}

double area(const Json& region) { return region["rect"][2].get<double>() * region["rect"][3].get<double>(); }

// The live view's accepted-marker outline colour (ui/widgets.cpp accepted_colour: 0.1, 1.0, 0.2).
int green_pixels(const cv::Mat& shot, cv::Rect area) {
  area &= cv::Rect(0, 0, shot.cols, shot.rows);
  int n = 0;
  for (int y = area.y; y < area.br().y; ++y) {
    for (int x = area.x; x < area.br().x; ++x) {
      const cv::Vec3b& p = shot.at<cv::Vec3b>(y, x);
      n += p[1] > 225 && p[2] < 90 && p[0] < 110;
    }
  }
  return n;
}

struct Shipped {
  const char* name;
  std::vector<const char*> panels;   // every panel the workspace shows, the ones to leave in front last
  const char* extra;                 // more arguments (a scene for Script)
  const char* before = "";           // actions after switching to it (Calibrate: wait for views and a solve)
};

// Every tab of the workspace is brought to the front for a few frames (open=), so each panel is audited, then
// the main ones are left in front for the screenshot. A candidate is selected so the inspector has content.
std::string visit_all(const Shipped& w) {
  std::string a = std::string("1:workspace=") + w.name + w.before + ";1:freeze;3:select=marker";
  int frame = 6;
  for (const char* p : w.panels) {
    a += ';';
    a += std::to_string(frame);
    a += ":open=";
    a += p;
    frame += 4;
  }
  return a;
}

const Shipped kInspect{"Inspect",
                       {"log", "dictionary", "why", "source", "peers", "inspector", "candidates", "parameters",
                        "timings", "pipeline", "live_view"},
                       ""};
const Shipped kScript{"Script", {"log", "console", "scene", "script", "live_view"}, "--scene '" ARWB_SOURCE_DIR "/scripts/museum/museum.lua'"};
const Shipped kTeach{"Teach", {"candidates", "inspector", "tour", "pipeline", "live_view"}, ""};
// On a folder of chessboard views, with views kept and solved before the panels are visited, so that every part
// of the coach (checklist, bars, the camera's table, the per-view bars, the maps) is drawn and audited.
const std::string& chessboard_source() {
  static TempDir dir;   // kept for the binary's life, removed at its exit
  static const std::string arg = [] {
    const SynthCamera camera;
    const SynthChessboard board{9, 6, 0.025, 1.0};
    const ChessboardRenderer renderer(camera, board);
    const auto poses = chessboard_poses(camera, board, 8, 3);
    for (size_t i = 0; i < poses.size(); ++i)
      cv::imwrite(dir.str("board_" + std::to_string(i) + ".png"),
                  renderer.render(poses[i].first, poses[i].second, 0.6, 2.0, unsigned(i + 1)).image);
    return "--source '" + dir.str() + "'";
  }();
  return arg;
}
// The folder at 8 images a second: the views are kept as fast as the board search takes them (at 1 a second,
// calib_wait=7 had waited 7 s of each run on the clock).
const Shipped kCalibrate{"Calibrate", {"log", "source", "calibration_views", "calibrate", "live_view"}, "",
                         ";1:speed=8;1:calib_wait=7"};
// A small plan run to the end, its grid drawn and a cell open in the live view (26 mm at 0.5 m: detected), so
// the plan, the progress, the grid and the cell's strips are all audited (850 lx: no shadows or glints).
const Shipped kLab{"Lab",
                   {"log", "pipeline", "inspector", "source", "parameters", "candidates", "why", "lab", "live_view"},
                   "",
                   ";1:lab_axis=sizes_mm:65,26;1:lab_axis=distances_m:0.5,2;1:lab_axis=lux:850;1:lab_frames=4;1:lab_run;"
                   "1:lab_wait;"
                   "2:lab_cell=2,0"};

// One workspace at one window size, in normal then presentation mode: nothing overlaps, nothing is cut off,
// the regions tile the window, the live view shows the markers; presentation mode has large text and gives the
// live view and the stage most of the screen.
void fits(const Shipped& w, int width, int height) {
  for (bool present : {false, true}) {
    SCOPED_TRACE(std::string(w.name) + " at " + std::to_string(width) + "x" + std::to_string(height) +
                 (present ? " in presentation mode" : ""));
    TempDir tmp;
    const std::string shot = tmp.str("shot.png");
    const int frames = 10 + 4 * static_cast<int>(w.panels.size()) + 6;
    const bool calibrate = w.name == std::string("Calibrate");
    const RunResult r = test::run_arwb_window(
        "--config-dir '" + tmp.str("config") + "' --size " + std::to_string(width) + "x" + std::to_string(height) +
        (present ? " --presentation" : "") + " --frames " + std::to_string(frames) + " --stats --screenshot '" + shot +
        "' " + (calibrate ? chessboard_source() : std::string(w.extra)) + " --actions '" + visit_all(w) + (w.name == std::string("Teach") ? ";2:tour=2" : "") + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    const Json l = layout_of(r);
    ASSERT_TRUE(l.contains("regions")) << r.out;
    EXPECT_EQ(l["workspace"], w.name);
    EXPECT_EQ(l["presentation"], present);
    EXPECT_EQ(l["overlaps"], 0) << l.dump();
    EXPECT_TRUE(l["clipped"].empty()) << "cut off: " << l["clipped"].dump(1);
    EXPECT_EQ(l["off_screen"], Json::array()) << "past the screen's edge";
    // A software renderer (llvmpipe, no GPU) pays for every pixel drawn: the window's background is the clear
    // colour, and a region's picture is not drawn over a backdrop of its own size (1.7 when both were).
    const double overdraw = test::stats(r)["ui_fill"]["overdraw"].get<double>();
    std::printf("%s %dx%d%s: overdraw %.2f\n", w.name, width, height, present ? " presentation" : "", overdraw);
    EXPECT_LT(overdraw, 1.2) << "pixels drawn over each other";
    // Every panel is in some region, and the regions cover the main area (no hole, no overlap: the sum).
    for (const char* p : w.panels) EXPECT_NE(region_with(l, p), nullptr) << p << " not shown: " << l.dump();
    double covered = 0;
    for (const Json& reg : l["regions"]) {
      const Json& rc = reg["rect"];
      EXPECT_GE(rc[0].get<int>(), 0);
      EXPECT_LE(rc[0].get<int>() + rc[2].get<int>(), width);
      EXPECT_LE(rc[1].get<int>() + rc[3].get<int>(), height);
      EXPECT_GT(rc[2].get<int>(), 100) << reg.dump();
      EXPECT_GT(rc[3].get<int>(), 60) << reg.dump();
      covered += area(reg);
    }
    EXPECT_GT(covered, 0.8 * width * height) << l.dump();
    const Json* live = region_with(l, "live_view");
    ASSERT_NE(live, nullptr);
    const bool script = w.name == std::string("Script");
    if (present) {
      // The teacher's screen: text of 28 px or more at 1080 lines, and the image and the stage on most of it
      // (Script keeps half the width for the editor).
      if (height >= 1080) {
        EXPECT_GE(l["font_px"].get<double>(), 28.0);
      }
      EXPECT_GT(l["font_px"].get<double>(), 15.0);
      if (script) {
        EXPECT_GT(area(*live), 0.3 * width * height) << l.dump();
      } else if (calibrate) {
        EXPECT_GT(area(*live), 0.5 * width * height) << l.dump();
      } else {
        const Json* stage = region_with(l, "pipeline");
        ASSERT_NE(stage, nullptr);
        EXPECT_GT(area(*live) + area(*stage), 0.5 * width * height) << l.dump();
      }
    }
    // The screenshot shows the accepted markers' outlines inside the live view's region (the scene's media
    // cover them in Script).
    const cv::Mat img = cv::imread(shot);
    ASSERT_EQ(img.size(), cv::Size(width, height));
    const Json& rc = (*live)["rect"];
    const cv::Rect live_rect(rc[0].get<int>(), rc[1].get<int>(), rc[2].get<int>(), rc[3].get<int>());
    if (calibrate) {
      // The coach had something to show: views kept and solved.
      const Json c = test::stats(r)["calibration"];
      EXPECT_GE(c["views"].get<int>(), 7) << c.dump();
      EXPECT_TRUE(c.contains("checklist")) << c.dump();
    } else if (!script) {
      EXPECT_GT(green_pixels(img, live_rect), 100);
    }
  }
}

// The tour in presentation mode at 1920x1080, every step: its title, Look line and Try controls show without
// scrolling under the two pictures (they came after the text, which ran past the panel's bottom); the text
// follows in a panel of its own.
TEST(Workspaces, TheToursLookAndTryLinesShowAtEveryStepOnAProjector) {
  TempDir tmp;
  std::string steps = "1:workspace=Teach;2:presentation";
  for (int i = 0; i < 20; ++i) steps += ";" + std::to_string(4 + 3 * i) + ":tour=" + std::to_string(i);
  const RunResult r = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --size 1920x1080 --frames 66 "
                                            "--stats --actions '" + steps + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json s = test::stats(r);
  EXPECT_EQ(s["tour_step"], "summary") << "every step was visited";
  EXPECT_EQ(s["tour_overflow_px"], 0) << "a step's Look or Try ran past the tour's panel";
}

// A teacher at a projector opens both Help windows, and the marker sheet dialog: in presentation mode, whose
// sizes are twice the normal ones at 1080 lines, each stays on the screen (they ran off its left and right edges).
TEST(Workspaces, HelpWindowsAndDialogsStayOnScreenInPresentationMode) {
  for (const char* size : {"1920x1080", "1280x720"}) {
    SCOPED_TRACE(size);
    TempDir tmp;
    const RunResult r = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --size " + size +
                                              " --presentation --frames 14 --stats --actions "
                                              "'2:help=shortcuts;3:help=first;4:sheet'");
    ASSERT_EQ(r.status, 0) << r.err;
    const Json l = layout_of(r);
    EXPECT_EQ(l["presentation"], true);
    EXPECT_EQ(l["off_screen"], Json::array()) << l.dump();
  }
}

// Stage pictures a class reads from the back of the room: in presentation mode at 1920x1080 the outlines are made
// wide enough for the picture's zoom (about 3 screen pixels), and the mosaics' labels and the markers' ids are
// drawn by the window in its 30 px type, not into the picture in a 12 px pixel font. In the normal mode they are
// drawn in, 1 px, as a snapshot's are.
TEST(Workspaces, StagePicturesOnAProjectorHaveWideLinesAndLargeText) {
  const auto stage_views = [](const std::string& actions) {
    TempDir tmp;
    const RunResult r = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --size 1920x1080 --frames 14 "
                                              "--stats --actions '1:workspace=Teach;" + actions + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    const Json s = test::stats(r);
    EXPECT_TRUE(s.contains("stage_views")) << r.out;
    return s.value("stage_views", Json::object());
  };
  Json v = stage_views("2:presentation;4:tour=quad_fit;8:tour=identification");
  EXPECT_EQ(v["text_drawn_in"], false) << v.dump();
  EXPECT_GE(v["line"].get<int>(), 2) << v.dump();
  const double wide = v["line"].get<double>() * v["zoom"].get<double>();   // screen pixels
  EXPECT_GE(wide, 2.5) << v.dump();
  EXPECT_LE(wide, 4.5) << v.dump();
  EXPECT_GT(v["labels_drawn"].get<int>(), 0) << v.dump();
  EXPECT_GE(v["label_px"].get<double>(), 20) << v.dump();

  v = stage_views("2:presentation;4:tour=duplicates");
  EXPECT_GT(v["labels_drawn"].get<int>(), 0) << "the markers' ids: " << v.dump();
  EXPECT_GE(v["label_px"].get<double>(), 28) << v.dump();

  v = stage_views("3:tour=identification");
  EXPECT_EQ(v["text_drawn_in"], true) << v.dump();
  EXPECT_EQ(v["line"], 1) << v.dump();
  EXPECT_EQ(v["labels_drawn"], 0) << v.dump();
}

TEST(Workspaces, InspectFitsAt1280x720) { fits(kInspect, 1280, 720); }
TEST(Workspaces, InspectFitsAt1600x900) { fits(kInspect, 1600, 900); }
TEST(Workspaces, InspectFitsAt1920x1080) { fits(kInspect, 1920, 1080); }
TEST(Workspaces, ScriptFitsAt1280x720) { fits(kScript, 1280, 720); }
TEST(Workspaces, ScriptFitsAt1600x900) { fits(kScript, 1600, 900); }
TEST(Workspaces, ScriptFitsAt1920x1080) { fits(kScript, 1920, 1080); }
TEST(Workspaces, TeachFitsAt1280x720) { fits(kTeach, 1280, 720); }
TEST(Workspaces, TeachFitsAt1600x900) { fits(kTeach, 1600, 900); }
TEST(Workspaces, TeachFitsAt1920x1080) { fits(kTeach, 1920, 1080); }
TEST(Workspaces, CalibrateFitsAt1280x720) { fits(kCalibrate, 1280, 720); }
TEST(Workspaces, CalibrateFitsAt1600x900) { fits(kCalibrate, 1600, 900); }
TEST(Workspaces, CalibrateFitsAt1920x1080) { fits(kCalibrate, 1920, 1080); }
TEST(Workspaces, LabFitsAt1280x720) { fits(kLab, 1280, 720); }
TEST(Workspaces, LabFitsAt1600x900) { fits(kLab, 1600, 900); }
TEST(Workspaces, LabFitsAt1920x1080) { fits(kLab, 1920, 1080); }

std::string args(const TempDir& tmp, const std::string& more) {
  return "--config-dir '" + tmp.str("config") + "' --frames 20 --stats " + more;
}

TEST(Workspaces, SplitterAndMovedPanelAreKeptBetweenRuns) {
  TempDir tmp;
  // What dragging the first splitter to 30% and the Timings tab onto the Candidates region does.
  RunResult r = test::run_arwb_window(args(tmp, "--actions '5:splitter=0,0.3;6:move=timings>candidates'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string file = test::read_file(tmp.str("config/workspaces.json"));
  EXPECT_NE(file.find("\"ratio\": 0.3"), std::string::npos) << file;
  // A second run without actions starts from that arrangement.
  r = test::run_arwb_window(args(tmp, ""));
  ASSERT_EQ(r.status, 0) << r.err;
  const Json l = layout_of(r);
  const Json* cands = region_with(l, "candidates");
  ASSERT_NE(cands, nullptr) << l.dump();
  EXPECT_EQ(cands, region_with(l, "timings")) << l.dump();
  const Json* live = region_with(l, "live_view");
  ASSERT_NE(live, nullptr);
  EXPECT_NEAR((*live)["rect"][2].get<double>(), 0.3 * 1600, 12) << l.dump();
  EXPECT_EQ(l["overlaps"], 0);
}

TEST(Workspaces, UsersSaveTheirOwnWorkspace) {
  TempDir tmp;
  RunResult r = test::run_arwb_window(args(tmp, "--actions '5:move=log>live_view;6:save_workspace=Mine'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(layout_of(r)["workspace"], "Mine");
  // Kept: the next run opens in it, with the log beside the live view.
  r = test::run_arwb_window(args(tmp, ""));
  Json l = layout_of(r);
  EXPECT_EQ(l["workspace"], "Mine");
  EXPECT_EQ(region_with(l, "log"), region_with(l, "live_view")) << l.dump();
  // The shipped workspaces are still there to switch to.
  r = test::run_arwb_window(args(tmp, "--actions '2:workspace=Teach'"));
  l = layout_of(r);
  EXPECT_EQ(l["workspace"], "Teach");
  EXPECT_NE(region_with(l, "tour"), nullptr) << l.dump();
  // A shipped name cannot be taken.
  r = test::run_arwb_window(args(tmp, "--actions '2:save_workspace=Teach'"));
  EXPECT_NE(r.err.find("'Teach' is a shipped workspace"), std::string::npos) << r.err;
}

TEST(Workspaces, ActionsSwitchWorkspaceAndBringPanelsToFront) {
  TempDir tmp;
  // In the same frame as the switch: the opened panel goes into the new workspace.
  RunResult r = test::run_arwb_window(args(tmp, "--actions '2:workspace=Script;2:open=timings;6:close=console'"));
  ASSERT_EQ(r.status, 0) << r.err;
  Json l = layout_of(r);
  EXPECT_EQ(l["workspace"], "Script");
  ASSERT_NE(region_with(l, "script"), nullptr) << l.dump();
  const Json* t = region_with(l, "timings");   // opened: added to the workspace, in front of its region
  ASSERT_NE(t, nullptr) << l.dump();
  EXPECT_EQ((*t)["front"], "timings");
  EXPECT_EQ(region_with(l, "console"), nullptr) << l.dump();
  EXPECT_EQ(l["overlaps"], 0);
  r = test::run_arwb_window(args(tmp, "--actions '2:workspace=Nowhere'"));
  EXPECT_NE(r.err.find("no workspace 'Nowhere'"), std::string::npos) << r.err;
}

TEST(Workspaces, AClosedPanelReopensBesideTheOnesItBelongsWith) {
  TempDir tmp;
  // Timings shares a region with Peers in the shipped Inspect: closed, then opened again (the View menu), it goes
  // back there, in front.
  const RunResult r = test::run_arwb_window(args(tmp, "--actions '5:close=timings;8:open=timings'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const Json l = layout_of(r);
  const Json* t = region_with(l, "timings");
  ASSERT_NE(t, nullptr) << l.dump();
  EXPECT_EQ(t, region_with(l, "peers")) << l.dump();
  EXPECT_EQ((*t)["front"], "timings");
}

TEST(Workspaces, ABadWorkspacesFileGivesAMessageAndTheShippedLayout) {
  TempDir tmp;
  std::filesystem::create_directories(tmp.str("config"));
  // Each bad file is set aside beside the ones before it, never over them.
  int n = 0;
  for (const std::string& bad :
       {std::string("{\"version\": 1, \"workspaces\": [{\"name\": \"Inspect\", \"normal\": {\"tabs\": [\"bogus\"]}, "
                    "\"presentation\": {\"tabs\": []}}]}"),
        std::string("{ not json"), std::string("{\"version\": 1, \"workspaces\": [{\"name\": \"X\", \"normal\": "
                                               "{\"split\": \"rows\", \"ratio\": 7, \"first\": {}, \"second\": {}}, "
                                               "\"presentation\": {\"tabs\": []}}]}")}) {
    test::write_file(tmp.str("config/workspaces.json"), bad);
    const RunResult r = test::run_arwb_window(args(tmp, ""));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("workspaces.json"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(the shipped workspaces are used; the file is kept as"), std::string::npos) << r.err;
    const std::string aside = tmp.str("config/workspaces.json.bad") + (++n == 1 ? "" : "." + std::to_string(n));
    EXPECT_NE(r.err.find("the file is kept as " + aside + ")"), std::string::npos) << r.err;
    EXPECT_EQ(test::read_file(aside), bad);
    const Json l = layout_of(r);
    EXPECT_EQ(l["workspace"], "Inspect");
    EXPECT_NE(region_with(l, "candidates"), nullptr) << l.dump();
  }
}

}  // namespace
}  // namespace arwb
