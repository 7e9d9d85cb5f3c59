// Marker labels placed so they stay readable (ui/label_layout.hpp): crowded markers, rotated markers, media in
// the way, labels that must move away (leader lines), labels that cannot fit (hidden, last first), and positions
// that stay put from frame to frame.
#include "ui/label_layout.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace arwb::ui {
namespace {

constexpr float kGap = 3, kCorner = 5;

LabelQuad square(float cx, float cy, float side, float angle_deg = 0) {
  const float a = angle_deg * 3.14159265f / 180.0f, h = side * 0.5f;
  const float c = std::cos(a), s = std::sin(a);
  const float local[4][2] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
  LabelQuad q;
  for (int i = 0; i < 4; ++i) {
    q[static_cast<size_t>(i)] = {cx + c * local[i][0] - s * local[i][1], cy + s * local[i][0] + c * local[i][1]};
  }
  return q;
}

LabelLayoutInput grid_of_markers(int cols, int rows, float pitch, float side, float label_w, float label_h,
                                 float angle = 0) {
  LabelLayoutInput in;
  in.bounds = {0, 0, 1600, 900};
  in.gap = kGap;
  in.corner_margin = kCorner;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      LabelRequest req;
      req.anchor = square(60 + pitch * static_cast<float>(c), 60 + pitch * static_cast<float>(r), side,
                          angle * static_cast<float>((r * cols + c) % 7));
      req.width = label_w;
      req.height = label_h;
      req.key = static_cast<uint64_t>(r * cols + c);
      in.labels.push_back(req);
    }
  }
  return in;
}

// Whether p is inside a convex quad (strictly, by more than 0.01 px).
bool inside(const LabelQuad& q, LabelPoint p) {
  int sign = 0;
  for (size_t i = 0; i < 4; ++i) {
    const LabelPoint a = q[i], b = q[(i + 1) % 4];
    const float len = std::hypot(b.x - a.x, b.y - a.y);
    const float d = ((b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x)) / len;
    if (std::abs(d) < 0.01f) return false;
    const int s = d > 0 ? 1 : -1;
    if (sign && s != sign) return false;
    sign = s;
  }
  return true;
}

