// Pictures of a frame's trace (see trace_view.hpp). Whole-image views are drawn over one dimmed copy of the
// working frame made once per call; mosaics are grids of fixed-size tiles, one per candidate that reached the
// stage, in trace order. OpenCV drawing and vectorised ops throughout (contours are set pixel by pixel, see
// draw_chain), and buffers are pooled (ViewPool): the worker calls this every frame.
#include "inspect/trace_view.hpp"

#include "capture/pixels.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace arwb {
namespace {

// Colours (BGR).
const cv::Scalar kGreen(60, 220, 60);
const cv::Scalar kRed(40, 40, 255);
const cv::Scalar kCyan(255, 255, 0);
const cv::Scalar kOrange(0, 150, 255);
const cv::Scalar kMagenta(255, 0, 255);
const cv::Scalar kLight(235, 235, 235);
const cv::Scalar kDimBox(90, 90, 90);
const cv::Scalar kThinGrey(150, 150, 150);
const cv::Scalar kLabel(220, 220, 220);
const cv::Scalar kMosaicBg(28, 28, 28);

constexpr double kDimFactor = 0.35;
constexpr int kTile = 64;        // tile side, px
constexpr int kGap = 2;          // between tiles and around the mosaic
constexpr int kLabelH = 11;      // one label line above or below a tile
constexpr double kFontScale = 0.8;
constexpr int kFont = cv::FONT_HERSHEY_PLAIN;

// Buffers for the pictures, kept by the calling thread and handed out again once every other holder has let go
// (refcount back to 1: only the pool). A frame's views are ~9 working-size images; fresh ones each frame cost
// more in page faults (the allocator returns freed megabytes to the system) than all the drawing. A buffer still
// held elsewhere (the UI's current frame, a snapshot) is never written. When full, the free buffer unused the
// longest is resized (mosaics change size from frame to frame; the working-size buffers are used every call).
class ViewPool {
 public:
  void next_call() { ++call_; }

  cv::Mat take(cv::Size size, int type) {
    for (auto& e : entries_)
      if (e.mat.size() == size && e.mat.type() == type && only_here(e.mat)) {
        e.used = call_;
        return e.mat;
      }
    const size_t bytes = size_t(size.area()) * size_t(CV_ELEM_SIZE(type));
    if (entries_.size() < kMaxBuffers && bytes_ + bytes <= kMaxBytes) {
      entries_.push_back({cv::Mat(size, type), call_});
      bytes_ += bytes;
      return entries_.back().mat;
    }
    Entry* lru = nullptr;
    for (auto& e : entries_)
      if (only_here(e.mat) && (!lru || e.used < lru->used)) lru = &e;
    if (!lru || bytes_ - lru->mat.total() * lru->mat.elemSize() + bytes > kMaxBytes) return cv::Mat(size, type);
    bytes_ -= lru->mat.total() * lru->mat.elemSize();
    lru->mat = cv::Mat(size, type);
    lru->used = call_;
    bytes_ += bytes;
    return lru->mat;
  }

