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

enum class Kind { marker, media, label };
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
  // Separating axes: the box's two, then the quad's edge normals (convex quads only; else its box stands in).
  if (b.x1 <= qb.x0 + kEps || qb.x1 <= b.x0 + kEps || b.y1 <= qb.y0 + kEps || qb.y1 <= b.y0 + kEps) return false;
  if (!convex(q)) return true;
  const LabelPoint corners[4] = {{b.x0, b.y0}, {b.x1, b.y0}, {b.x1, b.y1}, {b.x0, b.y1}};
  for (size_t i = 0; i < 4; ++i) {
    const LabelPoint a = q[i], c = q[(i + 1) % 4];
    const float nx = -(c.y - a.y), ny = c.x - a.x;
    const float len = std::sqrt(nx * nx + ny * ny);
    if (len < 1e-6f) continue;
    float qmin = 1e30f, qmax = -1e30f, bmin = 1e30f, bmax = -1e30f;
    for (const LabelPoint& p : q) {
      const float d = (p.x * nx + p.y * ny) / len;
      qmin = std::min(qmin, d);
      qmax = std::max(qmax, d);
    }
    for (const LabelPoint& p : corners) {
      const float d = (p.x * nx + p.y * ny) / len;
      bmin = std::min(bmin, d);
      bmax = std::max(bmax, d);
    }
    if (bmax <= qmin + kEps || qmax <= bmin + kEps) return false;
  }
  return true;
}