// What every layout must hold: placed labels inside the bounds, off each other, off every marker and its
// corners, off every media; counts that add up; a leader exactly when the label is away from its marker.
void expect_readable(const LabelLayoutInput& in, const LabelLayout& out) {
  ASSERT_EQ(out.placements.size(), in.labels.size());
  EXPECT_EQ(out.placed + out.hidden, static_cast<int>(in.labels.size()));
  int placed = 0;
  for (size_t i = 0; i < out.placements.size(); ++i) {
    const LabelPlacement& p = out.placements[i];
    if (!p.placed) continue;
    ++placed;
    EXPECT_GE(p.box.x0, in.bounds.x0);
    EXPECT_GE(p.box.y0, in.bounds.y0);
    EXPECT_LE(p.box.x1, in.bounds.x1);
    EXPECT_LE(p.box.y1, in.bounds.y1);
    EXPECT_NEAR(p.box.width(), p.short_form ? in.labels[i].short_width : in.labels[i].width, 1e-3);
    for (size_t j = i + 1; j < out.placements.size(); ++j) {
      if (out.placements[j].placed) {
        EXPECT_FALSE(p.box.overlaps(out.placements[j].box)) << "labels " << i << ", " << j;
      }
    }
    // Only a marker that runs off the view may carry its own label (zoomed in, no room around it).
    const LabelBox own = quad_box(in.labels[i].anchor);
    const bool runs_off = own.x0 < in.bounds.x0 || own.y0 < in.bounds.y0 || own.x1 > in.bounds.x1 ||
                          own.y1 > in.bounds.y1;
    for (size_t j = 0; j < in.labels.size(); ++j) {
      if (!(j == i && runs_off)) {
        EXPECT_FALSE(box_meets_quad(p.box, in.labels[j].anchor)) << "label " << i << " covers marker " << j;
      }
      for (const LabelPoint& c : in.labels[j].anchor) {
        const LabelBox around{p.box.x0 - kCorner, p.box.y0 - kCorner, p.box.x1 + kCorner, p.box.y1 + kCorner};
        EXPECT_FALSE(around.contains(c) && !(c.x == around.x0 || c.x == around.x1 || c.y == around.y0 ||
                                             c.y == around.y1))
            << "label " << i << " within " << kCorner << " px of a corner of marker " << j;
      }
    }
    for (const LabelQuad& media : in.obstacles) EXPECT_FALSE(box_meets_quad(p.box, media)) << "label " << i;
    // A leader when, and only when, the label does not touch its marker's box.
    const LabelBox a = quad_box(in.labels[i].anchor);
    const float sep = std::max(std::max({0.0f, a.x0 - p.box.x1, p.box.x0 - a.x1}),
                               std::max({0.0f, a.y0 - p.box.y1, p.box.y0 - a.y1}));
    EXPECT_EQ(p.leader, sep > kCorner + 0.5f) << "label " << i << " at " << sep << " px from its marker";
    if (p.leader) {
      // Through no other marker and no other label: checked at 64 points along it.
      for (int k = 1; k < 64; ++k) {
        const float t = static_cast<float>(k) / 64.0f;
        const LabelPoint at{p.leader_from.x + t * (p.leader_to.x - p.leader_from.x),
                            p.leader_from.y + t * (p.leader_to.y - p.leader_from.y)};
        for (size_t j = 0; j < in.labels.size(); ++j) {
          if (j != i) {
            EXPECT_FALSE(inside(in.labels[j].anchor, at)) << "leader " << i << " crosses marker " << j;
          }
          const LabelBox& other = out.placements[j].box;
          if (j != i && out.placements[j].placed) {
            EXPECT_FALSE(at.x > other.x0 && at.x < other.x1 && at.y > other.y0 && at.y < other.y1)
                << "leader " << i << " crosses label " << j;
          }
        }
      }
      // From the label's edge to the marker's outline.
      EXPECT_TRUE(p.box.contains(p.leader_from));
      EXPECT_TRUE(box_meets_quad({p.leader_to.x - 0.5f, p.leader_to.y - 0.5f, p.leader_to.x + 0.5f,
                                  p.leader_to.y + 0.5f},
                                 in.labels[i].anchor));
    }
  }
  EXPECT_EQ(placed, out.placed);
}

TEST(LabelLayout, SpaciousMarkersGetTheirLabelRightAbove) {
  const LabelLayoutInput in = grid_of_markers(6, 4, 200, 60, 110, 16);
  const LabelLayout out = layout_labels(in);
  expect_readable(in, out);
  EXPECT_EQ(out.hidden, 0);
  for (size_t i = 0; i < in.labels.size(); ++i) {
    const LabelBox a = quad_box(in.labels[i].anchor);
    const LabelPlacement& p = out.placements[i];
    EXPECT_NEAR(p.box.y1, a.y0 - kCorner, 1e-3) << i;   // above, clear of the corner marks
    EXPECT_NEAR((p.box.x0 + p.box.x1) * 0.5f, (a.x0 + a.x1) * 0.5f, 1e-3) << i;
    EXPECT_FALSE(p.leader);
  }
}

TEST(LabelLayout, CrowdedMarkersNeverOverlapAndHideWhatCannotFit) {
  // 240 markers 60 px apart with labels wider than the spacing ("12 ARUCO_ORIGINAL" is about 130 px).
  const LabelLayoutInput in = grid_of_markers(24, 10, 60, 40, 130, 16);
  const LabelLayout out = layout_labels(in);
  expect_readable(in, out);
  EXPECT_GT(out.placed, 20);
  EXPECT_GT(out.hidden, 0);
}