 private:
  static constexpr size_t kMaxBuffers = 64;
  static constexpr size_t kMaxBytes = size_t(96) << 20;
  struct Entry {
    cv::Mat mat;
    uint64_t used = 0;
  };
  static bool only_here(cv::Mat& m) {
    // The last release elsewhere is an atomic decrement; acquire so its reads of the pixels come before our writes.
    return m.u && std::atomic_ref<int>(m.u->refcount).load(std::memory_order_acquire) == 1;
  }
  std::vector<Entry> entries_;
  size_t bytes_ = 0;
  uint64_t call_ = 0;
};

ViewPool& pool() {
  thread_local ViewPool p;
  return p;
}

// Working pixels from input pixels (the markers' corners are in input pixels; pixel centres at integers).
cv::Point2f to_work(const cv::Point2f& p, const FrameTrace& t) {
  const double sx = t.scale_x > 0 ? t.scale_x : 1.0, sy = t.scale_y > 0 ? t.scale_y : 1.0;
  return {float((p.x + 0.5) / sx - 0.5), float((p.y + 0.5) / sy - 0.5)};
}

cv::Point rounded(const cv::Point2f& p) { return {cvRound(p.x), cvRound(p.y)}; }

std::array<cv::Point, 4> quad_points(const Quad& q) {
  return {rounded(q[0]), rounded(q[1]), rounded(q[2]), rounded(q[3])};
}

// Any image as 8-bit BGR (scaled as capture scales every picture), in a pooled buffer (shares nothing with the
// input).
cv::Mat to_bgr(const cv::Mat& img) {
  if (img.empty()) return {};
  const cv::Mat src = to_8bit(img);
  cv::Mat out = pool().take(src.size(), CV_8UC3);  // the conversions below write into it (same size and type)
  switch (src.channels()) {
    case 1: cv::cvtColor(src, out, cv::COLOR_GRAY2BGR); break;
    case 4: cv::cvtColor(src, out, cv::COLOR_BGRA2BGR); break;
    case 3: src.copyTo(out); break;
    default: out.setTo(cv::Scalar::all(0)); break;
  }
  return out;
}

// A pooled copy of an image.
cv::Mat copy_of(const cv::Mat& img) {
  cv::Mat out = pool().take(img.size(), img.type());
  img.copyTo(out);
  return out;
}

// A pooled image filled with one colour.
cv::Mat filled(cv::Size size, const cv::Scalar& colour) {
  cv::Mat out = pool().take(size, CV_8UC3);
  out.setTo(colour);
  return out;
}

// A colour as one 8-bit BGR pixel.
cv::Vec3b pixel_of(const cv::Scalar& c) {
  return {cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]), cv::saturate_cast<uchar>(c[2])};
}

// Draws a closed contour 1 px wide. The pipeline's contours keep every border pixel, so consecutive points are
// neighbours: setting the pixels is ~20x faster than cv::polylines, which sets up a line per 1-pixel segment.
// Points further apart (a contour from elsewhere) are joined with cv::line.
void draw_chain(cv::Mat& img, const std::vector<cv::Point>& pts, const cv::Vec3b& colour) {
  const cv::Rect bounds(0, 0, img.cols, img.rows);
  const size_t n = pts.size();
  for (size_t i = 0; i < n; ++i) {
    const cv::Point& p = pts[i];
    if (bounds.contains(p)) img.at<cv::Vec3b>(p) = colour;
    const cv::Point& q = pts[i + 1 < n ? i + 1 : 0];
    if (std::abs(q.x - p.x) > 1 || std::abs(q.y - p.y) > 1)
      cv::line(img, p, q, cv::Scalar(colour[0], colour[1], colour[2]), 1, cv::LINE_8);
  }
}

// Batches the outlines of one colour: contours as pixel chains, quads in one cv::polylines call.
class PolyBatch {
 public:
  void add(const std::vector<cv::Point>& pts) {
    if (!pts.empty()) chains_.push_back(&pts);
  }
  void add_quad(const Quad& q) { quads_.push_back(quad_points(q)); }
  // Chains wider than a pixel go to cv::polylines too (a projector's pictures only).
  void draw(cv::Mat& img, const cv::Scalar& colour, int thickness = 1) {
    std::vector<const cv::Point*> ptrs;
    std::vector<int> counts;
    if (thickness <= 1) {
      for (const auto* chain : chains_) draw_chain(img, *chain, pixel_of(colour));
    } else {
      for (const auto* chain : chains_) {
        ptrs.push_back(chain->data());
        counts.push_back(int(chain->size()));
      }
    }
    for (const auto& q : quads_) {
      ptrs.push_back(q.data());
      counts.push_back(4);
    }
    if (!ptrs.empty())
      cv::polylines(img, ptrs.data(), counts.data(), int(ptrs.size()), true, colour, thickness, cv::LINE_8);
  }

 private:
  std::vector<const std::vector<cv::Point>*> chains_;
  std::vector<std::array<cv::Point, 4>> quads_;
};

// How this call draws (the style) and where its text goes: drawn into the picture, listed for the viewer, or
// both.
struct Pen {
  StageViewStyle style;
  std::vector<StageLabel>* labels = nullptr;   // the current stage's, or null

