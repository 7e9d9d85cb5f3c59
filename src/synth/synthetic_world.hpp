// The built-in synthetic source: markers moving in 3D in front of a pinhole camera, turning, coming closer and
// going away, under changing light, with exact ground truth for every frame. It is what the workbench shows
// when there is no camera, and what the GUI tests look at.
#pragma once

#include "board/board_spec.hpp"
#include "detect/dictionary.hpp"
#include "synth/chessboard_view.hpp"
#include "synth/synth.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace arwb {

// The world's controls (the workbench's sliders). Ranges are in the comments; values outside are clamped.
struct SyntheticControls {
  bool animate = true;           // false: the world holds still at `time_s`
  double time_s = 0;             // the world's clock when not animated
  double speed = 1.0;            // 0 .. 4, animation speed
  double distance_m = 0.6;       // 0.2 .. 3, camera to the centre of the marker group
  double tilt_deg = 30;          // 0 .. 80, largest tilt of the markers out of the image plane
  double light = 1.0;            // 0.2 .. 1.5, overall brightness (light also varies over time and across the frame)
  double blur_px = 0.0;          // 0 .. 5, Gaussian sigma
  double noise = 2.0;            // 0 .. 40, Gaussian noise sigma in grey levels
  double marker_size_m = 0.08;   // 0.02 .. 0.3, printed side of each marker (black border included)
  int markers = 3;               // 1 .. 8
  int first_id = 0;              // ids first_id, first_id+1, ... (ids a dictionary reads ambiguously are skipped)
  std::string dict = "ARUCO_ORIGINAL";
  // Not empty: exactly these ids are shown (the first 8 of them that `dict` has), in place of `markers` ids from
  // `first_id`; the player shows a bundle's own markers this way, so that its media appear without a camera.
  std::vector<int> ids;
  // "" shows the markers above; "chessboard" (the paper's 9x6 inner corners, 25 mm) or "charuco" shows a
  // calibration board held in front of a camera with known intrinsics and lens distortion (SyntheticSource::
  // board_camera), moved from pose to pose with pauses, so that the Calibrate workspace can be shown without a
  // camera and its result compared with the truth.
  std::string board;
  bool operator==(const SyntheticControls&) const = default;
};

struct SyntheticFrame {
  cv::Mat image;                      // BGR
  std::vector<TruthMarker> markers;   // the markers fully inside the frame, corners exact
};

class SyntheticWorld {
 public:
  explicit SyntheticWorld(cv::Size size = {640, 480}, double focal_px = 600, uint64_t seed = 1);

  // The world at time t (seconds); the same controls and t give the same image (noise included).
  SyntheticFrame render(double t) const;

  SyntheticControls& controls() { return controls_; }
  const SyntheticControls& controls() const { return controls_; }
  void set_controls(const SyntheticControls& c);   // clamps into range; an unknown dictionary keeps the old one
  cv::Size size() const { return size_; }
  // The camera a calibration board is seen through while controls().board names one ("chessboard", "charuco"):
  // SynthCamera's defaults scaled to this world's size. Null while markers are shown.
  const SynthCamera* board_camera() const;
  // The board shown while controls().board names one (the paper's chessboard, the CLI's ChArUco defaults).
  static BoardSpec board_spec(const std::string& board);

  // The board's schedule: each pose is reached in kBoardMoveS, then held for kBoardHoldS (long enough for a
  // still-frame check to keep a view), over kBoardPoses poses, looping.
  static constexpr double kBoardMoveS = 0.6, kBoardHoldS = 1.1;
  static constexpr int kBoardPoses = 20;

 private:
  struct BoardStage;
  // The stage for `board`, made when first asked for (the renderer undistorts every pixel once).
  const BoardStage* stage(const std::string& board) const;
  SyntheticFrame render_board(const SyntheticControls& c, double t) const;
  // Blur, then light (a slow global swell, a gradient that turns), then noise, on a BGR frame.
  void optics(cv::Mat& image, const SyntheticControls& c, double t) const;

  cv::Size size_;
  double focal_px_;
  uint64_t seed_;
  SyntheticControls controls_;
  cv::Mat background_;   // rendered once
  cv::Mat noise_;        // CV_16SC1 normal samples, read at a per-frame offset: noise without a draw per pixel
  mutable std::shared_ptr<BoardStage> board_;   // the board shown last, with its pose cache
};

}  // namespace arwb
