// The synthetic source's board mode, as the Calibrate workspace uses it: frames of the source showing the paper's
// chessboard or the ChArUco board, read at the workbench's pace through detect_board, ViewSelector and
// solve_calibration, give back the camera the source says it shows them through (board_camera()).
#include "calibration/board.hpp"
#include "calibration/solve.hpp"
#include "synth/synthetic_source.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cstdio>

namespace arwb {
namespace {

struct Run {
  std::vector<CalibrationView> views;
  int frames = 0, boards = 0;
  std::map<std::string, int> tally;
};

// `poses` of the board's poses at `fps` frames a second of the source's clock (fewer than the workbench's 20: the
// chessboard's detection costs a tenth of a second on a moving board).
Run watch(SyntheticSource& src, const BoardSpec& spec, double fps, int poses) {
  Run r;
  ViewSelector sel(spec, SelectOptions{});
  const double loop = (SyntheticWorld::kBoardMoveS + SyntheticWorld::kBoardHoldS) * poses;
  cv::Mat frame, grey;
  for (double t = 0; t < loop; t += 1 / fps) {
    src.next(t, frame);
    if (!src.board_camera()) break;
    if (t > 0 && src.world().controls().time_s >= loop) break;
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    const BoardDetection d = detect_board(grey, spec);
    r.boards += d.found;
    const Verdict v = sel.consider(d, frame.size());
    ++r.tally[v.kind];
    if (v.keep) r.views.push_back({"frame " + std::to_string(r.frames), d.corners, d.ids});
    ++r.frames;
  }
  return r;
}

void expect_calibrates(const std::string& board, double fps, int poses) {
  SyntheticSource src;
  EXPECT_EQ(src.board_camera(), nullptr) << "markers are shown: no board camera";
  SyntheticControls c = src.world().controls();
  c.board = board;
  c.noise = 2;
  src.world().set_controls(c);
  const SynthCamera* camera = src.board_camera();
  ASSERT_NE(camera, nullptr);
  const BoardSpec spec = SyntheticWorld::board_spec(board);
  const Run r = watch(src, spec, fps, poses);
  std::printf("%s: %d frames, board in %d, %zu views kept;", board.c_str(), r.frames, r.boards, r.views.size());
  for (const auto& [kind, n] : r.tally) std::printf(" %s %d", kind.c_str(), n);
  std::printf("\n");
  EXPECT_GT(r.tally.at("moving"), 0) << "the board must move between pauses";
  const Result<Solution> s = solve_calibration(r.views, spec, camera->size);
  ASSERT_TRUE(s.ok()) << s.error();
  const cv::Matx33d& K = s->calibration.camera_matrix;
  const cv::Matx33d& T = camera->camera_matrix;
  std::printf("%s: fx %.2f (%.2f) fy %.2f (%.2f) cx %.2f (%.2f) cy %.2f (%.2f) k1 %.4f (%.4f), rms %.3f px\n",
              board.c_str(), K(0, 0), T(0, 0), K(1, 1), T(1, 1), K(0, 2), T(0, 2), K(1, 2), T(1, 2),
              s->calibration.distortion[0], camera->distortion[0], s->rms);
  EXPECT_NEAR(K(0, 0), T(0, 0), 0.005 * T(0, 0));
  EXPECT_NEAR(K(1, 1), T(1, 1), 0.005 * T(1, 1));
  EXPECT_NEAR(K(0, 2), T(0, 2), 2.0);
  EXPECT_NEAR(K(1, 2), T(1, 2), 2.0);
  EXPECT_NEAR(s->calibration.distortion[0], camera->distortion[0], 0.02);
  // Back to markers: no board camera.
  c.board.clear();
  src.world().set_controls(c);
  EXPECT_EQ(src.board_camera(), nullptr);
}

TEST(BoardSource, TheChessboardShownCalibratesToTheBoardCamera) { expect_calibrates("chessboard", 3, 14); }

TEST(BoardSource, TheChArUcoBoardShownCalibratesToTheBoardCamera) { expect_calibrates("charuco", 4, 25); }

TEST(BoardSource, HoldsEachPoseStillForAboutASecond) {
  SyntheticSource src;
  SyntheticControls c = src.world().controls();
  c.board = "chessboard";
  c.noise = 0;
  src.world().set_controls(c);
  cv::Mat m;
  // Inside a pause two frames differ only by the light's slow swell; across a move the board is elsewhere.
  const double hold = SyntheticWorld::kBoardMoveS + 0.1;
  const cv::Mat a = src.world().render(hold).image;
  cv::absdiff(a, src.world().render(hold + 0.9).image, m);
  EXPECT_LT(cv::mean(m)[0], 3.0);
  cv::absdiff(a, src.world().render(hold + 0.9 + SyntheticWorld::kBoardHoldS).image, m);
  EXPECT_GT(cv::mean(m)[0], 10.0);
}

}  // namespace
}  // namespace arwb