  int line() const { return std::max(1, style.line); }
  int strip() const { return style.text ? kLabelH : 2 * kLabelH; }
  // `text` centred in `box` (a label strip), or on `at` when the box is empty, with a dark outline when `outline`.
  void text(cv::Mat& img, const std::string& text, cv::Rect box, cv::Point2f at = {}, double scale = kFontScale,
            int font = kFont, bool outline = false, const cv::Scalar& colour = kLabel) const {
    if (text.empty()) return;
    const bool strip = box.area() > 0;
    const cv::Point2f centre =
        strip ? cv::Point2f(float(box.x) + float(box.width) * 0.5f - 0.5f, float(box.y) + float(box.height) * 0.5f - 0.5f)
              : at;
    if (labels)
      labels->push_back({centre, strip ? float(box.height) : 0.0f, text, pixel_of(colour)});
    if (!style.text) return;
    int base = 0;
    const cv::Size ts = cv::getTextSize(text, font, scale, 1, &base);
    const cv::Point org = strip ? cv::Point(box.x + std::max(0, (box.width - ts.width) / 2), box.y + (box.height + ts.height) / 2)
                                : cv::Point(cvRound(at.x) - ts.width / 2, cvRound(at.y) + ts.height / 2);
    if (outline) cv::putText(img, text, org, font, scale, cv::Scalar::all(0), 3, cv::LINE_8);
    cv::putText(img, text, org, font, scale, colour, 1, cv::LINE_8);
  }
};

const std::vector<cv::Point>* contour_of(const CandidateRecord& c, const FrameTrace& t) {
  if (c.contour < 0 || c.contour >= int(t.contours.size())) return nullptr;
  return &t.contours[size_t(c.contour)];
}

// [SECTION] whole-image views

cv::Mat view_contours(const FrameTrace& t, cv::Size size, const Pen& pen) {
  cv::Mat img = filled(size, cv::Scalar::all(0));
  for (const auto& c : t.candidates)
    if (c.contour < 0 && c.fate.stage == Stage::size_filter && c.bbox.area() > 0)
      cv::rectangle(img, c.bbox, kDimBox, pen.line(), cv::LINE_8);
  PolyBatch all;
  for (const auto& c : t.contours) all.add(c);
  all.draw(img, kLight, pen.line());
  return img;
}

// search_regions: the frame, dimmed outside the regions searched, each region outlined (green: around known
// markers; the whole frame is left as it is).
cv::Mat view_search_regions(const FrameTrace& t, const cv::Mat& base, const cv::Mat& dim, const Pen& pen) {
  if (t.search.whole || base.empty()) return base.empty() ? copy_of(dim) : to_bgr(base);
  cv::Mat img = copy_of(dim);
  const cv::Mat bright = base.type() == CV_8UC3 ? base : to_bgr(base);
  const cv::Rect frame(0, 0, img.cols, img.rows);
  for (const cv::Rect& r : t.search.regions) {
    const cv::Rect in = r & frame;
    if (in.empty()) continue;
    bright(in).copyTo(img(in));
    cv::rectangle(img, in, kGreen, pen.line(), cv::LINE_8);
  }
  return img;
}

cv::Mat view_size_filter(const FrameTrace& t, const cv::Mat& dim, const Pen& pen) {
  cv::Mat img = copy_of(dim);
  PolyBatch passed, rejected;
  for (const auto& c : t.candidates) {
    const auto* pts = contour_of(c, t);
    if (!pts) continue;
    (c.fate.stage == Stage::size_filter ? rejected : passed).add(*pts);
  }
  rejected.draw(img, kRed, pen.line());
  passed.draw(img, kGreen, pen.line());
  return img;
}

cv::Mat view_quad_fit(const FrameTrace& t, const cv::Mat& dim, const Pen& pen) {
  cv::Mat img = copy_of(dim);
  PolyBatch quads, rejected;
  for (const auto& c : t.candidates) {
    if (c.has_quad) quads.add_quad(c.quad);
    else if (c.fate.stage == Stage::quad_fit)
      if (const auto* pts = contour_of(c, t)) rejected.add(*pts);
  }
  rejected.draw(img, kOrange, pen.line());
  quads.draw(img, kCyan, pen.line());
  return img;
}

cv::Mat view_nested_filter(const FrameTrace& t, const cv::Mat& dim, const Pen& pen) {
  cv::Mat img = copy_of(dim);
  PolyBatch kept, merged;
  for (const auto& c : t.candidates) {
    if (!c.has_quad) continue;
    (c.fate.stage == Stage::nested_filter ? merged : kept).add_quad(c.quad);
  }
  kept.draw(img, kCyan, pen.line());
  merged.draw(img, kMagenta, pen.line());
  return img;
}

