// A marker's or a candidate's four corners, and the two measures the stages, the views and the panels take of
// them.
#pragma once

#include <opencv2/core.hpp>

#include <array>

namespace arwb {

using Quad = std::array<cv::Point2f, 4>;

// The length of the outline: the four sides, corner 3 back to corner 0 included.
double quad_perimeter(const Quad& q);

// The mean of the four corners. Not the marker's projected centre under perspective (the tracker takes where the
// diagonals cross for that); for labels, containment tests and sampling, the mean is what is meant.
cv::Point2f quad_centre(const Quad& q);

}  // namespace arwb
