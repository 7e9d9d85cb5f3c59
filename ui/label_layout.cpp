#include "ui/label_layout.hpp"

#include <algorithm>
#include <cmath>

namespace arwb::ui {

namespace {

// Boxes that touch within this do not meet: positions are computed to touch exactly, up to rounding.
constexpr float kEps = 1e-3f;

LabelBox grown(const LabelBox& b, float m) { return {b.x0 - m, b.y0 - m, b.x1 + m, b.y1 + m}; }

bool convex(const LabelQuad& q) {
  int sign = 0;
  for (size_t i = 0; i < 4; ++i) {
    const LabelPoint& a = q[i];
    const LabelPoint& b = q[(i + 1) % 4];
    const LabelPoint& c = q[(i + 2) % 4];
    const float cross = (b.x - a.x) * (c.y - b.y) - (b.y - a.y) * (c.x - b.x);
    if (std::abs(cross) < 1e-6f) continue;
    const int s = cross > 0 ? 1 : -1;
    if (sign != 0 && s != sign) return false;
    sign = s;
  }
  return true;
}

// The point of segment ab nearest p.
LabelPoint nearest_on_segment(LabelPoint a, LabelPoint b, LabelPoint p) {
  const float dx = b.x - a.x, dy = b.y - a.y;
  const float len2 = dx * dx + dy * dy;
  float t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0;
  t = std::clamp(t, 0.0f, 1.0f);
  return {a.x + t * dx, a.y + t * dy};
}

float dist2(LabelPoint a, LabelPoint b) { return (a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y); }

bool overlap_open(const LabelBox& a, const LabelBox& b) {
  return a.x0 < b.x1 - kEps && b.x0 < a.x1 - kEps && a.y0 < b.y1 - kEps && b.y0 < a.y1 - kEps;
}

// Separating axes for two convex polygons (a segment is a polygon of two points): they meet unless some edge
// normal separates them. Touching is not meeting.
bool convex_meet(const LabelPoint* a, int na, const LabelPoint* b, int nb) {
  auto separated_along = [&](const LabelPoint* poly, int n) {
    for (int i = 0; i < n; ++i) {
      const LabelPoint p = poly[i], q = poly[(i + 1) % n];
      const float nx = -(q.y - p.y), ny = q.x - p.x;
      const float len = std::sqrt(nx * nx + ny * ny);
      if (len < 1e-6f) continue;
      float amin = 1e30f, amax = -1e30f, bmin = 1e30f, bmax = -1e30f;
      for (int k = 0; k < na; ++k) {
        const float d = (a[k].x * nx + a[k].y * ny) / len;
        amin = std::min(amin, d);
        amax = std::max(amax, d);
      }
      for (int k = 0; k < nb; ++k) {
        const float d = (b[k].x * nx + b[k].y * ny) / len;
        bmin = std::min(bmin, d);
        bmax = std::max(bmax, d);
      }
      if (amax <= bmin + kEps || bmax <= amin + kEps) return true;
      if (n == 2) break;   // a segment's second "edge" is the same line
    }
    return false;
  };
  return !separated_along(a, na) && !separated_along(b, nb);
}

struct Segment {
  LabelPoint from, to;
  LabelBox box() const {
    return {std::min(from.x, to.x), std::min(from.y, to.y), std::max(from.x, to.x), std::max(from.y, to.y)};
  }
};

bool segment_meets_box(const Segment& s, const LabelBox& b) {
  const LabelPoint seg[2] = {s.from, s.to};
  const LabelPoint corners[4] = {{b.x0, b.y0}, {b.x1, b.y0}, {b.x1, b.y1}, {b.x0, b.y1}};
  // A segment along the box's edge (its axis-aligned box is flat) is outside it: the open test below.
  const LabelBox sb = s.box();
  if (sb.x1 <= b.x0 + kEps || b.x1 <= sb.x0 + kEps || sb.y1 <= b.y0 + kEps || b.y1 <= sb.y0 + kEps) return false;
  return convex_meet(seg, 2, corners, 4);
}

bool segment_meets_quad(const Segment& s, const LabelQuad& q) {
  const LabelPoint seg[2] = {s.from, s.to};
  if (!convex(q)) return segment_meets_box(s, quad_box(q));
  return convex_meet(seg, 2, q.data(), 4);
}

bool segments_cross(const Segment& a, const Segment& b) {
  const LabelPoint sa[2] = {a.from, a.to}, sb[2] = {b.from, b.to};
  return convex_meet(sa, 2, sb, 2);
}

// Obstacles in a uniform grid over the bounds, so a candidate is tested against its neighbours only.
class Grid {
 public:
  Grid(const LabelBox& bounds, float cell) : origin_{bounds.x0, bounds.y0}, cell_(std::max(cell, 8.0f)) {
    cols_ = std::clamp(static_cast<int>(std::ceil(bounds.width() / cell_)), 1, 512);
    rows_ = std::clamp(static_cast<int>(std::ceil(bounds.height() / cell_)), 1, 512);
    cells_.resize(static_cast<size_t>(cols_ * rows_));
  }
  void add(const LabelBox& b, int item) {
    int cx0, cy0, cx1, cy1;
    if (!span(b, &cx0, &cy0, &cx1, &cy1)) return;
    for (int y = cy0; y <= cy1; ++y)
      for (int x = cx0; x <= cx1; ++x) cells_[static_cast<size_t>(y * cols_ + x)].push_back(item);
  }
  // Calls f(item) once for each item whose cells meet `b`, until f returns true; returns whether one did.
  template <class F>
  bool any(const LabelBox& b, std::vector<int>& seen, int stamp, F f) const {
    int cx0, cy0, cx1, cy1;
    if (!span(b, &cx0, &cy0, &cx1, &cy1)) return false;
    for (int y = cy0; y <= cy1; ++y) {
      for (int x = cx0; x <= cx1; ++x) {
        for (int item : cells_[static_cast<size_t>(y * cols_ + x)]) {
          if (seen[static_cast<size_t>(item)] == stamp) continue;
          seen[static_cast<size_t>(item)] = stamp;
          if (f(item)) return true;
        }
      }
    }
    return false;
  }