cv::Mat view_corner_refinement(const FrameTrace& t, const cv::Mat& dim, const Pen& pen) {
  cv::Mat img = copy_of(dim);
  PolyBatch quads;
  for (const auto& c : t.candidates)
    if (c.has_quad) quads.add_quad(c.quad);
  const int k = pen.line();
  quads.draw(img, kThinGrey, k);
  for (const auto& m : t.markers)
    for (const auto& p : m.corners) {
      const cv::Point c = rounded(to_work(p, t));
      cv::drawMarker(img, c, kGreen, cv::MARKER_CROSS, 6 * k + 1, k, cv::LINE_8);
      cv::circle(img, c, 3 * k, kGreen, k, cv::LINE_8);
    }
  return img;
}

cv::Mat view_duplicates(const FrameTrace& t, const cv::Mat& dim, const Pen& pen) {
  cv::Mat img = copy_of(dim);
  const int k = pen.line();
  PolyBatch dropped;
  for (const auto& c : t.candidates)
    if (c.has_quad && c.fate.stage == Stage::duplicates) dropped.add_quad(c.quad);
  dropped.draw(img, kMagenta, k);
  for (const auto& m : t.markers) {
    Quad w;
    for (size_t j = 0; j < 4; ++j) w[j] = to_work(m.corners[j], t);
    const cv::Point2f centre = quad_centre(w);
    const auto pts = quad_points(w);
    // Corner 0: a filled square, as OpenCV's drawDetectedMarkers marks it, under the outline.
    cv::rectangle(img, pts[0] - cv::Point(3 * k, 3 * k), pts[0] + cv::Point(3 * k, 3 * k), kRed, cv::FILLED);
    const cv::Point* ptr = pts.data();
    const int n = 4;
    cv::polylines(img, &ptr, &n, 1, true, kGreen, 2 * k, cv::LINE_8);
    pen.text(img, std::to_string(m.id), {}, centre, 0.5, cv::FONT_HERSHEY_SIMPLEX, true, kGreen);
  }
  return img;
}

// [SECTION] mosaics

// One tile: its content is drawn into a kTile x kTile BGR region; labels above and below; an optional frame.
struct TileSpec {
  int candidate = -1;
  std::string below;                  // extra label under the tile ("" for none)
  cv::Scalar frame{-1, -1, -1, -1};   // frame colour, or val[0] < 0 for none
};
using DrawTile = std::function<void(int candidate, cv::Mat& roi)>;

cv::Mat empty_mosaic(const Pen& pen) {
  cv::Mat img = filled({96, 48}, kMosaicBg);
  pen.text(img, "none", {0, 0, img.cols, img.rows}, {}, 1.2);
  return img;
}

cv::Mat mosaic(const std::vector<TileSpec>& tiles, const DrawTile& draw, const Pen& pen) {
  if (tiles.empty()) return empty_mosaic(pen);
  bool any_below = false;
  for (const auto& s : tiles) any_below = any_below || !s.below.empty();
  const int strip = pen.strip();
  const int cell_w = kTile, cell_h = strip + kTile + (any_below ? strip : 0);
  const int n = int(tiles.size());
  // Columns for a roughly 4:3 mosaic: cols * cell_w / (rows * cell_h) ~ 4/3 with rows ~ n / cols.
  int cols = int(std::lround(std::sqrt(4.0 / 3.0 * n * cell_h / double(cell_w))));
  cols = std::clamp(cols, 1, n);
  const int rows = (n + cols - 1) / cols;
  cv::Mat img = filled({cols * (cell_w + kGap) + kGap, rows * (cell_h + kGap) + kGap}, kMosaicBg);
  for (int i = 0; i < n; ++i) {
    const TileSpec& s = tiles[size_t(i)];
    const int x = kGap + (i % cols) * (cell_w + kGap), y = kGap + (i / cols) * (cell_h + kGap);
    std::string label = "#";
    label += std::to_string(s.candidate);  // not "#" + string: GCC 12 warns falsely (-Wrestrict) on that
    pen.text(img, label, {x, y, cell_w, strip});
    const cv::Rect tile_rect(x, y + strip, kTile, kTile);
    cv::Mat roi = img(tile_rect);
    draw(s.candidate, roi);
    if (s.frame[0] >= 0) {  // 2 px inside the tile
      roi.rowRange(0, 2).setTo(s.frame);
      roi.rowRange(kTile - 2, kTile).setTo(s.frame);
      roi.colRange(0, 2).setTo(s.frame);
      roi.colRange(kTile - 2, kTile).setTo(s.frame);
    }
    if (any_below) pen.text(img, s.below, {x, y + strip + kTile, cell_w, strip});
  }
  return img;
}

