// `arwb calibrate` run as a user runs it: a folder and a video of synthetic chessboard views of a known camera
// give that camera back in the file and the JSON; each kind of bad input is one line on stderr and writes nothing.
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

const SynthCamera kCamera;

// The views of the calibration tests, rendered once for the binary.
const std::vector<ChessboardView>& board_views() {
  static const std::vector<ChessboardView> views = [] {
    const ChessboardRenderer r(kCamera, SynthChessboard{});
    std::vector<ChessboardView> out;
    for (const auto& [rv, tv] : chessboard_poses(kCamera, SynthChessboard{}, 14, 21))
      out.push_back(r.render(rv, tv, 0.6, 1.5, unsigned(out.size() + 1)));
    return out;
  }();
  return views;
}

void write_views(const std::string& dir, size_t count) {
  std::filesystem::create_directories(dir);
  for (size_t i = 0; i < count && i < board_views().size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/view_%02zu.png", i);
    ASSERT_TRUE(cv::imwrite(dir + name, board_views()[i].image));
  }
}

TEST(Calibrate, AFolderOfViewsGivesTheKnownCameraInTheFileAndTheJson) {
  TempDir dir;
  write_views(dir.str("views"), 14);
  std::filesystem::create_directory(dir.str("paper"));
  const auto r = run_arwb("calibrate --input " + q(dir.str("views")) + " --out " + q(dir.str("cam.yml")) +
                          " --paper-files " + q(dir.str("paper")) + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = test::parse(r.out);
  EXPECT_NEAR(j["fx"].get<double>(), 560, 0.005 * 560);
  EXPECT_NEAR(j["fy"].get<double>(), 555, 0.005 * 555);
  EXPECT_NEAR(j["cx"].get<double>(), 322, 2);
  EXPECT_NEAR(j["cy"].get<double>(), 236, 2);
  EXPECT_NEAR(j["distortion_coefficients"][0].get<double>(), -0.25, 0.02);
  EXPECT_EQ(j["frames_read"], 14);
  EXPECT_EQ(j["report"]["checklist"].size(), 5u);
  EXPECT_TRUE(j["report"]["per_view_errors_worst_first"].is_array());
  const Result<Calibration> file = read_calibration(dir.str("cam.yml"));
  ASSERT_TRUE(file.ok()) << file.error();
  EXPECT_DOUBLE_EQ(file->camera_matrix(0, 0), j["fx"].get<double>());
  EXPECT_EQ(file->image_size, cv::Size(640, 480));
  const Result<Calibration> paper = read_calibration(dir.str("paper/cameraMatrix.xml"));
  ASSERT_TRUE(paper.ok()) << paper.error();
  EXPECT_EQ(paper->distortion, file->distortion);
}

// Views named in Latin-1 (vue_\xe9t\xe9_00.png: not UTF-8): the JSON names them with U+FFFD for each bad byte and
// the run exits 0 having written its file (it wrote the calibration, then exited 1 with nlohmann's type_error.316).
TEST(Calibrate, ViewsNamedInLatin1AreInTheJsonWithTheBadBytesReplaced) {
  TempDir dir;
  write_views(dir.str("views"), 14);
  for (const auto& e : std::filesystem::directory_iterator(dir.str("views"))) {
    const std::string name = e.path().filename().string();
    std::filesystem::rename(e.path(), e.path().parent_path() / ("vue_\xe9t\xe9_" + name.substr(5)));
  }
  const auto r = run_arwb("calibrate --input " + q(dir.str("views")) + " --out " + q(dir.str("cam.yml")) + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = test::parse(r.out);   // throws on text that is not UTF-8
  EXPECT_NE(r.out.find("vue_\xef\xbf\xbdt\xef\xbf\xbd_"), std::string::npos) << r.out.substr(0, 2000);
  EXPECT_EQ(j["frames_read"], 14);
  EXPECT_TRUE(read_calibration(dir.str("cam.yml")).ok());
}

TEST(Calibrate, AVideoKeepsOnlyStillViewsAndSaysWhyOthersWereNot) {
  TempDir dir;
  cv::VideoWriter w(dir.str("board.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, kCamera.size, false);
  ASSERT_TRUE(w.isOpened());
  // Each pose held for three frames: the first of each is the board arriving (moving), the second kept, the
  // third like the second.
  for (const ChessboardView& v : board_views())
    for (int k = 0; k < 3; ++k) w.write(v.image);
  w.release();
  const auto r = run_arwb("calibrate --input " + q(dir.str("board.avi")) + " --out " + q(dir.str("cam.xml")) +
                          " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = test::parse(r.out);
  EXPECT_EQ(j["frames_read"], 42);
  EXPECT_GE(j["views_kept"].get<int>(), 12);
  EXPECT_GE(j["not_kept"]["moving"].get<int>(), 12);
  EXPECT_GE(j["not_kept"]["similar"].get<int>(), 12);
  EXPECT_NEAR(j["fx"].get<double>(), 560, 0.01 * 560);   // JPEG-compressed frames: a looser bound
  EXPECT_TRUE(read_calibration(dir.str("cam.xml")).ok());
}

struct Bad {
  std::string args;
  std::string says;
};

void expect_one_line_and_nothing_written(const TempDir& dir, const std::string& args, const std::string& says,
                                         int status = 1) {
  const auto r = run_arwb("calibrate " + args);
  EXPECT_EQ(r.status, status) << r.err;
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir.path())) {
    const std::string n = e.path().filename().string();
    EXPECT_TRUE(n.rfind("cam.", 0) != 0 && n.find("arwb-saving") == std::string::npos) << "written: " << e.path();
  }
}

TEST(Calibrate, TooFewViews) {
  TempDir dir;
  write_views(dir.str("views"), 3);
  expect_one_line_and_nothing_written(dir, "--input " + q(dir.str("views")) + " --out " + q(dir.str("cam.xml")),
                                      "3 views; at least 6 are needed");
}

TEST(Calibrate, NoBoardInAnyFrame) {
  TempDir dir;
  std::filesystem::create_directory(dir.str("grey"));
  for (int i = 0; i < 3; ++i)
    cv::imwrite(dir.str("grey/" + std::to_string(i) + ".png"), cv::Mat(480, 640, CV_8UC1, cv::Scalar(40 + 50 * i)));
  expect_one_line_and_nothing_written(dir, "--input " + q(dir.str("grey")) + " --out " + q(dir.str("cam.xml")),
                                      "no 9x6 chessboard in any of the 3 frames of " + dir.str("grey"));
}

TEST(Calibrate, AWrongBoardSizeNamesTheSizeFound) {
  TempDir dir;
  write_views(dir.str("views"), 2);
  // Smaller and larger than printed: OpenCV's detector alone would find a 7x5 grid along the board's outer edge.
  // (6x9 is the same board turned, which OpenCV reads: not an error.)
  for (const std::string size : {"--cols 7 --rows 5", "--cols 10 --rows 7", "--cols 8 --rows 6"}) {
    const auto r = run_arwb("calibrate --input " + q(dir.str("views")) + " " + size + " --out " + q(dir.str("cam.xml")));
    EXPECT_EQ(r.status, 1) << size;
    EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("chessboard"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("a 9x6 chessboard is in view_00.png: give --cols 9 --rows 6"), std::string::npos)
        << size << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.str("cam.xml")));
  }
}

TEST(Calibrate, FramesOfDifferentSizes) {
  TempDir dir;
  write_views(dir.str("views"), 2);
  cv::imwrite(dir.str("views/view_99.png"), cv::Mat(600, 800, CV_8UC1, cv::Scalar(128)));
  expect_one_line_and_nothing_written(dir, "--input " + q(dir.str("views")) + " --out " + q(dir.str("cam.xml")),
                                      "view_99.png: 800x600, but view_00.png is 640x480; calibrate one camera at one size");
}

TEST(Calibrate, AnUnwritableOutputFolderIsRefusedBeforeReading) {
  TempDir dir;
  write_views(dir.str("views"), 1);
  expect_one_line_and_nothing_written(dir, "--input " + q(dir.str("views")) + " --out " + q(dir.str("none/cam.xml")),
                                      dir.str("none/cam.xml") + ": cannot write (no such folder");
  expect_one_line_and_nothing_written(
      dir, "--input " + q(dir.str("views")) + " --out " + q(dir.str("cam.xml")) + " --paper-files " + q(dir.str("nope")),
      "--paper-files " + dir.str("nope") + ": no such folder");
}

// A folder that exists but where no file can be made (procfs here, which refuses even root): said before the
// input is read, for the calibration file and for the paper's files. And when the paper's files cannot be
// written at the end, the calibration file is not written either: the run writes all it was asked for, or nothing.
TEST(Calibrate, AFolderThatCannotBeWrittenIsSaidBeforeReadingAndNothingIsWrittenHalf) {
  TempDir dir;
  write_views(dir.str("views"), 1);
  expect_one_line_and_nothing_written(dir, "--input " + q(dir.str("views")) + " --out /proc/cam.xml",
                                      "/proc/cam.xml: cannot write in /proc (");
  expect_one_line_and_nothing_written(
      dir, "--input " + q(dir.str("views")) + " --out " + q(dir.str("cam.xml")) + " --paper-files /proc",
      "--paper-files /proc: cannot write there (");
  write_views(dir.str("views"), 8);
  std::filesystem::create_directories(dir.str("paper/distCoeffs.xml.arwb-saving"));   // its temporary file's place
  const auto r = run_arwb("calibrate --input " + q(dir.str("views")) + " --out " + q(dir.str("cam.xml")) +
                          " --paper-files " + q(dir.str("paper")));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find(dir.str("paper/distCoeffs.xml") + ": cannot write"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.str("cam.xml")));
  EXPECT_FALSE(std::filesystem::exists(dir.str("paper/cameraMatrix.xml")));
}

