// The Calibrate workspace, run for real under xvfb-run on a folder of chessboard views (synthetic views of a
// known camera); calib_wait makes the runs independent of the machine's speed: it fills up over the frames (views kept, frames refused by reason,
// a solve with its checklist near the truth), calib_drop takes a view out and the worker solves again without it,
// calib_save writes a file the shared reader reads back, and --calib with a bad file says what and where
// while the window runs on, a good one drives the undistorted view.
#include "calibration/calibration_file.hpp"
#include "synth/chessboard_view.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <string>

namespace arwb {
namespace {

namespace fs = std::filesystem;
using test::RunResult;
using test::TempDir;
using Json = nlohmann::ordered_json;

// `count` views of the paper's board through `camera` (poses drawn from `seed`) written to `dir` as board_NN.png.
void write_board_views(const TempDir& dir, const SynthCamera& camera, int count, unsigned seed) {
  const SynthChessboard board{9, 6, 0.025, 1.0};
  const ChessboardRenderer renderer(camera, board);
  const auto poses = chessboard_poses(camera, board, count, seed);
  for (size_t i = 0; i < poses.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "board_%02zu.png", i);
    ASSERT_TRUE(cv::imwrite(dir.str(name), renderer.render(poses[i].first, poses[i].second, 0.6, 2.0, unsigned(i + 1)).image));
  }
}

// A folder of 16 views of the paper's board (the folder source plays one a second, and its frames are judged as
// stills), made once per binary.
const std::string& chessboard_folder() {
  static TempDir dir;   // kept for the binary's life, removed at its exit
  static const std::string path = [] {
    write_board_views(dir, SynthCamera{}, 16, 7);
    return dir.str();
  }();
  return path;
}

using test::stats;

std::string args(const TempDir& tmp, const std::string& more) {
  return "--config-dir '" + tmp.str("config") + "' --source '" + chessboard_folder() + "' --stats " + more;
}

TEST(CalibrateWorkspace, FillsUpOverTheFramesAndSolvesNearTheTruth) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(args(tmp, "--frames 12 --actions '1:workspace=Calibrate;2:calib_wait=10'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const Json c = stats(r)["calibration"];
  ASSERT_TRUE(c.is_object()) << r.out;
  EXPECT_TRUE(c["active"].get<bool>());
  EXPECT_GE(c["frames"].get<int>(), 10) << c.dump();
  EXPECT_GE(c["views"].get<int>(), 10) << c.dump();
  ASSERT_TRUE(c.contains("checklist")) << "no solve: " << c.dump();
  EXPECT_EQ(c["checklist"].size(), 5u);
  EXPECT_EQ(c["checklist"][0]["name"], "enough views");
  EXPECT_TRUE(c["checklist"][0]["ok"].get<bool>()) << c.dump();
  EXPECT_LT(c["rms"].get<double>(), 1.0);
  const SynthCamera truth;
  EXPECT_NEAR(c["fx"].get<double>(), truth.camera_matrix(0, 0), 0.01 * truth.camera_matrix(0, 0)) << c.dump();
  EXPECT_NEAR(c["fy"].get<double>(), truth.camera_matrix(1, 1), 0.01 * truth.camera_matrix(1, 1)) << c.dump();
  EXPECT_GT(c["coverage"]["x"].get<double>(), 0.3);
}

// What a teacher does without a camera: the synthetic source shows the workspace's board through its known lens,
// the solve comes out beside that truth, and leaving the workspace brings the markers back. The board moves from
// pose to pose and holds each for 1.1 s of the source's clock; --synthetic-step moves that clock a quarter second
// per frame and has every frame judged, so that a slow machine (a sanitizer, a loaded CPU), whose board search
// takes longer than a pause, still sees each pause as four or five still frames, not every frame "moving".
TEST(CalibrateWorkspace, OnTheSyntheticSourceTheBoardComesAndTheTruthIsBesideTheResult) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --stats --frames 40 "
                                            "--synthetic-step 0.25 --actions '1:workspace=Calibrate;2:calib_wait=8'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json s = stats(r);
  const Json c = s["calibration"];
  ASSERT_TRUE(c.contains("truth")) << "no synthetic camera to compare with: " << c.dump();
  ASSERT_TRUE(c.contains("fx")) << "no solve: " << c.dump();
  EXPECT_GE(c["solved_views"].get<int>(), 8) << c.dump();
  // The board moved between its pauses, and no frame went by unjudged.
  EXPECT_GE(c["refused"].value("moving", 0), 8) << c.dump();
  EXPECT_EQ(c["skipped"], 0) << c.dump();
  for (const char* k : {"fx", "fy"})
    EXPECT_NEAR(c[k].get<double>(), c["truth"][k].get<double>(), 0.01 * c["truth"][k].get<double>()) << k << c.dump();
  for (const char* k : {"cx", "cy"})
    EXPECT_NEAR(c[k].get<double>(), c["truth"][k].get<double>(), 3.0) << k << c.dump();
  EXPECT_EQ(s["synthetic_board"], "chessboard");
  // Frozen, the frame shown is searched too (it may have come while the search was busy): its board is drawn. On
  // the wall clock, not stepped, so that the search skips frames as it does live.
  const RunResult frozen = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --stats --frames 60 "
                                                 "--actions '1:workspace=Calibrate;2:calib_wait=2;3:freeze'");
  ASSERT_EQ(frozen.status, 0) << frozen.err;
  const Json fc = stats(frozen)["calibration"];
  EXPECT_TRUE(fc.value("board_drawn", false)) << fc.dump();
  EXPECT_FALSE(fc.value("board_behind", true)) << fc.dump();
  const RunResult back = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --stats --frames 20 "
                                               "--actions '1:workspace=Calibrate;10:workspace=Inspect'");
  ASSERT_EQ(back.status, 0) << back.err;
  EXPECT_EQ(stats(back)["synthetic_board"], "") << "back in Inspect, the synthetic source shows markers again";

  // The ChArUco board: the synthetic source follows the kind of board the workspace looks for.
  const RunResult ch = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --stats --frames 20 "
                                             "--synthetic-step 0.25 --actions "
                                             "'1:workspace=Calibrate;1:calib_board=charuco;3:calib_wait=6'");
  ASSERT_EQ(ch.status, 0) << ch.err;
  const Json sc = stats(ch);
  EXPECT_EQ(sc["synthetic_board"], "charuco");
  EXPECT_GE(sc["calibration"]["views"].get<int>(), 6) << sc["calibration"].dump();
  EXPECT_NE(sc["calibration"]["board"].get<std::string>().find("ChArUco"), std::string::npos);
}

