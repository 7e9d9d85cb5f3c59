// A marker's pose in OpenCV's marker frame: the origin at the marker's centre, x towards corner 1, y up (towards
// corners 0 and 1), z out of the marker towards the camera; corner 0 at (-L/2, L/2, 0), corner 1 at (L/2, L/2, 0),
// corner 2 at (L/2, -L/2, 0), corner 3 at (-L/2, -L/2, 0), L the marker's side on its outer black edge (the
// detected corners). rvec and tvec take marker coordinates to the camera's (x right, y down, z forward); tvec is
// in the unit of L.
//
// A square seen from the front fits two poses almost equally well (the planar ambiguity: the marker tilted one
// way or the other). Both are kept: IPPE (Collins and Bartoli 2014, OpenCV's SOLVEPNP_IPPE_SQUARE) gives the two,
// each is refined by Levenberg-Marquardt on the four corners, and the ratio of their errors says how ambiguous
// the view is. In video the previous pose decides between them when the corners cannot (resolve_with_previous).
#pragma once

#include "calibration/calibration_file.hpp"
#include "detect/quad.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <optional>
#include <string>

namespace arwb {

// The paper's "set of default values" when there is no calibration: a webcam of 60 degrees horizontal field of
// view (fx = fy = (width / 2) / tan(30 degrees), 554 px at 640x480), the principal point at the image's centre
// ((width - 1) / 2, (height - 1) / 2), no lens distortion. `assumed` is set, and every pose made with it says so.
Calibration default_calibration(cv::Size image_size);
inline constexpr double kDefaultHorizontalFovDeg = 60;

struct PoseSolution {
  cv::Vec3d rvec{0, 0, 0};   // Rodrigues vector, marker to camera
  cv::Vec3d tvec{0, 0, 0};   // the marker's centre in the camera's frame, in the unit of the marker's side
  double error_px = 0;       // RMS distance of the four corners projected (with the lens model) to those detected
};

struct MarkerPose {
  PoseSolution pose;          // the one used: the lower error, unless the previous pose chose the other
  PoseSolution alternative;   // the other solution of the planar ambiguity
  // The lower error over the higher, 0..1: near 1 the two explain the corners alike (a marker seen nearly from
  // the front, or small), and the corners alone cannot tell which is true; near 0 one is clearly right.
  double ambiguity = 0;
  bool assumed_camera = false;   // made with default_calibration's values, not a calibration
  bool chosen_by_previous = false;   // `pose` has the higher error: the previous frame's pose chose it
};

// The four corners' positions in the marker frame (see above) for a side of `side`.
std::array<cv::Point3d, 4> marker_object_points(double side);

// Both poses of a marker of side `side` (> 0) whose corners were detected at `corners` (image pixels, lens
// distortion and all) by the camera `camera`. nullopt for a degenerate quad or a solve that fails.
std::optional<MarkerPose> estimate_marker_pose(const Quad& corners, double side, const Calibration& camera);

// The angle in degrees of the rotation taking one orientation to the other.
double rotation_difference_deg(const cv::Vec3d& rvec_a, const cv::Vec3d& rvec_b);

// When the corners leave the choice open (ambiguity at least `min_ambiguity`), the solution whose rotation is
// nearer `previous_rvec` (the same marker's pose on the previous frame) is taken, and chosen_by_previous says
// so when that is not the lower-error one. A clear view (ambiguity below it) keeps its lower-error solution:
// a marker that really turned is followed.
MarkerPose resolve_with_previous(const MarkerPose& p, const cv::Vec3d& previous_rvec, double min_ambiguity = 0.3);

// What the Pose panel, Lua and the JSON show. Angles in degrees.
struct PoseAngles {
  double distance = 0;   // |tvec|, in the unit of the marker's side
  double tilt_deg = 0;   // between the marker's normal and the line to the camera: 0 seen from the front
  // The marker frame's rotation relative to a marker facing the camera upright (x right, y up, z towards the
  // camera), as yaw about y, pitch about x and roll about z (applied roll, then pitch, then yaw).
  double yaw_deg = 0, pitch_deg = 0, roll_deg = 0;
};
PoseAngles pose_angles(const PoseSolution& p);

// Projects marker-frame points (in the unit of the side) with the pose and the camera's lens model.
std::vector<cv::Point2d> project_marker_points(const std::vector<cv::Point3d>& points, const PoseSolution& p,
                                               const Calibration& camera);

}  // namespace arwb