TEST(Calibrate, ATruncatedVideoIsNamed) {
  TempDir dir;
  cv::VideoWriter w(dir.str("board.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, kCamera.size, false);
  for (int k = 0; k < 6; ++k) w.write(board_views()[0].image);
  w.release();
  std::string bytes = test::read_file(dir.str("board.avi"));
  test::write_file(dir.str("cut.avi"), bytes.substr(0, 2000));   // the header and not one whole frame
  expect_one_line_and_nothing_written(dir, "--input " + q(dir.str("cut.avi")) + " --out " + q(dir.str("cam.xml")),
                                      dir.str("cut.avi") + ": ");
}

TEST(Calibrate, ACorruptVideoIsNamed) {
  TempDir dir;
  test::write_file(dir.str("board.mp4"), std::string(4096, '\x5a'));   // a video's name, no video's bytes
  const auto r = run_arwb("calibrate --input " + q(dir.str("board.mp4")) + " --out " + q(dir.str("cam.xml")));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find(dir.str("board.mp4")), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.str("cam.xml")));
}

TEST(Calibrate, ACameraThatCannotBeOpenedIsNamedAndABadCameraArgumentIsAUsageError) {
  // No camera is promised on a test machine: what can be tested is the refusal, by name, before anything is written.
  TempDir dir;
  expect_one_line_and_nothing_written(dir, "--input camera:63 --out " + q(dir.str("cam.xml")),
                                      "camera:63: cannot open /dev/video63");
  expect_one_line_and_nothing_written(dir, "--input camera:front --out " + q(dir.str("cam.xml")),
                                      "camera:front: the camera must be a device number", 2);
  expect_one_line_and_nothing_written(dir, "--input camera:0@big --out " + q(dir.str("cam.xml")),
                                      "the resolution must be WxH", 2);
}

}  // namespace