TEST(LabelLayout, RotatedCrowdedMarkersKeepTheirCornersClear) {
  const LabelLayoutInput in = grid_of_markers(12, 8, 110, 70, 60, 16, 13);
  const LabelLayout out = layout_labels(in);
  expect_readable(in, out);
  EXPECT_GE(out.placed, 48);   // half of them, in gaps barely wider than a label
}

TEST(LabelLayout, BlockedNeighbourhoodMovesTheLabelOutWithALeader) {
  // A marker near the view's bottom edge, two small markers right above it: every place next to it is taken or
  // outside the view, so its label moves one ring up, and its leader passes between the small markers.
  LabelLayoutInput in;
  in.bounds = {350, 240, 450, 320};
  in.gap = kGap;
  in.corner_margin = kCorner;
  auto add = [&](float x, float y, float side) {
    LabelRequest r;
    r.anchor = square(x, y, side);
    r.width = 50;
    r.height = 14;
    r.key = in.labels.size();
    in.labels.push_back(r);
  };
  add(400, 300, 30);
  add(380, 275, 8);
  add(420, 275, 8);
  const LabelLayout out = layout_labels(in);
  expect_readable(in, out);
  ASSERT_TRUE(out.placements[0].placed);
  EXPECT_TRUE(out.placements[0].leader);
  EXPECT_NEAR(out.placements[0].box.y1, 285 - kCorner - 14 - kGap, 1e-3);   // the second ring above
  EXPECT_NEAR(out.placements[0].leader_to.y, 285, 1e-3);                     // from the marker's top edge
}

TEST(LabelLayout, LeadersNeverCrossAnotherMarker) {
  // A marker boxed in by others on every side: a leader would have to cross one, so its label is hidden rather
  // than joined to it across another marker.
  LabelLayoutInput in;
  in.bounds = {0, 0, 800, 600};
  in.gap = kGap;
  in.corner_margin = kCorner;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      LabelRequest r;
      r.anchor = square(400 + 40.0f * static_cast<float>(dx), 300 + 40.0f * static_cast<float>(dy), 34);
      r.width = 50;
      r.height = 14;
      r.key = in.labels.size();
      if (dx == 0 && dy == 0) in.labels.insert(in.labels.begin(), r);
      else in.labels.push_back(r);
    }
  }
  const LabelLayout out = layout_labels(in);
  expect_readable(in, out);
  EXPECT_FALSE(out.placements[0].placed);
  EXPECT_EQ(out.hidden, 1);
}

TEST(LabelLayout, LabelsKeepOffTheMedia) {
  LabelLayoutInput in = grid_of_markers(3, 1, 300, 60, 120, 16);
  // A media drawn over the middle marker and the space above it (a picture on a plinth).
  in.obstacles.push_back(square(360, -45, 200));   // down to y = 55, the marker's upper half
  const LabelLayout out = layout_labels(in);
  expect_readable(in, out);
  EXPECT_EQ(out.hidden, 0);
  const LabelBox a = quad_box(in.labels[1].anchor);
  EXPECT_GE(out.placements[1].box.y0, a.y1) << "the middle label went below its marker, away from the media";
  EXPECT_FALSE(out.placements[1].leader);
}

TEST(LabelLayout, WhatCannotBePlacedIsDroppedLastPriorityFirst) {
  // Two markers side by side in a view that holds one label: the first keeps it.
  LabelLayoutInput in;
  in.bounds = {0, 0, 200, 70};   // 150 px labels fit only centred over x = 100
  in.gap = kGap;
  in.corner_margin = kCorner;
  for (int i = 0; i < 2; ++i) {
    LabelRequest r;
    r.anchor = square(100 + 50.0f * static_cast<float>(i), 45, 40);
    r.width = 150;
    r.height = 16;
    r.key = static_cast<uint64_t>(i);
    in.labels.push_back(r);
  }
  const LabelLayout out = layout_labels(in);
  expect_readable(in, out);
  EXPECT_TRUE(out.placements[0].placed);
  EXPECT_FALSE(out.placements[1].placed);
  EXPECT_EQ(out.hidden, 1);
}