// First pixel of cell i of a grid of `cells` cells across the tile: the pixels x that nearest-neighbour scaling
// maps to cell i are those with floor(x * cells / kTile) == i.
int cell_edge(int i, int cells) { return (i * kTile + cells - 1) / cells; }

// Grey kTile x kTile pictures of each candidate, made on first use and shared by the mosaics of one call.
class TileCache {
 public:
  explicit TileCache(const FrameTrace& t) : t_(t), warps_(t.candidates.size()), bits_(t.candidates.size()) {}

  // The frontal view, nearest-neighbour scaled.
  const cv::Mat& warp(int i) {
    cv::Mat& m = warps_[size_t(i)];
    const cv::Mat& w = t_.candidates[size_t(i)].warp;
    if (m.empty() && !w.empty()) cv::resize(w, m, {kTile, kTile}, 0, 0, cv::INTER_NEAREST);
    return m;
  }
  // The bit grid: black and white cells with thin grey lines between them.
  const cv::Mat& bits(int i) {
    cv::Mat& m = bits_[size_t(i)];
    const cv::Mat& b = t_.candidates[size_t(i)].bits;
    if (m.empty() && !b.empty() && b.rows == b.cols) {
      cv::Mat b255;
      b.convertTo(b255, CV_8U, 255.0);
      cv::resize(b255, m, {kTile, kTile}, 0, 0, cv::INTER_NEAREST);
      for (int k = 1; k < b.rows; ++k) {
        const int e = cell_edge(k, b.rows);
        m.row(e).setTo(128);
        m.col(e).setTo(128);
      }
    }
    return m;
  }

 private:
  const FrameTrace& t_;
  std::vector<cv::Mat> warps_, bits_;
};

// A grey tile into the BGR mosaic (roi has the right size and type: written in place).
void grey_into(const cv::Mat& grey, cv::Mat& roi) {
  if (!grey.empty()) cv::cvtColor(grey, roi, cv::COLOR_GRAY2BGR);
}

cv::Rect cell_rect(int r, int c, int cells) {
  const int x0 = cell_edge(c, cells), x1 = cell_edge(c + 1, cells);
  const int y0 = cell_edge(r, cells), y1 = cell_edge(r + 1, cells);
  return {x0, y0, x1 - x0, y1 - y0};
}

// A candidate passed stage s when its fate is a later stage or acceptance (the last value of Stage).
bool passed(const CandidateRecord& c, Stage s) { return static_cast<int>(c.fate.stage) > static_cast<int>(s); }

// A red frame inside every border cell of a bit grid that reads white (a border cell should be black).
void frame_white_border_cells(const cv::Mat& b, cv::Mat& roi) {
  if (b.empty() || b.rows != b.cols) return;
  const int n = b.rows;
  for (int r = 0; r < n; ++r)
    for (int col = 0; col < n; ++col) {
      if (r != 0 && r != n - 1 && col != 0 && col != n - 1) continue;
      if (b.at<uint8_t>(r, col) == 0) continue;  // black border cell: as it should be
      cv::Rect cr = cell_rect(r, col, n);
      cr.x += 1, cr.y += 1, cr.width -= 2, cr.height -= 2;
      if (cr.width > 0 && cr.height > 0) cv::rectangle(roi, cr, kRed, 1, cv::LINE_8);
    }
}

// The identification tile: the nearest id and its distance below, red where it failed, green where it passed.
void identification_tile(const CandidateRecord& c, TileSpec& s) {
  const DictMatch m = c.nearest();
  s.below = m.id >= 0 ? std::to_string(m.id) + " d" + std::to_string(m.hamming) : "-";
  s.frame = c.fate.stage == Stage::identification ? kRed
            : passed(c, Stage::identification)   ? kGreen
                                                 : cv::Scalar(-1, -1, -1, -1);
}

}  // namespace

bool stage_view_is_mosaic(Stage s) {
  switch (s) {
    case Stage::perspective_removal:
    case Stage::otsu:
    case Stage::bit_grid:
    case Stage::border_check:
    case Stage::identification: return true;
    default: return false;
  }
}

