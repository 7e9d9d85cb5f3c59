// Words: how far apart two are, and the known name a misspelt one was meant to be ("did you mean ...?"); text fit
// for a terminal; whether a text file is UTF-8.
#pragma once

#include "base/result.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace arwb {

// The items of a comma-separated list, empty items left out: "a,,b" gives a and b.
std::vector<std::string> split_list(std::string_view list);

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

// A size as people read it: "729 B" below 10 000 bytes, then "17.3 KiB", then "24.1 MiB".
std::string human_bytes(std::uint64_t n);

// `text` with everything a terminal could act on escaped, so that a file name like "a\x1B[31m\nb.png" prints as
// one harmless line: C0 controls and DEL as \n, \r, \t or \xNN, C1 controls (U+0080..U+009F) as \u0080, bytes
// that are not UTF-8 as \xNN, and the backslash itself stays as it is. Printable UTF-8 is kept.
// Applied where messages reach the terminal or the log (the workbench's Log, the command line's report()).
std::string printable(std::string_view text);

// `text` with each byte that does not start UTF-8 replaced by U+FFFD, as json_text writes it: for a label made
// from a file name (a plan named after caf\xE9_plan.yml), which then reads the same in the terminal, the JSON, the
// plots (PLplot refuses text that is not UTF-8) and the report.
std::string utf8_replaced(std::string_view text);

// Whether `text` (a whole file, without its UTF-8 byte order mark) is UTF-8 that a text file may hold. Refused,
// with `name` first: "<name>: UTF-16 text; save it as UTF-8" (a UTF-16 byte order mark, or a NUL in every other
// byte of the start: Windows' "Unicode"), the same for UTF-32, "<name>:LINE:COL: not UTF-8 (byte 0xE9); save it
// as UTF-8" (LINE and COL from 1, COL counting characters) and "<name>:LINE:COL: a NUL byte; not a text file".
Status check_utf8_text(std::string_view text, const std::string& name);

}  // namespace arwb
