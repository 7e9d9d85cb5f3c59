// Where the live view puts marker labels so they stay readable: next to their marker, never over another label,
// any marker or a projected media, inside the view. Pure geometry in screen pixels (no ImGui), so it is tested on
// its own (tests/ui/test_label_layout.cpp). `arwb render` draws no labels, so this lives with the UI.
//
// Greedy: first every label whose position of the last frame (relative to its marker) is still free keeps it, in
// priority order (the order of `labels`), so labels do not jump while their markers stand still, even when a new
// marker appears; then the others, in priority order, take the first free candidate around their marker: the four
// sides and four diagonals touching the marker's box, then the same eight further out, where a leader line joins
// label and marker (a leader crosses no other marker, label, leader or media); in each ring the full text, then a
// short one when given. A marker that runs off the view (zoomed in) with no room around it gets its label on its
// visible part, off its corners. A label with no free position is hidden, so the last labels are the ones dropped.
// Obstacles are kept in a uniform grid: 300 crowded labels take about 0.7 ms, 100 about 0.2 ms.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace arwb::ui {

struct LabelPoint {
  float x = 0, y = 0;
};

// An axis-aligned box, x0 <= x1, y0 <= y1.
struct LabelBox {
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  float width() const { return x1 - x0; }
  float height() const { return y1 - y0; }
  // Open intersection: boxes that only touch do not overlap.
  bool overlaps(const LabelBox& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  bool contains(LabelPoint p) const { return p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1; }
};

using LabelQuad = std::array<LabelPoint, 4>;

struct LabelRequest {
  LabelQuad anchor{};       // the marker's corners on screen; the label keeps off them
  float width = 0, height = 0;   // the label's box (text and padding)
  float short_width = 0;    // the box of a shorter text (the id alone), tried where the full one finds no room;
                            // 0: none
  uint64_t key = 0;         // identifies the label across frames (id and dictionary) for the cached position
};

struct LabelLayoutInput {
  std::vector<LabelRequest> labels;   // by priority, first is most important
  std::vector<LabelQuad> obstacles;   // more quads labels keep off (the projected media); convex
  LabelBox bounds;                    // labels stay inside (the view)
  float gap = 3;                      // space kept between a label and what it avoids, screen px (scales)
  float corner_margin = 4;            // space kept around each marker's corners (the corner-0 mark's size); the
                                      // nearest labels sit max(gap, corner_margin) from their marker's box
};

struct LabelPlacement {
  bool placed = false;
  bool short_form = false;          // the box holds the short text
  LabelBox box;
  bool leader = false;              // placed further from its marker's box than the nearest ring: draw a line
                                    // from `leader_from` to `leader_to`
  LabelPoint leader_from, leader_to;   // on the label's box and on the marker's outline
};

// A label's position relative to its marker's box, kept between frames by the caller (LabelCache).
struct LabelMemory {
  uint64_t key = 0;
  float dx = 0, dy = 0;   // the box's top-left minus the anchor box's top-left
  bool short_form = false;
};
using LabelCache = std::vector<LabelMemory>;

struct LabelLayout {
  std::vector<LabelPlacement> placements;   // one per request, in the same order
  int placed = 0, hidden = 0;
};

// Places the labels. `cache` (may be null) gives each key's position of the last call and receives this call's.
LabelLayout layout_labels(const LabelLayoutInput& in, LabelCache* cache = nullptr);

// The box around a quad's corners.
LabelBox quad_box(const LabelQuad& q);
// Whether a box and a quad (convex, or else its box is used) share any point, the box grown by `margin`.
bool box_meets_quad(const LabelBox& b, const LabelQuad& q, float margin = 0);

}  // namespace arwb::ui
