// Words: how far apart two are, and the known name a misspelt one was meant to be ("did you mean ...?").
#pragma once

#include <algorithm>
#include <string>
#include <string_view>

namespace arwb {

// Levenshtein distance: insertions, deletions and substitutions of single bytes.
int edit_distance(std::string_view a, std::string_view b);

// The name in `known` (strings or string_views) that `word` is a typo away from: at most 2 edits, and fewer edits
// than the longer of the two has bytes (so "x" never becomes "y"); the first of the nearest. "" when none is.
template <class Names>
std::string nearest_name(std::string_view word, const Names& known) {
  std::string_view best;
  int best_d = 3;
  for (const auto& name : known) {
    const std::string_view k(name);
    const int d = edit_distance(word, k);
    if (d < best_d && d < static_cast<int>(std::max(word.size(), k.size()))) {
      best_d = d;
      best = k;
    }
  }
  return std::string(best);
}

}  // namespace arwb