void thumbnail(const cv::Mat& in, cv::Mat& out, cv::Size fit) {
  if (in.empty() || fit.width < 1 || fit.height < 1) {
    out.release();
    return;
  }
  const int k = std::max(1, int(std::ceil(std::max(double(in.cols) / fit.width, double(in.rows) / fit.height))));
  if (k == 1) {
    in.copyTo(out);
    return;
  }
  const cv::Size size(in.cols / k, in.rows / k);
  if (size.width < 1 || size.height < 1) {   // a sliver thinner than k: the general area resize, to 1 pixel across
    cv::resize(in, out, cv::Size(std::max(1, size.width), std::max(1, size.height)), 0, 0, cv::INTER_AREA);
    return;
  }
  cv::resize(in(cv::Rect(0, 0, size.width * k, size.height * k)), out, size, 0, 0, cv::INTER_AREA);
}

void render_stage_views(const cv::Mat& working_bgr, const FrameTrace& trace, std::array<cv::Mat, kStageCount>& out,
                        const StageViewStyle& style, StageLabels* labels) {
  for (auto& m : out) m = cv::Mat();  // before taking buffers: the caller's old pictures may be reused
  if (labels)
    for (auto& l : *labels) l.clear();
  if (trace.level != TraceLevel::full || trace.stages.empty()) return;
  pool().next_call();

  // The working size: the trace's, else the image's.
  const StageRecord* acq = trace.stage(Stage::acquisition);
  cv::Size size(trace.work_width, trace.work_height);
  if (size.width <= 0 || size.height <= 0) size = acq && !acq->image.empty() ? acq->image.size() : working_bgr.size();

  // The frame the whole-image views draw over, at the working size: the given image, else acquisition's grey.
  cv::Mat base;
  if (!working_bgr.empty() && working_bgr.size() == size) {
    base = working_bgr;
  } else if (acq && acq->image.size() == size) {
    base = acq->image;
  } else if (!working_bgr.empty() && size.area() > 0) {
    cv::resize(working_bgr, base, size, 0, 0, cv::INTER_AREA);
  }
  cv::Mat dim;  // made on first use, shared by every whole-image view
  auto dimmed = [&]() -> const cv::Mat& {
    if (dim.empty()) {
      if (base.empty()) {
        dim = filled({std::max(size.width, 1), std::max(size.height, 1)}, cv::Scalar::all(0));
      } else {
        // Pooled too: returned to the pool when this call ends (convertTo writes into it, same size and type).
        const cv::Mat bgr = base.type() == CV_8UC3 ? base : to_bgr(base);
        dim = pool().take(bgr.size(), CV_8UC3);
        bgr.convertTo(dim, CV_8U, kDimFactor);
      }
    }
    return dim;
  };

  // Which candidates reached each per-candidate stage, in trace order.
  auto tiles_where = [&](auto pred, auto spec) {
    std::vector<TileSpec> tiles;
    for (int i = 0; i < int(trace.candidates.size()); ++i) {
      const CandidateRecord& c = trace.candidates[size_t(i)];
      if (!pred(c)) continue;
      TileSpec s;
      s.candidate = i;
      spec(c, s);
      tiles.push_back(std::move(s));
    }
    return tiles;
  };
  auto has_warp = [](const CandidateRecord& c) { return !c.warp.empty(); };
  auto has_bits = [](const CandidateRecord& c) { return !c.bits.empty(); };
  auto no_spec = [](const CandidateRecord&, TileSpec&) {};
  TileCache cache(trace);
  auto draw_warp = [&](int i, cv::Mat& roi) { grey_into(cache.warp(i), roi); };
  auto draw_bits = [&](int i, cv::Mat& roi) { grey_into(cache.bits(i), roi); };

  for (const StageRecord& rec : trace.stages) {
    const int si = static_cast<int>(rec.stage);
    if (si < 0 || si >= kStageCount) continue;
    cv::Mat& dst = out[size_t(si)];
    const Pen pen{style, labels ? &(*labels)[size_t(si)] : nullptr};
    switch (rec.stage) {
      case Stage::coarse_search:
      case Stage::fine_search:
        if (rec.image.empty()) {   // off, not coarser, not decimated or no region: none searched
          dst = copy_of(dimmed());
          break;
        }
        [[fallthrough]];
      case Stage::acquisition:
      case Stage::decimation:
      case Stage::adaptive_threshold:
        dst = to_bgr(rec.image.empty() && rec.stage != Stage::adaptive_threshold ? base : rec.image);
        // The search's pictures are the decimated image's size: stretched, their blocks lie over the frame's
        // pixels, so the views compare pixel for pixel.
        if (!dst.empty() && dst.size() != size && size.area() > 0) {
          cv::Mat big = pool().take(size, CV_8UC3);
          cv::resize(dst, big, size, 0, 0, cv::INTER_NEAREST);
          dst = big;
        }
        break;
      case Stage::search_regions:
        dst = view_search_regions(trace, base, dimmed(), pen);
        break;
      case Stage::contours:
        dst = view_contours(trace, size, pen);
        break;
      case Stage::size_filter:
        dst = view_size_filter(trace, dimmed(), pen);
        break;
      case Stage::quad_fit:
        dst = view_quad_fit(trace, dimmed(), pen);
        break;
      case Stage::nested_filter:
        dst = view_nested_filter(trace, dimmed(), pen);
        break;
      case Stage::perspective_removal:
        dst = mosaic(tiles_where(has_warp, no_spec), draw_warp, pen);
        break;
      case Stage::otsu:
        dst = mosaic(tiles_where(has_warp,
                                 [](const CandidateRecord& c, TileSpec& s) {
                                   if (c.fate.stage == Stage::otsu) s.frame = kRed;  // too uniform to threshold
                                 }),
                     [&](int i, cv::Mat& roi) {
                       // Thresholding commutes with nearest-neighbour scaling: threshold the scaled tile.
                       const cv::Mat& w = cache.warp(i);
                       if (w.empty()) return;
                       cv::Mat bin;
                       const int thr = std::max(trace.candidates[size_t(i)].otsu_threshold, 0);
                       cv::threshold(w, bin, thr, 255, cv::THRESH_BINARY);
                       grey_into(bin, roi);
                     },
                     pen);
        break;
      case Stage::bit_grid:
        dst = mosaic(tiles_where(has_bits, no_spec), draw_bits, pen);
        break;
      case Stage::border_check:
        dst = mosaic(tiles_where(has_bits,
                                 [](const CandidateRecord& c, TileSpec& s) {
                                   s.frame = c.fate.stage == Stage::border_check ? kRed : kGreen;
                                 }),
                     [&](int i, cv::Mat& roi) {
                       draw_bits(i, roi);
                       frame_white_border_cells(trace.candidates[size_t(i)].bits, roi);
                     },
                     pen);
        break;
      case Stage::identification:
        dst = mosaic(tiles_where(
                         [](const CandidateRecord& c) {
                           return !c.bits.empty() && c.fate.stage != Stage::otsu &&
                                  c.fate.stage != Stage::border_check;
                         },
                         identification_tile),
                     draw_bits, pen);
        break;
      case Stage::corner_refinement:
        dst = view_corner_refinement(trace, dimmed(), pen);
        break;
      case Stage::duplicates:
        dst = view_duplicates(trace, dimmed(), pen);
        break;
      case Stage::accepted:
        break;
    }
  }
}

std::string stage_view_caption(const FrameTrace& t, Stage s) {
  if (s != Stage::decimation && s != Stage::adaptive_threshold) return {};
  const SearchRecord& r = t.search;
  const int f = std::max(1, r.factor);
  const auto size = [](int w, int h) { return std::to_string(w) + "x" + std::to_string(h); };
  // The size searched, for the whole frame (regions are each their own size).
  const std::string searched = r.whole ? " (" + size(t.work_width / f, t.work_height / f) + ")" : "";
  std::string c = f > 1 ? "searched at 1/" + std::to_string(f) + searched + ", each pixel the mean of a " +
                              std::to_string(f) + "x" + std::to_string(f) + " block, stretched over the frame"
                        : "decimation factor 1: the search ran on the grey image itself" + searched;
  if (!r.whole) {
    const size_t n = r.regions.size();
    c += n == 1 ? "; only the region around the markers of the frame before, the rest black"
                : "; only the " + std::to_string(n) + " regions around the markers of the frame before, the rest black";
  }
  return c;
}

}  // namespace arwb
