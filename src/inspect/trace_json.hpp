// A trace as one JSON object, for snapshots, bug reports and scripts. Contours' points and images are left out
// (too big); their counts and sizes are kept.
#pragma once

#include "detect/trace.hpp"

#include <string>

namespace arwb {

// {"level","width","height","work_width","work_height","scale_x","scale_y","total_ms","contours":N,
//  "stages":[{"name","ms","in","out","image":[w,h]|null}],
//  "search":{"whole","factor","known","why","regions":[[x,y,w,h]...]},
//  "markers":[{"id","dict","corners":[[x,y]x4],"hamming","rotation"}],
//  "candidates":[{"contour","bbox":[x,y,w,h],"perimeter","quad":[[x,y]x4]|null,"otsu_threshold","stddev",
//                 "border_errors","border_cells","dict","per_rotation":[{"id","distance"}x4],"marker",
//                 "warp":[w,h]|null,"bits":["0110..."]|null,"fate":{"stage","param","value","limit","message"}}]}
std::string trace_to_json(const FrameTrace& t);

}  // namespace arwb
