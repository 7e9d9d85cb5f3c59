// Sampling the grey image between its pixels, and the square-to-quad homography the frontal views are made with:
// perspective_removal's, border_check's quiet zone's and corner_refinement's. Internal to the stages.
#pragma once

#include "detect/quad.hpp"

#include <opencv2/core.hpp>

#include <algorithm>

namespace arwb::stages {

// Bilinear interpolation at (x, y), pixel centres at integers, clamped to the image.
inline double sample_bilinear(const cv::Mat& grey, double x, double y) {
  x = std::clamp(x, 0.0, double(grey.cols - 1));
  y = std::clamp(y, 0.0, double(grey.rows - 1));
  const int x0 = std::min(int(x), grey.cols - 2 < 0 ? 0 : grey.cols - 2);
  const int y0 = std::min(int(y), grey.rows - 2 < 0 ? 0 : grey.rows - 2);
  const int x1 = std::min(x0 + 1, grey.cols - 1), y1 = std::min(y0 + 1, grey.rows - 1);
  const double fx = x - x0, fy = y - y0;
  const uint8_t* r0 = grey.ptr<uint8_t>(y0);
  const uint8_t* r1 = grey.ptr<uint8_t>(y1);
  const double top = r0[x0] + fx * (r0[x1] - r0[x0]);
  const double bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
  return top + fy * (bottom - top);
}

// Bilinear interpolation inside the image at (x, y) given in 1/256 pixel (both >= 0, and x / 256 + 1, y / 256 + 1
// inside): integer weights, no conversion to floating point per pixel. The value times 65536.
inline int bilinear_q8(const uchar* data, size_t stride, int x, int y) {
  const int fx = x & 255, fy = y & 255;
  const uchar* r0 = data + size_t(y >> 8) * stride + (x >> 8);
  const uchar* r1 = r0 + stride;
  const int top = r0[0] * (256 - fx) + r0[1] * fx, bottom = r1[0] * (256 - fx) + r1[1] * fx;
  return top * (256 - fy) + bottom * fy;
}

// The homography taking the square [0, side]^2 to the quad, corner k of the square ((0,0), (side,0), (side,side),
// (0,side)) to quad[k]: Heckbert's closed form for the unit square, scaled. The same matrix as
// cv::getPerspectiveTransform up to rounding, without its linear solve and allocations (two per candidate).
inline cv::Matx33d square_to_quad(const Quad& q, double side) {
  const double x0 = q[0].x, y0 = q[0].y, x1 = q[1].x, y1 = q[1].y, x2 = q[2].x, y2 = q[2].y, x3 = q[3].x,
               y3 = q[3].y;
  const double sx = x0 - x1 + x2 - x3, sy = y0 - y1 + y2 - y3;
  double g = 0, h = 0;
  if (sx != 0 || sy != 0) {
    const double dx1 = x1 - x2, dx2 = x3 - x2, dy1 = y1 - y2, dy2 = y3 - y2;
    const double den = dx1 * dy2 - dx2 * dy1;
    if (den != 0) {
      g = (sx * dy2 - dx2 * sy) / den;
      h = (dx1 * sy - sx * dy1) / den;
    }
  }
  const double a = x1 - x0 + g * x1, b = x3 - x0 + h * x3, d = y1 - y0 + g * y1, e = y3 - y0 + h * y3;
  return cv::Matx33d(a / side, b / side, x0, d / side, e / side, y0, g / side, h / side, 1);
}

}  // namespace arwb::stages