// Photographs of 16:9 (960x540 here) are worked at 640x360, but the board is searched and the camera solved at the
// photographs' own size, as `arwb calibrate` does: the two give the same camera (before, the window solved the
// working image, fx 2/3 of the photographs', and a 4:3 working size made fy/fx 0.75 with every check "ok").
TEST(CalibrateWorkspace, SixteenByNinePhotographsGiveWhatTheCommandLineGives) {
  TempDir tmp, photos;
  SynthCamera camera;
  camera.size = {960, 540};
  camera.camera_matrix = cv::Matx33d(840, 0, 483, 0, 833, 268, 0, 0, 1);
  write_board_views(photos, camera, 14, 11);
  const RunResult cli = test::run_arwb("calibrate --input '" + photos.str() + "' --out '" + tmp.str("cli.yml") + "' --json");
  ASSERT_EQ(cli.status, 0) << cli.err;
  const Json j = Json::parse(cli.out);
  const RunResult r = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --source '" + photos.str() +
                                            "' --stats --frames 12 --actions '1:workspace=Calibrate;2:calib_wait=12'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json c = stats(r)["calibration"];
  ASSERT_TRUE(c.contains("fx")) << "no solve: " << c.dump();
  EXPECT_EQ(stats(r)["working_size"], "640x360") << "the photographs are worked at 640 wide, their aspect kept";
  EXPECT_EQ(c["size"], "960x540") << "and calibrated at their own size";
  const auto value = [&](const std::string& k) {
    const Json& K = j["camera_matrix"];
    return (k == "fx" ? K[0][0] : k == "fy" ? K[1][1] : k == "cx" ? K[0][2] : K[1][2]).get<double>();
  };
  for (const char* k : {"fx", "fy", "cx", "cy"})
    std::printf("%s: arwb calibrate %.2f, the window %.2f\n", k, value(k), c[k].get<double>());
  for (const char* k : {"fx", "fy"}) {
    EXPECT_NEAR(c[k].get<double>(), value(k), 0.005 * value(k)) << k;
    EXPECT_NEAR(c[k].get<double>(), k[1] == 'x' ? 840.0 : 833.0, 0.01 * 840) << k;
  }
  for (const char* k : {"cx", "cy"}) EXPECT_NEAR(c[k].get<double>(), value(k), 3.0) << k;
  bool square = false;
  for (const Json& check : c["checklist"]) square = square || (check["name"] == "square pixels" && check["ok"].get<bool>());
  EXPECT_TRUE(square) << c.dump();
}

