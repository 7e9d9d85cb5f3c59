// The one description of a calibration board (chessboard or ChArUco): what `arwb calibrate` looks for, what
// `arwb markers --board` prints, what the synthetic source shows and what the Calibrate workspace coaches with. It
// lives here, below synth and calibration, so that both read the same board.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace arwb {

enum class BoardKind { chessboard, charuco };

// The one description of a calibration board: what `arwb calibrate` looks for, what `arwb markers --board`
// prints, what the synthetic source shows and what the Calibrate workspace coaches with.
struct BoardSpec {
  BoardKind kind = BoardKind::chessboard;
  // chessboard: inner corners, as OpenCV counts them (the paper's board is 9x6, 10x7 squares).
  // charuco: squares, as OpenCV's CharucoBoard counts them (its inner corners are (cols-1)x(rows-1)).
  int cols = 9, rows = 6;
  double square_mm = 25;
  double marker_mm = 0;                  // charuco: a marker's side, less than square_mm
  std::string dictionary = "DICT_5X5_100";   // charuco: the markers' dictionary, as dictionary_by_name knows it
  std::string describe() const;          // "chessboard 9x6 inner corners (10x7 squares), 25 mm squares"
  cv::Size inner_corners() const;        // the corners a full view has, across and down
  std::vector<cv::Point3f> object_points() const;  // every inner corner row by row, in mm, z = 0
  // Empty when the board can exist; else what is wrong, naming the option: "--marker-mm 30 must be less than
  // --square-mm 25", "--dict DICT_4X4_50 has 50 markers; a 5x7 ChArUco board needs 17".
  std::string problem() const;
  bool operator==(const BoardSpec&) const = default;
};
const char* board_kind_name(BoardKind k);   // "chessboard", "charuco"
// The board a kind starts with, everywhere (the CLI's defaults, the synthetic source, the Calibrate workspace):
// the paper's chessboard (9x6 inner corners, 25 mm), or a ChArUco board of 5x7 squares of 35 mm with 26 mm
// markers of DICT_5X5_100, which fits on A4.
BoardSpec default_board(BoardKind kind);

}  // namespace arwb
