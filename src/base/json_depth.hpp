// How deep JSON text nests, measured before a parser that recurses once per level sees it. tinygltf turns a
// model's JSON into its own values recursively, with no limit, so a 40 KB glTF nesting 20,000 arrays in
// `asset.extras` overflows the stack and takes the program down. Every JSON file a user hands us (a model, a
// bundle's manifest, the lab's cells, the workspaces, a truth set) needs a few levels; kMaxJsonDepth is far above.
#pragma once

#include "base/result.hpp"

#include <string>
#include <string_view>

namespace arwb {

inline constexpr int kMaxJsonDepth = 64;

// Counts the arrays and objects open at each point of `text` ("[" and "{" outside strings, a string's escapes
// skipped). "<name>:LINE: nested deeper than 64 levels" at the first line that goes past max_depth ("line LINE: ..."
// without a name, for a caller that names the file itself). Not a JSON validator: text it passes may still be
// malformed, which the parser then reports.
Status check_json_depth(std::string_view text, const std::string& name, int max_depth = kMaxJsonDepth);

}  // namespace arwb
