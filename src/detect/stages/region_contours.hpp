// contours' tracing of one kind of region, for find_contours (the dark regions) and fine_search's quad_holes (the
// light ones inside a dark shape). Internal to the stages: pipeline.hpp is what the rest of the project sees.
#pragma once

#include "detect/pipeline.hpp"

#include <functional>
#include <vector>

namespace arwb::stages {

// find_contours of the nonzero regions, or when `light` of the zero ones. `keep`, when given, is asked about each
// region about to be traced, with its box undecimated (the grey image's scale, from the binary's origin): false
// leaves it untraced.
std::vector<std::vector<cv::Point>> region_contours(const cv::Mat& binary, bool light, double min_perimeter_px,
                                                    int* region_count, std::vector<SmallRegion>* small, int factor,
                                                    int max_side_px,
                                                    const std::function<bool(const cv::Rect&)>& keep = {});

}  // namespace arwb::stages