TEST(LabelLayout, AZoomedInMarkerCarriesItsLabelOnItsVisiblePart) {
  // The view shows the upper part of one big marker (zoomed in): no room around it, so its label sits on it,
  // centred on what is visible.
  LabelLayoutInput in;
  in.bounds = {0, 0, 400, 300};
  in.gap = kGap;
  in.corner_margin = kCorner;
  LabelRequest big;
  big.anchor = square(200, 250, 500);
  big.width = 120;
  big.height = 16;
  big.key = 1;
  in.labels.push_back(big);
  const LabelLayout out = layout_labels(in);
  expect_readable(in, out);
  ASSERT_TRUE(out.placements[0].placed);
  EXPECT_FALSE(out.placements[0].leader);
  EXPECT_NEAR((out.placements[0].box.x0 + out.placements[0].box.x1) * 0.5f, 200, 1e-3);
  EXPECT_NEAR((out.placements[0].box.y0 + out.placements[0].box.y1) * 0.5f, 150, 1e-3);   // the visible part's middle
  // Whole in the view, the same marker keeps its label off itself, beside it.
  in.bounds = {-300, -100, 700, 600};
  const LabelLayout whole = layout_labels(in);
  expect_readable(in, whole);
  EXPECT_TRUE(whole.placements[0].placed);
  EXPECT_FALSE(box_meets_quad(whole.placements[0].box, big.anchor));
}

TEST(LabelLayout, TheShortTextWhereTheFullOneFindsNoRoom) {
  // As above, with an id-only text of 20 px for each: the second marker gets its id next to it.
  LabelLayoutInput in;
  in.bounds = {0, 0, 200, 70};
  in.gap = kGap;
  in.corner_margin = kCorner;
  for (int i = 0; i < 2; ++i) {
    LabelRequest r;
    r.anchor = square(100 + 50.0f * static_cast<float>(i), 45, 40);
    r.width = 150;
    r.short_width = 20;
    r.height = 16;
    r.key = static_cast<uint64_t>(i);
    in.labels.push_back(r);
  }
  LabelCache cache;
  const LabelLayout out = layout_labels(in, &cache);
  expect_readable(in, out);
  EXPECT_EQ(out.hidden, 0);
  EXPECT_FALSE(out.placements[0].short_form);
  EXPECT_TRUE(out.placements[1].short_form);
  // Kept, short, in the next frame.
  const LabelLayout next = layout_labels(in, &cache);
  EXPECT_TRUE(next.placements[1].short_form);
  EXPECT_EQ(next.placements[1].box.x0, out.placements[1].box.x0);
}

