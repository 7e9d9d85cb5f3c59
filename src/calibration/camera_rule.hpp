// The one rule for a camera: what read_calibration accepts, every part that uses a camera (detect's poses, render,
// export and its self-test, play, the lab, the workbench) can use. A camera outside it gives no pose, picture or
// table worth showing, so the reader and calibration_for_size refuse it with the reason instead.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace arwb {

// Of the matrix alone: focal lengths of 1 to 10^7 pixels (under one pixel no picture is a view through a lens;
// beyond, a field of view under a thousandth of a degree), principal point and skew within 10^7 pixels. "" or
// the reason: "focal length fx 1e-300 is not 1 to 1e+07 pixels".
std::string camera_matrix_problem(const cv::Matx33d& k);

// Over a picture of `size`: the distortion can be undone at every pixel, the edges and corners included
// (undone, then applied again, each point of a 9x7 grid lands within a pixel of where it was). Coefficients that
// overflow, or bend the edge of the picture back on itself, fail here. "" or the reason: "its distortion cannot be
// undone at pixel (0, 0) of a 640x480 picture (undone and applied again, it lands 37.2 px away); calibrate again
// with views that reach the corners" (a solve from views that stayed in the middle extrapolates there).
std::string camera_picture_problem(const cv::Matx33d& k, const std::vector<double>& distortion, cv::Size size);

}  // namespace arwb