 private:
  // The cells a box covers, clamped to the grid (things outside the bounds land in the border cells).
  bool span(const LabelBox& b, int* cx0, int* cy0, int* cx1, int* cy1) const {
    if (!(b.x0 <= b.x1 && b.y0 <= b.y1)) return false;   // also refuses NaN
    auto cell = [&](float v, float o, int n) {
      const float c = std::floor((v - o) / cell_);
      return static_cast<int>(std::clamp(c, 0.0f, static_cast<float>(n - 1)));
    };
    *cx0 = cell(b.x0, origin_.x, cols_);
    *cx1 = cell(b.x1, origin_.x, cols_);
    *cy0 = cell(b.y0, origin_.y, rows_);
    *cy1 = cell(b.y1, origin_.y, rows_);
    return true;
  }
  LabelPoint origin_;
  float cell_;
  int cols_ = 1, rows_ = 1;
  std::vector<std::vector<int>> cells_;
};

enum class Kind { marker, media, label, leader };
struct Item {
  Kind kind;
  int index;   // into labels (markers and placed labels) or obstacles (media)
};

}  // namespace

LabelBox quad_box(const LabelQuad& q) {
  LabelBox b{q[0].x, q[0].y, q[0].x, q[0].y};
  for (const LabelPoint& p : q) {
    b.x0 = std::min(b.x0, p.x);
    b.y0 = std::min(b.y0, p.y);
    b.x1 = std::max(b.x1, p.x);
    b.y1 = std::max(b.y1, p.y);
  }
  return b;
}

bool box_meets_quad(const LabelBox& box, const LabelQuad& q, float margin) {
  const LabelBox b = grown(box, margin);
  const LabelBox qb = quad_box(q);
  if (!overlap_open(b, qb)) return false;
  if (!convex(q)) return true;   // its box stands in
  const LabelPoint corners[4] = {{b.x0, b.y0}, {b.x1, b.y0}, {b.x1, b.y1}, {b.x0, b.y1}};
  return convex_meet(corners, 4, q.data(), 4);
}

namespace {

// One call's placing: the grid of what is on the view so far (markers, media, then each label and its leader as
// it is placed) and the last call's positions.
class Placer {
 public:
  // The grid's cells are about four label heights wide: a candidate meets a handful of cells.
  Placer(const LabelLayoutInput& in, LabelCache* cache, LabelLayout* out)
      : in_(in), out_(*out), gap_(std::max(0.0f, in.gap)), corner_(std::max(gap_, in.corner_margin)),
        grid_(in.bounds, std::max(typical_height(in) * 4.0f, 32.0f)) {
    const size_t n = in.labels.size();
    items_.reserve(n * 4 + in.obstacles.size());
    anchor_boxes_.resize(n);
    for (size_t i = 0; i < n; ++i) {
      anchor_boxes_[i] = quad_box(in.labels[i].anchor);
      add(grown(anchor_boxes_[i], corner_ + gap_), Kind::marker, i);
    }
    for (size_t i = 0; i < in.obstacles.size(); ++i) add(grown(quad_box(in.obstacles[i]), gap_), Kind::media, i);
    seen_.assign(items_.size() + 2 * n, -1);
    if (cache) {
      previous_ = *cache;
      std::sort(previous_.begin(), previous_.end(),
                [](const LabelMemory& a, const LabelMemory& b) { return a.key < b.key; });
    }
  }