TEST(LabelLayout, UnmovedMarkersKeepTheirLabelsFrameToFrame) {
  LabelLayoutInput in = grid_of_markers(12, 6, 90, 50, 100, 16);
  LabelCache cache;
  const LabelLayout first = layout_labels(in, &cache);
  expect_readable(in, first);
  // The same input gives the same layout (deterministic)...
  const LabelLayout again = layout_labels(in);
  // ...and, next frame, a marker appears among the others and one far away moves: the rest stay put.
  LabelLayoutInput next = in;
  LabelRequest newcomer;
  newcomer.anchor = square(60 + 90 * 4.5f, 60 + 90 * 2.5f, 40);
  newcomer.width = 100;
  newcomer.height = 16;
  newcomer.key = 999;
  next.labels.insert(next.labels.begin(), newcomer);   // even ahead of them all in priority
  for (LabelPoint& p : next.labels.back().anchor) p.x += 7;
  const LabelLayout second = layout_labels(next, &cache);
  expect_readable(next, second);
  int kept = 0, compared = 0;
  for (size_t i = 0; i + 1 < in.labels.size(); ++i) {
    const LabelPlacement& a = first.placements[i];
    EXPECT_EQ(a.placed, again.placements[i].placed);
    EXPECT_EQ(a.box.x0, again.placements[i].box.x0);
    EXPECT_EQ(a.box.y0, again.placements[i].box.y0);
    const LabelPlacement& b = second.placements[i + 1];
    if (!a.placed || !b.placed) continue;
    // Labels the newcomer's own marker now covers must move; the others stay.
    if (box_meets_quad(a.box, newcomer.anchor, kCorner)) continue;
    ++compared;
    kept += a.box.x0 == b.box.x0 && a.box.y0 == b.box.y0;
  }
  EXPECT_GT(compared, 40);
  EXPECT_EQ(kept, compared);

  // A marker that drops out for a frame (a flicker) frees room next to its neighbours: their labels stay where
  // they are all the same, and nothing jumps when it comes back.
  LabelLayoutInput flicker = in;
  const size_t gone = 1;   // the second marker of the top row: its neighbours' labels are nearby
  flicker.labels.erase(flicker.labels.begin() + static_cast<long>(gone));
  LabelCache steady;
  const LabelLayout before = layout_labels(in, &steady);
  const LabelLayout during = layout_labels(flicker, &steady);
  const LabelLayout after = layout_labels(in, &steady);
  const LabelLayout fresh = layout_labels(flicker);
  int moved_if_fresh = 0;
  for (size_t i = 0; i < in.labels.size(); ++i) {
    if (i == gone || !before.placements[i].placed) continue;
    const size_t j = i < gone ? i : i - 1;
    EXPECT_EQ(during.placements[j].box.x0, before.placements[i].box.x0) << i;
    EXPECT_EQ(during.placements[j].box.y0, before.placements[i].box.y0) << i;
    EXPECT_EQ(after.placements[i].box.x0, before.placements[i].box.x0) << i;
    EXPECT_EQ(after.placements[i].box.y0, before.placements[i].box.y0) << i;
    moved_if_fresh += fresh.placements[j].box.x0 != before.placements[i].box.x0 ||
                      fresh.placements[j].box.y0 != before.placements[i].box.y0;
  }
  EXPECT_GT(moved_if_fresh, 0) << "without the last positions, the flicker would have moved labels";
}

TEST(LabelLayout, BoxAgainstRotatedQuad) {
  const LabelQuad diamond = square(100, 100, 100, 45);   // corners at distance 70.7 from the centre
  EXPECT_TRUE(box_meets_quad({90, 90, 110, 110}, diamond));
  // In the diamond's bounding box but outside the diamond: near its top-left corner.
  EXPECT_FALSE(box_meets_quad({30, 30, 50, 50}, diamond));
  EXPECT_TRUE(box_meets_quad({30, 30, 50, 50}, diamond, 30));
  EXPECT_FALSE(box_meets_quad({200, 90, 220, 110}, diamond));
  // Touching is not meeting: labels are placed touching at the gap.
  EXPECT_FALSE(box_meets_quad({150, 0, 170, 20}, square(100, 100, 100)));
  EXPECT_FALSE(box_meets_quad({50, 30, 150, 50}, square(100, 100, 100)));
}

TEST(LabelLayout, NothingToPlaceAndDegenerateInput) {
  LabelCache cache{{1, 2, 3}};
  const LabelLayout none = layout_labels({}, &cache);
  EXPECT_TRUE(none.placements.empty());
  EXPECT_TRUE(cache.empty());
  LabelLayoutInput in = grid_of_markers(2, 1, 200, 40, 0, 16);   // empty text
  in.labels[1].anchor[2] = {NAN, 5};
  in.labels[1].width = 50;
  const LabelLayout out = layout_labels(in);
  EXPECT_EQ(out.hidden, 2);
}

}  // namespace
}  // namespace arwb::ui
