// How deep YAML text nests, measured before OpenCV's FileStorage parses it. Its parser recurses once per level of
// nesting, with no limit of its own, so a preset or dictionary nested 40,000 deep ("[[[[..." or "- - - - ...")
// overflows the stack and takes the program down. Our presets, dictionaries and calibration files are flat maps
// or a map of short lists; a few levels is all they need.
#pragma once

#include "base/result.hpp"

#include <string>
#include <string_view>

namespace arwb {

inline constexpr int kMaxYamlDepth = 32;

// Counts the levels open at each point of `text`: block levels (each deeper indentation, and each "- " or "? "
// entry that starts a nested node on its line) plus flow levels ("[" and "{" that open a collection, outside
// quotes and comments). "<name>:LINE: nested deeper than 32 levels" at the first line that goes past max_depth.
// Not a YAML validator: text it passes may still be malformed, which the parser then reports.
Status check_yaml_depth(std::string_view text, const std::string& name, int max_depth = kMaxYamlDepth);

}  // namespace arwb