  const LabelBox& anchor_box(size_t i) const { return anchor_boxes_[i]; }
  bool has_previous() const { return !previous_.empty(); }

  // Label i at its last position (remembered_only) or at the nearest free candidate; false: no place for it.
  bool place(size_t i, bool remembered_only) {
    const LabelRequest& r = in_.labels[i];
    if (!(r.width > 0 && r.height > 0 && std::isfinite(r.width) && std::isfinite(r.height))) return false;
    for (const LabelPoint& q : r.anchor)
      if (!std::isfinite(q.x) || !std::isfinite(q.y)) return false;
    const bool found = remembered_only ? at_remembered(i) : (in_rings(i) || on_visible_part(i));
    if (!found) return false;
    const LabelPlacement& p = out_.placements[i];
    add(grown(p.box, gap_), Kind::label, i);
    if (p.leader) add(Segment{p.leader_from, p.leader_to}.box(), Kind::leader, i);
    return true;
  }

 private:
  static float typical_height(const LabelLayoutInput& in) {
    float h = 0;
    for (const LabelRequest& r : in.labels) h = std::max(h, r.height);
    return h;
  }

  void add(const LabelBox& b, Kind kind, size_t index) {
    grid_.add(b, static_cast<int>(items_.size()));
    items_.push_back({kind, static_cast<int>(index)});
  }

  // A leader from the marker's outline (the point nearest the label's middle) to the label, when the label is
  // beyond the first ring; none otherwise.
  bool leader_for(size_t i, const LabelBox& c, Segment* out_leader) const {
    const LabelBox& a = anchor_boxes_[i];
    const float sep_x = std::max({0.0f, a.x0 - c.x1, c.x0 - a.x1});
    const float sep_y = std::max({0.0f, a.y0 - c.y1, c.y0 - a.y1});
    if (std::max(sep_x, sep_y) <= corner_ + 0.5f) return false;
    const LabelQuad& q = in_.labels[i].anchor;
    const LabelPoint mid{(c.x0 + c.x1) * 0.5f, (c.y0 + c.y1) * 0.5f};
    LabelPoint best = q[0];
    for (size_t e = 0; e < 4; ++e) {
      const LabelPoint p = nearest_on_segment(q[e], q[(e + 1) % 4], mid);
      if (e == 0 || dist2(p, mid) < dist2(best, mid)) best = p;
    }
    *out_leader = {{std::clamp(best.x, c.x0, c.x1), std::clamp(best.y, c.y0, c.y1)}, best};
    return true;
  }

