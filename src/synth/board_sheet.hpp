// The calibration board printed at true size for `arwb markers --board`: a chessboard or a ChArUco board (its
// BoardSpec) on A4 or A3, portrait or landscape, with lines of text under it (what the board is, the command that
// reads it) and the 100 mm measuring bar, as a PDF or an SVG. Lengths are in millimetres.
//
// The squares follow one convention for both kinds, the one `arwb synth --chessboard` renders and OpenCV 4.6's
// CharucoBoard::draw uses: the top-left square is black, so square (col, row) is black when col + row is even. A
// ChArUco board's markers fill its white squares, ids 0, 1, 2 ... row by row from the top, each centred in its square
// and upright (the marker's own top-left corner at the top left).
#pragma once

#include "board/board_spec.hpp"
#include "synth/marker_sheet.hpp"

#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

namespace arwb {

enum class PaperChoice { a4, a3, automatic };

struct BoardSheetLayout {
  BoardSpec board;
  std::string paper;                 // "A4", "A3"
  bool landscape = false;
  double page_w_mm = 0, page_h_mm = 0;
  cv::Rect2d board_mm;               // the squares on the page: top-left corner, width and height
  double quiet_mm = 0;               // white kept around the squares (a chessboard: one square)
  std::vector<std::string> text;     // lines under the board
  double text_font_mm = 0;           // smaller than the usual when a line would not fit across the page
  double text_top_mm = 0;            // the first line's top
  std::string paper_name() const { return paper + (landscape ? " landscape" : " portrait"); }
};

// The smallest page allowed by `paper` (A4 before A3, portrait before landscape) on which the board, its quiet zone,
// the text and the measuring bar fit inside 10 mm margins (the quiet zone may reach into the margin: it is paper).
// nullopt and *problem, one line naming the option, when none does: "a chessboard of 10x7 squares of 40 mm does not
// fit on A3 with ...; the largest --square-mm that fits is 38.2".
std::optional<BoardSheetLayout> board_sheet_layout(const BoardSpec& board, PaperChoice paper,
                                                   std::vector<std::string> text, std::string* problem);

// Writes the page. Throws std::invalid_argument for a board that cannot be drawn (a dictionary too small for the
// ChArUco board), std::runtime_error naming the file that cannot be written; nothing is written then.
SheetResult write_board_sheet(const BoardSheetLayout& layout, SheetFormat format, const std::string& path);

// The page drawn by the same code into an 8-bit grey image of px_per_mm pixels a millimetre (the page's top-left
// corner at pixel (0, 0)'s top-left), to check what is printed.
cv::Mat render_board_sheet(const BoardSheetLayout& layout, double px_per_mm);
// The board alone (its squares, no quiet zone) at px_per_mm, as CharucoBoard::draw would size it.
cv::Mat render_board(const BoardSpec& board, double px_per_mm);

// A ChArUco board's markers: one per white square, floor(cols * rows / 2).
int charuco_marker_count(const BoardSpec& board);

}  // namespace arwb