TEST(CalibrateWorkspace, NothingIsLookedForOutsideTheWorkspace) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(args(tmp, "--frames 30"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(stats(r)["calibration"]["active"].get<bool>());
}

TEST(CalibrateWorkspace, AnotherBoardStartsAfreshAndABoardThatCannotExistIsRefused) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(args(
      tmp, "--frames 10 --actions '1:workspace=Calibrate;2:calib_wait=2;3:calib_board=charuco,5,7,35,40;"
           "4:calib_board=charuco;5:calib_wait'"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("--marker-mm 40.00 must be less than --square-mm 35.00"), std::string::npos) << r.err;
  const Json c = stats(r)["calibration"];
  EXPECT_NE(c["board"].get<std::string>().find("ChArUco 5x7 squares"), std::string::npos) << c.dump();
  // The chessboard's views are gone with its board, and no ChArUco board is in these frames.
  EXPECT_EQ(c["views"], 0) << c.dump();
  EXPECT_EQ(c["boards"], 0) << c.dump();
  EXPECT_GE(c["refused"]["no board"].get<int>(), 1) << c.dump();
}

TEST(CalibrateWorkspace, DroppingAViewSolvesAgainWithoutIt) {
  TempDir tmp;
  const RunResult r = test::run_arwb_window(
      args(tmp, "--verbose --frames 12 --actions "
                "'1:workspace=Calibrate;2:calib_wait=7;3:calib_capture=off;4:calib_wait;5:calib_drop=2;6:calib_wait'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const Json c = stats(r)["calibration"];
  ASSERT_TRUE(c.contains("solved_views")) << c.dump();
  EXPECT_EQ(c["dropped"], 1) << c.dump();
  EXPECT_EQ(c["views"].get<int>(), c["kept"].get<int>() - 1) << c.dump();
  EXPECT_TRUE(c["current"].get<bool>()) << "the solve after the drop had time to finish: " << c.dump();
  EXPECT_EQ(c["solved_views"], c["views"]) << c.dump();
  EXPECT_NE(r.err.find("calibration: dropped board_"), std::string::npos) << r.err;
  EXPECT_FALSE(c["capture"].get<bool>());
}

TEST(CalibrateWorkspace, SavesAFileTheReaderReadsBack) {
  TempDir tmp;
  const std::string out = tmp.str("camera.yml");
  const RunResult r = test::run_arwb_window(
      args(tmp, "--frames 8 --actions '1:workspace=Calibrate;2:calib_wait=6;3:calib_capture=off;4:calib_wait;"
                "5:calib_save=" + out + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const Json c = stats(r)["calibration"];
  ASSERT_TRUE(fs::exists(out)) << r.err;
  const Result<Calibration> back = read_calibration(out);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_NEAR(back->camera_matrix(0, 0), c["fx"].get<double>(), 0.01);
  EXPECT_NEAR(back->camera_matrix(1, 2), c["cy"].get<double>(), 0.01);
  EXPECT_EQ(back->image_size, cv::Size(640, 480));
  EXPECT_NE(stats(r)["note"].get<std::string>().find("calibration: wrote"), std::string::npos) << r.out;

  // Saving where it cannot be written: one line naming the file, nothing written, the window goes on.
  const std::string bad = tmp.str("no/such/folder/camera.yml");
  const RunResult r2 = test::run_arwb_window(
      args(tmp, "--frames 8 --actions '1:workspace=Calibrate;2:calib_wait=6;3:calib_capture=off;4:calib_wait;"
                "5:calib_save=" + bad + "'"));
  ASSERT_EQ(r2.status, 0) << r2.err;
  EXPECT_NE(r2.err.find(bad), std::string::npos) << r2.err;
  EXPECT_FALSE(fs::exists(bad));
}

TEST(CalibrateWorkspace, ABadCalibrationFileIsNamedAndTheWindowRunsOn) {
  TempDir tmp;
  const std::string bad = tmp.str("cam.yml");
  test::write_file(bad, "%YAML:1.0\ncamera_matrix: !!opencv-matrix\n  rows: 2\n  cols: 3\n  dt: d\n"
                        "  data: [ 500, 0, 320, 0, 500, 240 ]\ndistortion_coefficients: !!opencv-matrix\n"
                        "  rows: 1\n  cols: 5\n  dt: d\n  data: [ 0, 0, 0, 0, 0 ]\n");
  const RunResult r = test::run_arwb_window("--config-dir '" + tmp.str("config") +
                                            "' --source synthetic --frames 40 --stats --calib '" + bad +
                                            "' --actions '1:workspace=Calibrate;2:undistort=on'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("cam.yml: camera_matrix"), std::string::npos) << r.err;
  const Json s = stats(r);
  EXPECT_GE(s["problems"].get<int>(), 1);
  EXPECT_EQ(s["frames"], 40);
  EXPECT_EQ(s["calibration"]["loaded"], "");
  EXPECT_EQ(s["calibration"]["undistorted_by"], "");
}

TEST(CalibrateWorkspace, AGoodCalibrationFileDrivesTheUndistortedView) {
  TempDir tmp;
  const std::string good = tmp.str("cam.yml");
  Calibration c;
  // The synthetic webcam at twice its size (the same aspect ratio: scaled to the 640x480 working image).
  c.camera_matrix = cv::Matx33d(1120, 0, 644.5, 0, 1110, 472.5, 0, 0, 1);
  c.distortion = {-0.25, 0.08, 0, 0, 0};
  c.image_size = {1280, 960};
  ASSERT_TRUE(write_calibration(good, c, {}).ok());
  const RunResult r = test::run_arwb_window("--config-dir '" + tmp.str("config") +
                                            "' --source synthetic --frames 40 --stats --calib '" + good +
                                            "' --actions '1:workspace=Calibrate;2:undistort=on;3:calib_wait'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json s = stats(r);
  EXPECT_EQ(s["problems"], 0) << r.err;
  EXPECT_NE(s["calibration"]["loaded"].get<std::string>().find("cam.yml"), std::string::npos) << s.dump();
  EXPECT_NE(s["calibration"]["undistorted_by"].get<std::string>().find("cam.yml"), std::string::npos) << s.dump();

  // Another aspect ratio cannot be scaled: refused with the sizes, and nothing undistorts.
  c.image_size = {1280, 720};
  ASSERT_TRUE(write_calibration(good, c, {}).ok());
  const RunResult r2 = test::run_arwb_window("--config-dir '" + tmp.str("config") +
                                             "' --source synthetic --frames 40 --stats --calib '" + good +
                                             "' --actions '1:workspace=Calibrate;2:undistort=on'");
  ASSERT_EQ(r2.status, 0) << r2.err;
  EXPECT_NE(r2.err.find("1280x720"), std::string::npos) << r2.err;
  EXPECT_EQ(stats(r2)["calibration"]["undistorted_by"], "");
}

}  // namespace
}  // namespace arwb