  // Whether an item of the grid is in the way of label i at `c` (with `leader` when it has one).
  bool in_the_way(const Item& it, size_t i, const LabelBox& c, const Segment* leader, bool on_own_marker) const {
    const size_t k = static_cast<size_t>(it.index);
    const LabelBox spaced = grown(c, gap_);
    switch (it.kind) {
      case Kind::marker: {
        const LabelQuad& q = in_.labels[k].anchor;
        if (!(on_own_marker && k == i) && box_meets_quad(c, q, gap_)) return true;
        const LabelBox around = grown(c, corner_);
        for (const LabelPoint& p : q)
          if (p.x > around.x0 && p.x < around.x1 && p.y > around.y0 && p.y < around.y1) return true;
        return leader && k != i && segment_meets_quad(*leader, q);
      }
      case Kind::media:
        return box_meets_quad(c, in_.obstacles[k], gap_) || (leader && segment_meets_quad(*leader, in_.obstacles[k]));
      case Kind::label:
        return spaced.overlaps(out_.placements[k].box) ||
               (leader && segment_meets_box(*leader, grown(out_.placements[k].box, gap_)));
      case Kind::leader: {
        const Segment other{out_.placements[k].leader_from, out_.placements[k].leader_to};
        return segment_meets_box(other, spaced) || (leader && segments_cross(*leader, other));
      }
    }
    return false;
  }

  // Whether label i may sit at `c` (with `leader` when it has one): inside the bounds, its box off every marker
  // and its corners, the media, the other labels and their leaders; its leader across no other marker, media,
  // label or leader.
  bool free_at(size_t i, const LabelBox& c, const Segment* leader, bool on_own_marker = false) {
    const LabelBox& v = in_.bounds;
    if (c.x0 < v.x0 - kEps || c.y0 < v.y0 - kEps || c.x1 > v.x1 + kEps || c.y1 > v.y1 + kEps) return false;
    LabelBox probe = grown(c, corner_ + gap_);
    if (leader) {
      const LabelBox lb = leader->box();
      probe = {std::min(probe.x0, lb.x0), std::min(probe.y0, lb.y0), std::max(probe.x1, lb.x1),
               std::max(probe.y1, lb.y1)};
    }
    return !grid_.any(probe, seen_, ++stamp_, [&](int item) {
      return in_the_way(items_[static_cast<size_t>(item)], i, c, leader, on_own_marker);
    });
  }

  // Label i at `c`, with a leader when it is that far, if it is free there.
  bool take(size_t i, const LabelBox& c, bool short_form) {
    Segment leader;
    const bool has_leader = leader_for(i, c, &leader);
    if (!free_at(i, c, has_leader ? &leader : nullptr)) return false;
    LabelPlacement& p = out_.placements[i];
    p.placed = true;
    p.box = c;
    p.short_form = short_form;
    p.leader = has_leader;
    if (has_leader) {
      p.leader_from = leader.from;
      p.leader_to = leader.to;
    }
    return true;
  }

  bool has_short(const LabelRequest& r) const { return r.short_width > 0 && r.short_width < r.width; }

  // Where the last call put it, relative to its marker, if that is still free.
  bool at_remembered(size_t i) {
    const LabelRequest& r = in_.labels[i];
    const auto it = std::lower_bound(previous_.begin(), previous_.end(), r.key,
                                     [](const LabelMemory& m, uint64_t k) { return m.key < k; });
    if (it == previous_.end() || it->key != r.key || (it->short_form && !has_short(r))) return false;
    const LabelBox& a = anchor_boxes_[i];
    const float w = it->short_form ? r.short_width : r.width;
    return take(i, {a.x0 + it->dx, a.y0 + it->dy, a.x0 + it->dx + w, a.y0 + it->dy + r.height}, it->short_form);
  }