LabelLayout layout_labels(const LabelLayoutInput& in, LabelCache* cache) {
  LabelLayout out;
  const size_t n = in.labels.size();
  out.placements.resize(n);
  if (n == 0) {
    if (cache) cache->clear();
    return out;
  }
  const float gap = std::max(0.0f, in.gap);
  const float corner = std::max(gap, in.corner_margin);

  // Cells about four label heights wide: a candidate meets a handful of cells.
  float typical_h = 0;
  for (const LabelRequest& r : in.labels) typical_h = std::max(typical_h, r.height);
  Grid grid(in.bounds, std::max(typical_h * 4.0f, 32.0f));
  std::vector<Item> items;
  items.reserve(n * 2 + in.obstacles.size());
  std::vector<LabelBox> anchor_boxes(n);
  for (size_t i = 0; i < n; ++i) {
    anchor_boxes[i] = quad_box(in.labels[i].anchor);
    grid.add(grown(anchor_boxes[i], corner + gap), static_cast<int>(items.size()));
    items.push_back({Kind::marker, static_cast<int>(i)});
  }
  for (size_t i = 0; i < in.obstacles.size(); ++i) {
    grid.add(grown(quad_box(in.obstacles[i]), gap), static_cast<int>(items.size()));
    items.push_back({Kind::media, static_cast<int>(i)});
  }
  items.reserve(items.size() + n);
  std::vector<int> seen(items.size() + n, -1);
  int stamp = 0;

  auto free_at = [&](const LabelBox& c) {
    if (c.x0 < in.bounds.x0 - kEps || c.y0 < in.bounds.y0 - kEps || c.x1 > in.bounds.x1 + kEps ||
        c.y1 > in.bounds.y1 + kEps) {
      return false;
    }
    const LabelBox probe = grown(c, corner + gap);
    const bool hit = grid.any(probe, seen, ++stamp, [&](int item) {
      const Item& it = items[static_cast<size_t>(item)];
      switch (it.kind) {
        case Kind::marker: {
          const LabelQuad& q = in.labels[static_cast<size_t>(it.index)].anchor;
          if (box_meets_quad(c, q, gap)) return true;
          const LabelBox around = grown(c, corner);
          for (const LabelPoint& p : q)
            if (p.x > around.x0 && p.x < around.x1 && p.y > around.y0 && p.y < around.y1) return true;
          return false;
        }
        case Kind::media:
          return box_meets_quad(c, in.obstacles[static_cast<size_t>(it.index)], gap);
        case Kind::label:
          return grown(c, gap).overlaps(out.placements[static_cast<size_t>(it.index)].box);
      }
      return false;
    });
    return !hit;
  };

  // The last call's positions, by key.
  LabelCache previous;
  if (cache) {
    previous = *cache;
    std::sort(previous.begin(), previous.end(), [](const LabelMemory& a, const LabelMemory& b) { return a.key < b.key; });
    cache->clear();
  }
  auto remembered = [&](uint64_t key) -> const LabelMemory* {
    auto it = std::lower_bound(previous.begin(), previous.end(), key,
                               [](const LabelMemory& m, uint64_t k) { return m.key < k; });
    return it != previous.end() && it->key == key ? &*it : nullptr;
  };

  // First the labels whose last position is still free keep it, in priority order, so a marker that appears
  // does not push the others about; then the rest, in priority order, take the nearest free candidate.
  constexpr int kRings = 6;
  std::vector<char> done(n, 0);
  auto place = [&](size_t i, bool remembered_only) {
    const LabelRequest& r = in.labels[i];
    const LabelBox& a = anchor_boxes[i];
    const float w = r.width, h = r.height;
    if (!(w > 0 && h > 0 && std::isfinite(w) && std::isfinite(h))) return false;
    for (const LabelPoint& q : r.anchor)
      if (!std::isfinite(q.x) || !std::isfinite(q.y)) return false;
    const float cx = (a.x0 + a.x1) * 0.5f, cy = (a.y0 + a.y1) * 0.5f;
    LabelPlacement& p = out.placements[i];
    auto take = [&](const LabelBox& c) {
      if (!free_at(c)) return false;
      p.placed = true;
      p.box = c;
      return true;
    };
    bool found = false;
    if (remembered_only) {
      const LabelMemory* m = remembered(r.key);
      found = m && take({a.x0 + m->dx, a.y0 + m->dy, a.x0 + m->dx + w, a.y0 + m->dy + h});
    }
    // The first ring touches the marker's box as close as its corner marks allow.
    const float step = h + gap;
    for (int k = 0; k < kRings && !found && !remembered_only; ++k) {
      const float d = corner + static_cast<float>(k) * step;
      const float above = a.y0 - d - h, below = a.y1 + d, left = a.x0 - d - w, right = a.x1 + d;
      const LabelBox candidates[8] = {
          {cx - w * 0.5f, above, cx + w * 0.5f, above + h},  {cx - w * 0.5f, below, cx + w * 0.5f, below + h},
          {right, cy - h * 0.5f, right + w, cy + h * 0.5f},  {left, cy - h * 0.5f, left + w, cy + h * 0.5f},
          {right, above, right + w, above + h},              {left, above, left + w, above + h},
          {right, below, right + w, below + h},              {left, below, left + w, below + h},
      };
      for (const LabelBox& c : candidates) {
        if (take(c)) {
          found = true;
          break;
        }
      }
    }
    if (!found) return false;
    grid.add(grown(p.box, gap), static_cast<int>(items.size()));
    items.push_back({Kind::label, static_cast<int>(i)});
    // Away from the marker (beyond the first ring): a leader from the marker's outline to the label.
    const float sep_x = std::max({0.0f, a.x0 - p.box.x1, p.box.x0 - a.x1});
    const float sep_y = std::max({0.0f, a.y0 - p.box.y1, p.box.y0 - a.y1});
    if (std::max(sep_x, sep_y) > corner + 0.5f) {
      const LabelPoint mid{(p.box.x0 + p.box.x1) * 0.5f, (p.box.y0 + p.box.y1) * 0.5f};
      LabelPoint best = r.anchor[0];
      for (size_t e = 0; e < 4; ++e) {
        const LabelPoint q = nearest_on_segment(r.anchor[e], r.anchor[(e + 1) % 4], mid);
        if (e == 0 || dist2(q, mid) < dist2(best, mid)) best = q;
      }
      p.leader = true;
      p.leader_to = best;
      p.leader_from = {std::clamp(best.x, p.box.x0, p.box.x1), std::clamp(best.y, p.box.y0, p.box.y1)};
    }
    return true;
  };
  if (cache && !previous.empty()) {
    for (size_t i = 0; i < n; ++i) done[i] = place(i, true);
  }
  for (size_t i = 0; i < n; ++i) {
    if (!done[i]) done[i] = place(i, false);
  }
  for (size_t i = 0; i < n; ++i) {
    if (!done[i]) {
      ++out.hidden;
      continue;
    }
    ++out.placed;
    const LabelBox& a = anchor_boxes[i];
    if (cache) cache->push_back({in.labels[i].key, out.placements[i].box.x0 - a.x0, out.placements[i].box.y0 - a.y0});
  }
  return out;
}

}  // namespace arwb::ui
