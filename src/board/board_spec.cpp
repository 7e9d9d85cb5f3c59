#include "board/board_spec.hpp"

#include "base/decimals.hpp"
#include "detect/dictionary.hpp"

#include <cstdio>

namespace arwb {

namespace {
std::string num(double v, int decimals = 1) { return fixed_text(v, decimals); }
}  // namespace

BoardSpec default_board(BoardKind kind) {
  BoardSpec b;
  if (kind == BoardKind::charuco) b.kind = kind, b.cols = 5, b.rows = 7, b.square_mm = 35, b.marker_mm = 26;
  return b;
}

const char* board_kind_name(BoardKind k) { return k == BoardKind::charuco ? "charuco" : "chessboard"; }

cv::Size BoardSpec::inner_corners() const {
  return kind == BoardKind::charuco ? cv::Size(cols - 1, rows - 1) : cv::Size(cols, rows);
}

std::string BoardSpec::problem() const {
  if (kind == BoardKind::chessboard) return {};
  if (cols < 3 || rows < 3) return "a ChArUco board needs at least 3x3 squares";
  if (marker_mm <= 0) return "--marker-mm: give the markers' side (less than --square-mm " + num(square_mm, 2) + ")";
  if (marker_mm >= square_mm)
    return "--marker-mm " + num(marker_mm, 2) + " must be less than --square-mm " + num(square_mm, 2);
  std::string error;
  const std::optional<Dictionary> d = dictionary_by_name(dictionary, &error);
  if (!d) return "--dict " + error;
  // One marker in every white square: half of them, rounded down (the top-left square is black).
  const int needed = cols * rows / 2;
  if (d->size() < needed)
    return "--dict " + dictionary + " has " + std::to_string(d->size()) + " markers; a " + std::to_string(cols) + "x" +
           std::to_string(rows) + " ChArUco board needs " + std::to_string(needed);
  return {};
}

std::string BoardSpec::describe() const {
  if (kind == BoardKind::charuco)
    return "ChArUco " + std::to_string(cols) + "x" + std::to_string(rows) + " squares (" +
           std::to_string(cols - 1) + "x" + std::to_string(rows - 1) + " inner corners), " + num(square_mm, 2) +
           " mm squares, " + num(marker_mm, 2) + " mm markers, " + dictionary + " (OpenCV 4.6 layout)";
  return "chessboard " + std::to_string(cols) + "x" + std::to_string(rows) + " inner corners (" +
         std::to_string(cols + 1) + "x" + std::to_string(rows + 1) + " squares), " + num(square_mm, 2) +
         " mm squares";
}

std::vector<cv::Point3f> BoardSpec::object_points() const {
  std::vector<cv::Point3f> pts;
  const cv::Size n = inner_corners();
  // A ChArUco board's first inner corner is one square in from its outer corner; its corners are measured from
  // that first corner, as a chessboard's are, so that poses of both kinds mean the same.
  for (int r = 0; r < n.height; ++r)
    for (int c = 0; c < n.width; ++c) pts.emplace_back(float(c * square_mm), float(r * square_mm), 0.f);
  return pts;
}

}  // namespace arwb
