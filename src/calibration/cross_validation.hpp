// Cross-validation of a calibration, as mrcal does it: two calibrations of the same camera from disjoint halves of
// the views are compared over the whole image. Where they agree, the views pinned the lens down; where they
// differ, the result cannot be trusted (typically the corners the board never reached). Both are intrinsics of the
// same camera, but each half's solve may put the camera's axis in a slightly different direction (a principal
// point traded against a tilt), which moves nothing a user projects with; like mrcal's projection_diff, the
// comparison first fits the rotation between the two cameras' frames near the image's centre, then measures what
// is left.
#pragma once

#include "calibration/calibration_file.hpp"

#include <opencv2/core.hpp>

namespace arwb {

struct ProjectionDiff {
  // The distance in pixels, per cell of a grid over the image, between where calibration `a` and calibration `b`
  // see the same direction (the cell's centre unprojected by `a`, turned by the fitted rotation, projected by `b`).
  // NaN where `a` cannot unproject the cell (its distortion model folds over there).
  cv::Mat1f diff;
  double max_px = 0, median_px = 0;   // over the cells that are not NaN
};

// `a` and `b` for images of `size`; a grid of `cols` x `rows` cells. The rotation is fitted on the cells within a
// sixth of the image's smaller side from its centre (mrcal's default focus), or on all cells when fewer than 8
// lie there.
ProjectionDiff projection_diff(const Calibration& a, const Calibration& b, cv::Size size, int cols = 32, int rows = 24);

}  // namespace arwb
