// The printed calibration board: the page is rendered through the drawing code that writes the PDF, at a known
// resolution, and OpenCV must find every inner corner where the layout says, one square apart at true size; the
// ChArUco board must be OpenCV 4.6's own (CharucoBoard::draw); boards too large for the paper are refused with the
// largest square that fits.
#include "synth/board_sheet.hpp"
#include "synth/chessboard_view.hpp"

#include <gtest/gtest.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

namespace arwb {
namespace {

constexpr double kPxPerMm = 4.0;   // 100 px a 25 mm square

BoardSpec chessboard(int cols, int rows, double square_mm) {
  BoardSpec b;
  b.cols = cols, b.rows = rows, b.square_mm = square_mm;
  return b;
}

BoardSpec charuco(int cols, int rows, double square_mm, double marker_mm, const std::string& dict) {
  BoardSpec b;
  b.kind = BoardKind::charuco;
  b.cols = cols, b.rows = rows, b.square_mm = square_mm, b.marker_mm = marker_mm, b.dictionary = dict;
  return b;
}

BoardSheetLayout layout_of(const BoardSpec& b, PaperChoice paper = PaperChoice::automatic) {
  std::string problem;
  const auto lay = board_sheet_layout(b, paper, {b.describe(), "read it with: arwb calibrate ..."}, &problem);
  EXPECT_TRUE(lay.has_value()) << problem;
  return lay.value_or(BoardSheetLayout{});
}

// Where inner corner (c, r) is on the rendered page, in pixels (a pixel's centre is at +0.5, OpenCV's at 0).
cv::Point2d expected_corner(const BoardSheetLayout& lay, int c, int r) {
  return {(lay.board_mm.x + (c + 1) * lay.board.square_mm) * kPxPerMm - 0.5,
          (lay.board_mm.y + (r + 1) * lay.board.square_mm) * kPxPerMm - 0.5};
}

// Every corner found is within half a pixel of an inner corner of the layout, each inner corner found once, and
// neighbours in the grid OpenCV returns are one square apart to within half a pixel.
void expect_chessboard_at_true_size(const BoardSheetLayout& lay) {
  const cv::Mat page = render_board_sheet(lay, kPxPerMm);
  ASSERT_EQ(page.cols, std::lround(lay.page_w_mm * kPxPerMm));
  ASSERT_EQ(page.rows, std::lround(lay.page_h_mm * kPxPerMm));
  const cv::Size n = lay.board.inner_corners();
  std::vector<cv::Point2f> corners;
  ASSERT_TRUE(cv::findChessboardCornersSB(page, n, corners, cv::CALIB_CB_ACCURACY)) << lay.board.describe();
  ASSERT_EQ(corners.size(), size_t(n.area()));
  std::vector<int> hits(corners.size(), 0);
  for (const cv::Point2f& p : corners) {
    const int c = int(std::lround(((p.x + 0.5) / kPxPerMm - lay.board_mm.x) / lay.board.square_mm)) - 1;
    const int r = int(std::lround(((p.y + 0.5) / kPxPerMm - lay.board_mm.y) / lay.board.square_mm)) - 1;
    ASSERT_TRUE(c >= 0 && c < n.width && r >= 0 && r < n.height) << p;
    const cv::Point2d e = expected_corner(lay, c, r);
    EXPECT_NEAR(p.x, e.x, 0.5) << "corner (" << c << ", " << r << ")";
    EXPECT_NEAR(p.y, e.y, 0.5) << "corner (" << c << ", " << r << ")";
    ++hits[size_t(r * n.width + c)];
  }
  for (int h : hits) EXPECT_EQ(h, 1);
  const double pitch = lay.board.square_mm * kPxPerMm;
  for (int r = 0; r < n.height; ++r)
    for (int c = 0; c < n.width; ++c) {
      const cv::Point2f p = corners[size_t(r * n.width + c)];
      if (c + 1 < n.width) {
        EXPECT_NEAR(cv::norm(corners[size_t(r * n.width + c + 1)] - p), pitch, 0.5);
      }
      if (r + 1 < n.height) {
        EXPECT_NEAR(cv::norm(corners[size_t((r + 1) * n.width + c)] - p), pitch, 0.5);
      }
    }
}

TEST(BoardSheet, ThePapersChessboardGoesOnA3LandscapeAndIsFoundAtTrueSize) {
  // 10x7 squares of 25 mm are 250 x 175 mm; with a 25 mm white border all round that is 300 x 225 mm, more than
  // A4 (297 x 210) holds either way, and more than A3 portrait is wide (297).
  const BoardSheetLayout lay = layout_of(BoardSpec{});
  EXPECT_EQ(lay.paper_name(), "A3 landscape");
  EXPECT_DOUBLE_EQ(lay.page_w_mm, 420);
  EXPECT_DOUBLE_EQ(lay.page_h_mm, 297);
  EXPECT_DOUBLE_EQ(lay.quiet_mm, 25);
  EXPECT_DOUBLE_EQ(lay.board_mm.width, 250);
  EXPECT_DOUBLE_EQ(lay.board_mm.height, 175);
  EXPECT_GE(lay.board_mm.x, 25);
  EXPECT_GE(lay.board_mm.y, 25);
  EXPECT_LE(lay.board_mm.y + 175 + 25, lay.text_top_mm) << "the text stays out of the white border";
  expect_chessboard_at_true_size(lay);
}

TEST(BoardSheet, ASmallerChessboardGoesOnA4PortraitOrOnTheA3AskedFor) {
  const BoardSpec b = chessboard(7, 5, 20);   // 8x6 squares: 160 x 120 mm, 200 x 160 with its border
  const BoardSheetLayout a4 = layout_of(b);
  EXPECT_EQ(a4.paper_name(), "A4 portrait");
  expect_chessboard_at_true_size(a4);
  EXPECT_EQ(layout_of(b, PaperChoice::a3).paper_name(), "A3 portrait");
}

TEST(BoardSheet, TheWhiteBorderAroundAChessboardIsClearOnThePage) {
  const BoardSheetLayout lay = layout_of(BoardSpec{});
  const cv::Mat page = render_board_sheet(lay, kPxPerMm);
  const double q = lay.board.square_mm;   // one square of white all round, whatever the layout says
  const cv::Rect2d outer(lay.board_mm.x - q, lay.board_mm.y - q, lay.board_mm.width + 2 * q,
                         lay.board_mm.height + 2 * q);
  cv::Mat border(page.size(), CV_8U, cv::Scalar(0));
  auto px = [](const cv::Rect2d& mm) {
    return cv::Rect(cv::Point(int(std::lround(mm.x * kPxPerMm)), int(std::lround(mm.y * kPxPerMm))),
                    cv::Point(int(std::lround(mm.br().x * kPxPerMm)), int(std::lround(mm.br().y * kPxPerMm))));
  };
  border(px(outer)).setTo(255);
  border(px(lay.board_mm) + cv::Size(2, 2) - cv::Point(1, 1)).setTo(0);   // the squares' anti-aliased edge aside
  double darkest = 0;
  cv::Mat inverted = 255 - page;
  cv::minMaxLoc(inverted, nullptr, &darkest, nullptr, nullptr, border);
  EXPECT_EQ(darkest, 0) << "something is drawn in the white border";
}

TEST(BoardSheet, ChessboardSquaresAreThoseTheSyntheticChessboardShows) {
  // The synthetic views (arwb synth --chessboard) show the board seen from the front: the top-left square is black.
  SynthCamera cam;
  SynthChessboard sb;
  const ChessboardRenderer renderer(cam, sb);
  const double sq = sb.square_m;
  const cv::Vec3d tvec(-sq * sb.cols / 2, -sq * sb.rows / 2, 0.6);
  const ChessboardView view = renderer.render(cv::Vec3d(0, 0, 0), tvec);
  std::vector<cv::Point2f> centres;
  cv::projectPoints(std::vector<cv::Point3f>{{float(-sq / 2), float(-sq / 2), 0}, {float(sq / 2), float(-sq / 2), 0}},
                    cv::Vec3d(0, 0, 0), tvec, cv::Mat(cam.camera_matrix), cam.distortion, centres);
  const bool synth_first_black = view.image.at<uint8_t>(cv::Point(centres[0])) < 128;
  const bool synth_second_black = view.image.at<uint8_t>(cv::Point(centres[1])) < 128;

  const cv::Mat printed = render_board(BoardSpec{}, kPxPerMm);
  const int half = int(25 * kPxPerMm / 2);
  EXPECT_EQ(printed.at<uint8_t>(half, half) < 128, synth_first_black);
  EXPECT_EQ(printed.at<uint8_t>(half, 3 * half) < 128, synth_second_black);
  EXPECT_TRUE(synth_first_black);
}

// The same board as OpenCV 4.6 draws it, at the same scale: they differ only on edges (anti-aliasing, and OpenCV
// rounding marker cells to whole pixels), never a square or a cell.
void expect_same_as_opencv(const BoardSpec& b, cv::aruco::PREDEFINED_DICTIONARY_NAME dict, double px_per_mm) {
  const cv::Mat ours = render_board(b, px_per_mm);
  const auto board = cv::aruco::CharucoBoard::create(b.cols, b.rows, float(b.square_mm), float(b.marker_mm),
                                                     cv::aruco::getPredefinedDictionary(dict));
  cv::Mat theirs;
  board->draw(ours.size(), theirs, 0, 1);
  ASSERT_EQ(theirs.size(), ours.size());
  cv::Mat edges;
  cv::morphologyEx(theirs, edges, cv::MORPH_GRADIENT, cv::Mat::ones(3, 3, CV_8U));
  cv::dilate(edges > 0, edges, cv::Mat::ones(3, 3, CV_8U));
  cv::Mat diff;
  cv::absdiff(ours, theirs, diff);
  const cv::Mat differ = diff > 127;
  EXPECT_EQ(cv::countNonZero(differ & ~edges), 0) << b.describe();
  EXPECT_LT(cv::countNonZero(differ), ours.total() / 50) << b.describe();
  EXPECT_GT(cv::countNonZero(ours < 128), ours.total() / 4) << "the board is drawn at all";
}

TEST(BoardSheet, ChArUcoIsDrawnAsOpenCv46DrawsIt) {
  expect_same_as_opencv(charuco(5, 7, 35, 26, "DICT_5X5_100"), cv::aruco::DICT_5X5_100, 2.0);
  expect_same_as_opencv(charuco(6, 4, 30, 20, "4X4_50"), cv::aruco::DICT_4X4_50, 3.0);
  expect_same_as_opencv(charuco(5, 5, 40, 28, "6X6_250"), cv::aruco::DICT_6X6_250, 2.5);
}

TEST(BoardSheet, TheDefaultChArUcoBoardGoesOnA4AndEveryCornerIsFoundWithItsId) {
  const BoardSpec b = charuco(5, 7, 35, 26, "DICT_5X5_100");
  const BoardSheetLayout lay = layout_of(b);
  EXPECT_EQ(lay.paper_name(), "A4 portrait");
  const cv::Mat page = render_board_sheet(lay, kPxPerMm);
  const auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_5X5_100);
  const auto board = cv::aruco::CharucoBoard::create(5, 7, 35.f, 26.f, dict);
  std::vector<std::vector<cv::Point2f>> markers;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(page, dict, markers, marker_ids);
  EXPECT_EQ(marker_ids.size(), 17u);
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(markers, marker_ids, page, board, corners, ids);
  ASSERT_EQ(ids.size(), 24u) << "every inner corner of 4x6";
  for (size_t i = 0; i < ids.size(); ++i) {
    const cv::Point2d e = expected_corner(lay, ids[i] % 4, ids[i] / 4);
    EXPECT_NEAR(corners[i].x, e.x, 0.5) << "corner id " << ids[i];
    EXPECT_NEAR(corners[i].y, e.y, 0.5) << "corner id " << ids[i];
  }
}

// "...; the largest --square-mm that fits is 38.2": the number.
double largest_in(const std::string& problem) {
  const std::string key = "the largest --square-mm that fits is ";
  const size_t at = problem.find(key);
  if (at == std::string::npos) return 0;
  return std::atof(problem.c_str() + at + key.size());
}

TEST(BoardSheet, ABoardTooLargeForThePaperIsRefusedWithTheLargestSquareThatFits) {
  for (const auto& [b, paper] : {std::pair{chessboard(9, 6, 60), PaperChoice::automatic},
                                 std::pair{BoardSpec{}, PaperChoice::a4},
                                 std::pair{charuco(5, 7, 60, 45, "DICT_5X5_100"), PaperChoice::automatic},
                                 std::pair{charuco(8, 11, 35, 26, "DICT_5X5_100"), PaperChoice::a4}}) {
    std::string problem;
    EXPECT_FALSE(board_sheet_layout(b, paper, {"a line"}, &problem).has_value()) << b.describe();
    EXPECT_EQ(problem.find('\n'), std::string::npos) << problem;
    const double largest = largest_in(problem);
    ASSERT_GT(largest, 0) << problem;
    EXPECT_LT(largest, b.square_mm) << problem;
    BoardSpec fits = b, too_big = b;
    fits.square_mm = largest;
    too_big.square_mm = largest + 0.1;
    fits.marker_mm = too_big.marker_mm = largest * 0.7;
    std::string ignored;
    EXPECT_TRUE(board_sheet_layout(fits, paper, {"a line"}, &ignored).has_value()) << problem;
    EXPECT_FALSE(board_sheet_layout(too_big, paper, {"a line"}, &ignored).has_value()) << problem;
  }
  std::string problem;
  board_sheet_layout(BoardSpec{}, PaperChoice::a4, {}, &problem);
  EXPECT_NE(problem.find("A4 (--paper a4)"), std::string::npos) << problem;
}

TEST(BoardSheet, ADictionaryTooSmallForTheChArUcoBoardIsRefused) {
  BoardSpec b = charuco(11, 11, 10, 7, "4X4_50");   // 60 markers
  EXPECT_EQ(charuco_marker_count(b), 60);
  try {
    render_board(b, 1.0);
    ADD_FAILURE() << "drawn with too few markers";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--dict 4X4_50 has 50 markers; a 11x11 ChArUco board needs 60");
  }
}

}  // namespace
}  // namespace arwb
