// A text card's layout without cairo: its lines (cut and ended with "…" where too long), its size and where each
// line goes, measured with DejaVu Sans's own metrics (unhinted, in font units, written at build time by
// generate/card_font_table.cpp from the font cairo draws with). The desktop's cards (cards.cpp) are drawn at this
// layout, and the phone player's core lays its cards out with the same code and table, so a card has the same size,
// and a medium the same place, on both.
#pragma once

#include "track/media_spec.hpp"

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace arwb::media {

struct CardLayout {
  std::vector<std::string> lines;   // as drawn, top to bottom
  double font_px = 32;              // the size drawn (spec.font_px within 4..512)
  int pad = 0;                      // around the text, pixels
  int line_h = 1;                   // from one line's top to the next's
  double ascent = 0;                // from a line's top to its baseline
  int width = 1, height = 1;        // the card, pixels (at most kMaxCardSide a side)
};

// spec.text in spec.font_px: valid UTF-8 (invalid bytes as U+FFFD, tabs as spaces, controls dropped), cut to
// MediaStore::kMaxCardText bytes, lines too long or too many for a kMaxCardSide square ended with "…".
CardLayout layout_text_card(const MediaSpec& spec);

// How wide `utf8` is in DejaVu Sans at `px`: its advance, or its ink's right edge where a glyph reaches further.
// A character the font does not have is measured as U+FFFD.
double card_text_width(std::string_view utf8, double px);
// Ascent, descent (positive, below the baseline) and line height at `px`.
double card_font_ascent(double px);
double card_font_height(double px);

// `s` if it fits in `max_width` by `width` (and no ellipsis is forced), else its longest prefix that fits followed by
// "…" ("…" alone when none does).
std::string fit_line(const std::string& s, double max_width, bool force_ellipsis,
                     const std::function<double(const std::string&)>& width);

// Valid UTF-8 with U+FFFD for invalid bytes; tabs as spaces; other control characters dropped, except '\n'.
std::string clean_card_text(std::string_view in);
// The longest prefix of valid UTF-8 `s` of at most `bytes` bytes that ends on a character boundary.
size_t utf8_prefix(std::string_view s, size_t bytes);

}  // namespace arwb::media
