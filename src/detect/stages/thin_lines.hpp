// quad_fit's cut_thin_lines. Internal to the stages.
#pragma once

#include "detect/params.hpp"
#include "detect/quad.hpp"

#include <opencv2/core.hpp>

#include <utility>
#include <vector>

namespace arwb::stages {

// cut_thin_lines: the quad of a marker that thin lines join to other dark shapes. A line across a marker's quiet
// zone into its border makes one region of the marker, the line and whatever the line runs into; the region's
// outline runs along the marker's four sides, leaves them where a line does and comes back beside it. At a fine
// tolerance (1.5 px of the search image) its polygon has each side as a long edge, or as collinear ones where a line
// cut it. Four lines of such edges that follow each other along the outline, meet in a convex quad (clockwise, as
// the outline runs) that no vertex lies inside and one lies well outside, and cover 0.4 of each side and 0.7 of
// all, are the marker when the polygon has a thin line (two edges side by side, the opposite ways); of several, the
// most covered. Its corners, where lines fitted to those edges' points meet, into `quad`; false when there is none.
// `farthest`: the contour's farthest pair as approx_polygon found it; `shift`: what the contour points lack of their
// block's centre on a decimated search.
bool cut_thin_lines(const std::vector<cv::Point>& contour, std::pair<int, int> farthest, const DetectorParams& p,
                    int factor, double shift, Quad* quad);

}  // namespace arwb::stages
