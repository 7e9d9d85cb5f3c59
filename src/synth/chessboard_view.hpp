// Synthetic views of a printed chessboard or ChArUco board through a pinhole camera with lens distortion, with the
// exact image positions of its inner corners: the fixture that calibration is measured against (a known camera in, the
// solver's estimate out). The board is rendered per pixel, not warped from a picture: each pixel's 4x4 sample
// rays are undistorted once per camera and intersected with the board's plane, so the distortion is exactly the
// model OpenCV estimates (k1, k2, p1, p2, k3) and the edges are anti-aliased without blurring the corners away.
#pragma once

#include "board/board_spec.hpp"

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace arwb {

struct SynthCamera {
  cv::Size size{640, 480};
  cv::Matx33d camera_matrix{560, 0, 322, 0, 555, 236, 0, 0, 1};
  std::vector<double> distortion{-0.25, 0.08, 0, 0, 0};   // k1 k2 p1 p2 k3: a typical webcam's barrel
  // This camera made for images of `size`: the same field of view across and lens, the principal point as far
  // from the image's centre in proportion (a 16:9 size sees less of the world vertically, as a phone's video does).
  SynthCamera resized(cv::Size size) const;
};

struct SynthChessboard {
  int cols = 9, rows = 6;       // inner corners, as OpenCV counts them (the paper's 9x6: 10x7 squares)
  double square_m = 0.025;
  double margin_squares = 1.0;  // white paper around the squares, which detectors need
  // charuco: OpenCV 4.6's CharucoBoard of (cols+1)x(rows+1) squares, the top-left square black, a marker centred
  // in every white square, ids row by row from 0 (the board's y runs down, as in the image).
  BoardKind kind = BoardKind::chessboard;
  double marker_m = 0;                       // charuco: a marker's side, border included
  std::string dictionary = "DICT_5X5_100";   // charuco: as detect's dictionary_by_name knows it
  // The board `spec` describes (mm to metres; ChArUco squares to inner corners).
  static SynthChessboard of(const BoardSpec& spec, double margin_squares = 1.0);
};

struct ChessboardView {
  cv::Mat image;                        // 8-bit grey
  std::vector<cv::Point2f> corners;     // inner corners row by row (cols per row), OpenCV's projectPoints; a
                                        // ChArUco corner's index is its id
  bool all_inside = false;              // every inner corner at least 2 px inside the image
};

// Each 4x4 sample of each pixel's ray as undistorted normalised coordinates (CV_32FC2, (h*4) x (w*4)): sample
// (i, j) of pixel (x, y) sits at x + (i + 0.5)/4 - 0.5, pixel centres at integers as OpenCV places them. What the
// renderers of planar targets (boards, markers) intersect with their plane.
cv::Mat sample_rays(const SynthCamera& camera);
inline constexpr int kRaySamples = 4;   // per pixel side

class ChessboardRenderer {
 public:
  ChessboardRenderer(SynthCamera camera, SynthChessboard board);
  // The board turned by rvec and placed at tvec (metres) in the camera's frame (OpenCV's convention: x right,
  // y down, z forward); the board's origin is its first inner corner. Paper white 220, squares 30, the
  // background a soft grey gradient; blur_px > 0 adds a Gaussian blur (motion, focus), noise a Gaussian noise.
  // samples: 4 (4x4 per pixel), 2 (2x2, four times faster) or 1 (one, 16 times faster, an eighth of a pixel
  // off centre: for frames nobody measures, a board moving).
  ChessboardView render(const cv::Vec3d& rvec, const cv::Vec3d& tvec, double blur_px = 0, double noise = 0,
                        unsigned seed = 1, int samples = 4) const;
  // render() in parts, for a caller that spreads the work over several frames: render_rows draws the image rows
  // [row0, row1) into acc (grey levels, float; made the image's size if it is not), finish blurs, adds noise and
  // places the corners. render() is render_rows over every row, then finish.
  void render_rows(const cv::Vec3d& rvec, const cv::Vec3d& tvec, cv::Mat1f& acc, int row0, int row1,
                   int samples = 4) const;
  ChessboardView finish(cv::Mat1f acc, const cv::Vec3d& rvec, const cv::Vec3d& tvec, double blur_px = 0,
                        double noise = 0, unsigned seed = 1) const;
  const SynthCamera& camera() const { return camera_; }
  const SynthChessboard& board() const { return board_; }

 private:
  SynthCamera camera_;
  SynthChessboard board_;
  cv::Mat rays_;   // CV_32FC2, (h*4) x (w*4): each sample's undistorted normalised coordinates
  // charuco: per square (row by row over the (cols+1)x(rows+1) squares) the marker's cells, border included, as
  // a CV_8U matrix of 0 and 1 (white); empty for a black square or one past the dictionary's end.
  std::vector<cv::Mat> marker_cells_;
};

// A varied set of `count` board poses that keep the board inside the image: distances, tilts up to about 40
// degrees and positions spread over the frame (the same seed, the same poses).
std::vector<std::pair<cv::Vec3d, cv::Vec3d>> chessboard_poses(const SynthCamera& camera, const SynthChessboard& board,
                                                              int count, unsigned seed);
// Poses of a board held close, partly out of the image: between a third and four fifths of its inner corners at
// least 12 px inside it (for ChArUco, whose views may hold part of the board).
std::vector<std::pair<cv::Vec3d, cv::Vec3d>> partial_board_poses(const SynthCamera& camera,
                                                                 const SynthChessboard& board, int count,
                                                                 unsigned seed);

}  // namespace arwb
