// The calibration board, finding it in a frame, and choosing which frames become views: a view must be still
// (not blurred), add something (its pose unlike the views kept) and keep its corners away from the image's edge.
// Every frame refused says why.
#pragma once

#include "board/board_spec.hpp"

#include <opencv2/core.hpp>

#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

namespace cv::aruco {
class CharucoBoard;
}

namespace arwb {

struct BoardDetection {
  bool found = false;
  std::vector<cv::Point2f> corners;   // subpixel; a chessboard's row by row, all of them
  std::vector<int> ids;               // each corner's index into object_points(): empty when all are there in
                                      // order (a chessboard); a ChArUco view may hold part of the board
  double edge_width_px = 0;           // how wide the black-white edges are, px (blur): OpenCV's measure for a
                                      // chessboard, charuco_edge_width's for ChArUco
};

// Finds `board` of either kind in an 8-bit grey or BGR frame: the one entry point for the CLI and the workbench.
BoardDetection detect_board(const cv::Mat& frame, const BoardSpec& board);

// The fewest ChArUco corners a view must have (and not all on one line) to count as the board found.
constexpr int kMinCharucoCorners = 6;

// Finds a ChArUco board (OpenCV 4.6's layout) in an 8-bit grey or BGR frame: its markers by OpenCV's
// detectMarkers, then the chessboard corners between them by interpolateCornersCharuco, each with its id (an index
// into board.object_points()), sorted by id. Found when at least kMinCharucoCorners corners are there and they are
// not all on one line. The sharpness is measured across the square edges between neighbouring corners (OpenCV's
// chessboard measure reads the markers as edges).
BoardDetection detect_charuco(const cv::Mat& frame, const BoardSpec& board);
// The sharpness figure of a ChArUco view (see detect_charuco), px; 0 when no two neighbouring corners are there.
double charuco_edge_width(const cv::Mat& grey, const BoardSpec& board, const std::vector<cv::Point2f>& corners,
                          const std::vector<int>& ids);

// OpenCV's CharucoBoard for `board` (its predefined dictionary by detect's name for it), metres as units; null
// when the dictionary is not one of OpenCV's predefined ones.
cv::Ptr<cv::aruco::CharucoBoard> opencv_charuco_board(const BoardSpec& board);

// Finds the board in an 8-bit grey or BGR frame (OpenCV's findChessboardCornersSB, which is accurate to a
// fraction of a pixel without cornerSubPix, then its sharpness estimate). A grid whose points are not nearly all
// chessboard corners (four squares meeting) is refused: asked for fewer corners than the board has, OpenCV can
// return one that runs along the board's outer edge.
BoardDetection detect_chessboard(const cv::Mat& frame, const BoardSpec& board);

// The largest of `sizes` (inner corners) that a chessboard in the frame has, by OpenCV's findChessboardCorners,
// which finds a board only at its exact size: for naming the board that is there when the one asked for is not.
// Largest, whatever the order given: OpenCV can find a grid one corner short inside a board (8x6 in the paper's
// 9x6), never one larger than the board, so the largest grid found is the board.
std::optional<cv::Size> find_any_chessboard(const cv::Mat& frame, std::vector<cv::Size> sizes);

// The inner corners of the chessboard that a grid found in `frame` (at `corners`, all chessboard corners) belongs
// to, when it is larger than `board`: a grid of 7x5 corners inside a 9x6 board would make every view one of a
// board other than the one printed. Looks one square beyond each side of the grid for more chessboard corners
// and goes on while it finds them. nullopt when the board ends where the grid does.
std::optional<cv::Size> larger_board(const cv::Mat& frame, const BoardSpec& board,
                                     const std::vector<cv::Point2f>& corners);

// The view's place in the ROS calibrator's four terms, each 0..1: x and y of the board's centre across the room
// the board leaves in the image, size (the square root of the board's share of the image) and skew (how far the
// angle at a corner of the board is from a right angle).
struct ViewPose {
  double x = 0, y = 0, size = 0, skew = 0;
};
ViewPose view_pose(const std::vector<cv::Point2f>& corners, const BoardSpec& board, cv::Size image);
// The same for a view that may hold part of the board (ids as BoardDetection::ids; empty: all, in order): x, y and
// size from the corners seen (their mean, the area of their hull), skew from the whole board's outline placed by
// the homography of the corners seen.
ViewPose view_pose(const std::vector<cv::Point2f>& corners, const std::vector<int>& ids, const BoardSpec& board,
                   cv::Size image);

struct SelectOptions {
  bool video = true;              // frames follow each other (stillness is measured); false: a folder of stills
  double max_motion_px = 2.0;     // the largest mean corner motion since the previous frame
  double max_edge_width_px = 3.5; // blurrier boards are refused
  double min_edge_margin_px = 8;  // corners nearer the image's edge are refused (lens distortion is worst there,
                                  // and a corner half out of the image is placed wrongly)
  double min_pose_distance = 0.15;// the sum of |difference| over x, y, size and skew to every view kept
  int max_views = 40;
};

struct Verdict {
  bool keep = false;
  std::string reason;   // why not, or "kept"
  std::string kind;     // the reason's short name for the tally: "no board", "moving", "blurred", "edge", "similar", "enough"
};

class ViewSelector {
 public:
  ViewSelector(BoardSpec board, SelectOptions opt) : board_(board), opt_(opt) {}
  // Every frame, in order, with its detection (found or not).
  Verdict consider(const BoardDetection& d, cv::Size image);
  const std::vector<ViewPose>& kept_poses() const { return kept_; }

 private:
  BoardSpec board_;
  SelectOptions opt_;
  std::vector<cv::Point2f> previous_;   // the previous frame's corners, empty when it had no board
  std::vector<int> previous_ids_;       // and their ids (ChArUco)
  std::vector<ViewPose> kept_;
};

}  // namespace arwb