namespace {

// At the default 640x480, and at a 16:9 size given with --size (it was ignored: the views came out 640x480).
TEST(Calibrate, SynthChessboardViewsCalibrateToTheCameraWrittenBesideThem) {
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(960, 540)}) {
    SCOPED_TRACE(size);
    TempDir dir;
    const std::string size_arg = size.width == 640 ? "" : " --size 960x540";
    const auto s = run_arwb("synth --chessboard --count 12 --seed 3" + size_arg + " --out " + q(dir.str("views")));
    ASSERT_EQ(s.status, 0) << s.err;
    EXPECT_EQ(cv::imread(dir.str("views/board_000.png")).size(), size);
    const Result<Calibration> truth = read_calibration(dir.str("views/truth_camera.yml"));
    ASSERT_TRUE(truth.ok()) << truth.error();
    EXPECT_EQ(truth->image_size, size);
    const auto r = run_arwb("calibrate --input " + q(dir.str("views")) + " --out " + q(dir.str("cam.yml")));
    ASSERT_EQ(r.status, 0) << r.err;
    const Result<Calibration> got = read_calibration(dir.str("cam.yml"));
    ASSERT_TRUE(got.ok()) << got.error();
    EXPECT_EQ(got->image_size, size);
    EXPECT_NEAR(got->camera_matrix(0, 0), truth->camera_matrix(0, 0), 0.005 * truth->camera_matrix(0, 0));
    EXPECT_NEAR(got->camera_matrix(1, 2), truth->camera_matrix(1, 2), 2.0 * size.width / 640);
    EXPECT_NEAR(got->distortion[0], truth->distortion[0], 0.02);
  }
}

}  // namespace
