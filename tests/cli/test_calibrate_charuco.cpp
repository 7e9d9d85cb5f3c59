// `arwb calibrate --board charuco` run as a user runs it: `arwb synth --chessboard --board charuco` writes views
// of a known camera (a quarter of them with part of the board out of the image) and that camera; calibrating
// from them gives it back (fx, fy within 0.5 %, cx, cy within 2 px, k1 within 0.02), in a video too; a folder
// with no ChArUco board in it is one line that says boards of OpenCV's older layout are not read.
#include "calibration/calibration_file.hpp"
#include "synth/chessboard_view.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <filesystem>

using namespace arwb;
using test::run_arwb;
using test::q;
using test::TempDir;

namespace {

void expect_near_truth(const Calibration& got, const Calibration& truth) {
  EXPECT_NEAR(got.camera_matrix(0, 0), truth.camera_matrix(0, 0), 0.005 * truth.camera_matrix(0, 0));
  EXPECT_NEAR(got.camera_matrix(1, 1), truth.camera_matrix(1, 1), 0.005 * truth.camera_matrix(1, 1));
  EXPECT_NEAR(got.camera_matrix(0, 2), truth.camera_matrix(0, 2), 2.0);
  EXPECT_NEAR(got.camera_matrix(1, 2), truth.camera_matrix(1, 2), 2.0);
  EXPECT_NEAR(got.distortion[0], truth.distortion[0], 0.02);
}

TEST(CalibrateCharuco, SynthViewsWithPartialBoardsCalibrateToTheCameraWrittenBesideThem) {
  TempDir dir;
  const auto s = run_arwb("synth --chessboard --board charuco --count 20 --seed 3 --out " + q(dir.str("views")));
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_NE(s.out.find("wrote 20 views of the ChArUco 5x7 squares"), std::string::npos) << s.out;
  const Result<Calibration> truth = read_calibration(dir.str("views/truth_camera.yml"));
  ASSERT_TRUE(truth.ok()) << truth.error();
  const auto r = run_arwb("calibrate --board charuco --input " + q(dir.str("views")) + " --out " +
                          q(dir.str("cam.yml")) + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = test::parse(r.out);
  EXPECT_GE(j["views_kept"].get<int>(), 16) << r.out;
  EXPECT_NE(j["board"].get<std::string>().find("ChArUco 5x7"), std::string::npos);
  const Result<Calibration> got = read_calibration(dir.str("cam.yml"));
  ASSERT_TRUE(got.ok()) << got.error();
  expect_near_truth(*got, *truth);
  // The benchmark beside ours: OpenCV's calibrateCameraCharuco with its defaults; ours no worse.
  ASSERT_TRUE(j.contains("opencv_defaults"));
  EXPECT_LE(j["avg_reprojection_error"].get<double>(),
            j["opencv_defaults"]["avg_reprojection_error"].get<double>() + 0.01);
}

TEST(CalibrateCharuco, AVideoOfABoardHeldStillInTurnCalibrates) {
  TempDir dir;
  const SynthCamera camera;
  const BoardSpec spec{.kind = BoardKind::charuco, .cols = 5, .rows = 7, .square_mm = 35, .marker_mm = 26};
  const SynthChessboard board = SynthChessboard::of(spec);
  const ChessboardRenderer renderer(camera, board);
  auto poses = chessboard_poses(camera, board, 12, 4);
  const auto partial = partial_board_poses(camera, board, 4, 8);
  poses.insert(poses.end(), partial.begin(), partial.end());
  cv::VideoWriter w(dir.str("board.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, camera.size, false);
  ASSERT_TRUE(w.isOpened());
  for (size_t i = 0; i < poses.size(); ++i) {
    const cv::Mat image = renderer.render(poses[i].first, poses[i].second, 0.6, 1.0, unsigned(i + 1)).image;
    for (int k = 0; k < 3; ++k) w.write(image);   // held still for three frames
  }
  w.release();
  const auto r = run_arwb("calibrate --board charuco --input " + q(dir.str("board.avi")) + " --out " +
                          q(dir.str("cam.xml")) + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = test::parse(r.out);
  // The first frame of each pose is a jump from the last pose: moving; the two after it are still.
  EXPECT_GE(j["not_kept"]["moving"].get<int>(), 12) << r.out;
  EXPECT_GE(j["views_kept"].get<int>(), 12) << r.out;
  Calibration truth;
  truth.camera_matrix = camera.camera_matrix;
  truth.distortion = camera.distortion;
  const Result<Calibration> got = read_calibration(dir.str("cam.xml"));
  ASSERT_TRUE(got.ok()) << got.error();
  expect_near_truth(*got, truth);
}

TEST(CalibrateCharuco, NoChArUcoBoardIsOneLineThatNamesTheOlderLayout) {
  TempDir dir;
  const auto s = run_arwb("synth --chessboard --count 6 --seed 3 --out " + q(dir.str("views")));   // chessboards
  ASSERT_EQ(s.status, 0) << s.err;
  const auto r = run_arwb("calibrate --board charuco --input " + q(dir.str("views")) + " --out " +
                          q(dir.str("cam.xml")));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("no ChArUco 5x7 squares"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("older ChArUco layout (before 4.6"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.str("cam.xml")));
  const auto help = run_arwb("calibrate --help");
  EXPECT_NE(help.out.find("older layout"), std::string::npos) << help.out;
}

TEST(CalibrateCharuco, SynthRefusesBoardOptionsWithoutChessboardAndADictionaryTooSmall) {
  TempDir dir;
  const auto r = run_arwb("synth --board charuco --out " + q(dir.str("x")));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("are for --chessboard"), std::string::npos) << r.err;
  const auto small = run_arwb("synth --chessboard --board charuco --cols 12 --rows 12 --dict DICT_4X4_50 --out " +
                              q(dir.str("y")));
  EXPECT_EQ(small.status, 2);
  EXPECT_NE(small.err.find("has 50 markers; a 12x12 ChArUco board needs 72"), std::string::npos) << small.err;
}

}  // namespace