  // The first ring touches the marker's box as close as its corner marks allow. In each ring the full text first,
  // then the short one: near and short reads better than far and full.
  bool in_rings(size_t i) {
    constexpr int kRings = 6;
    const LabelRequest& r = in_.labels[i];
    const LabelBox& a = anchor_boxes_[i];
    const float h = r.height;
    const float cx = (a.x0 + a.x1) * 0.5f, cy = (a.y0 + a.y1) * 0.5f;
    const float step = h + gap_;
    for (int k = 0; k < kRings; ++k) {
      for (int form = 0; form < (has_short(r) ? 2 : 1); ++form) {
        const float w = form == 0 ? r.width : r.short_width;
        const float d = corner_ + static_cast<float>(k) * step;
        const float above = a.y0 - d - h, below = a.y1 + d, left = a.x0 - d - w, right = a.x1 + d;
        const LabelBox candidates[8] = {
            {cx - w * 0.5f, above, cx + w * 0.5f, above + h},  {cx - w * 0.5f, below, cx + w * 0.5f, below + h},
            {right, cy - h * 0.5f, right + w, cy + h * 0.5f},  {left, cy - h * 0.5f, left + w, cy + h * 0.5f},
            {right, above, right + w, above + h},              {left, above, left + w, above + h},
            {right, below, right + w, below + h},              {left, below, left + w, below + h},
        };
        for (const LabelBox& c : candidates)
          if (take(i, c, form == 1)) return true;
      }
    }
    return false;
  }

  // Zoomed in, the marker runs off the view and there is no room around it: on the marker's visible part,
  // centred, still off its corners, rather than no label at all.
  bool on_visible_part(size_t i) {
    const LabelRequest& r = in_.labels[i];
    const LabelBox& a = anchor_boxes_[i];
    const LabelBox& v = in_.bounds;
    if (!(a.x0 < v.x0 || a.y0 < v.y0 || a.x1 > v.x1 || a.y1 > v.y1)) return false;
    const float vx0 = std::max(a.x0, v.x0), vy0 = std::max(a.y0, v.y0);
    const float vx1 = std::min(a.x1, v.x1), vy1 = std::min(a.y1, v.y1);
    const float mx = (vx0 + vx1) * 0.5f, my = (vy0 + vy1) * 0.5f, h = r.height;
    for (int form = 0; form < (has_short(r) ? 2 : 1); ++form) {
      const float w = form == 0 ? r.width : r.short_width;
      const LabelBox c{mx - w * 0.5f, my - h * 0.5f, mx + w * 0.5f, my + h * 0.5f};
      if (c.x0 >= vx0 && c.x1 <= vx1 && c.y0 >= vy0 && c.y1 <= vy1 && free_at(i, c, nullptr, true)) {
        LabelPlacement& p = out_.placements[i];
        p = {};
        p.placed = true;
        p.box = c;
        p.short_form = form == 1;
        return true;
      }
    }
    return false;
  }

  const LabelLayoutInput& in_;
  LabelLayout& out_;
  const float gap_, corner_;
  Grid grid_;
  std::vector<Item> items_;
  std::vector<LabelBox> anchor_boxes_;
  std::vector<int> seen_;
  int stamp_ = 0;
  LabelCache previous_;   // the last call's positions, by key
};

}  // namespace

LabelLayout layout_labels(const LabelLayoutInput& in, LabelCache* cache) {
  LabelLayout out;
  const size_t n = in.labels.size();
  out.placements.resize(n);
  if (n == 0) {
    if (cache) cache->clear();
    return out;
  }
  Placer placer(in, cache, &out);
  if (cache) cache->clear();
  // First the labels whose last position is still free keep it, in priority order, so a marker that appears
  // does not push the others about; then the rest, in priority order, take the nearest free candidate.
  std::vector<char> done(n, 0);
  if (placer.has_previous()) {
    for (size_t i = 0; i < n; ++i) done[i] = placer.place(i, true);
  }
  for (size_t i = 0; i < n; ++i) {
    if (!done[i]) done[i] = placer.place(i, false);
  }
  for (size_t i = 0; i < n; ++i) {
    if (!done[i]) {
      ++out.hidden;
      continue;
    }
    ++out.placed;
    const LabelBox& a = placer.anchor_box(i);
    const LabelPlacement& p = out.placements[i];
    if (cache) cache->push_back({in.labels[i].key, p.box.x0 - a.x0, p.box.y0 - a.y0, p.short_form});
  }
  return out;
}

}  // namespace arwb::ui
