// contours: the outer border of every connected region of the binary image. The image becomes bit masks (BitRows),
// its small regions are taken out and counted, the rest are labelled as runs joined row by row, and each region
// large enough is traced from its top-left pixel.
#include "detect/stages/region_contours.hpp"

#include "detect/kernels/kernels.hpp"

#include <array>
#include <bit>
#include <cstring>

namespace arwb::stages {
namespace {

using kernels::BitRows;

// A buffer kept from call to call grows to n and never shrinks: growing it again, for the next frame after a smaller
// image (coarse_search's), would zero its new part.
template <typename T>
void at_least(std::vector<T>& buffer, size_t n) {
  if (buffer.size() < n) buffer.resize(n);
}

// A row's edge words (kernels::EdgeWords) and where they live: bits and before have words + 1 entries.
struct RowEdges {
  std::vector<uint64_t> bits;
  std::vector<int> before;
  void reserve(int words) {
    at_least(bits, size_t(words) + 1);
    at_least(before, size_t(words) + 1);
  }
  kernels::EdgeWords words() { return {bits.data(), before.data()}; }
};

// The small regions a border of min_perimeter_px leaves out, taken out of `bits`; their number when `count`. The
// specks first, then, of what is left, the regions in 5x5 pixels when a 5x5 box's border (20 pixels) is short and
// they need no count, else in 3x3 (12).
int drop_small_regions(const kernels::Kernels& k, const BitRows& bits, double min_perimeter_px, bool count) {
  if (min_perimeter_px <= 4.0) return 0;
  thread_local std::vector<uint64_t> scratch;
  at_least(scratch, 3 * bits.size());
  const int specks = k.drop_specks(bits, scratch.data(), count);
  if (20.0 < min_perimeter_px && !count) return k.drop_small_regions(bits, 5, false, scratch.data());
  if (12.0 < min_perimeter_px) return specks + k.drop_small_regions(bits, 3, count, scratch.data());
  return specks;
}

// Moore-neighbour tracing of outer borders, several at once. Each border starts at its region's top-left pixel
// (the pixel to its west is background, so the first scan starts there) and goes clockwise on screen; at each
// border pixel the next is the first on pixel of its eight neighbours, scanned clockwise from the background pixel
// examined just before the step (the eight directions E SE S SW W NW N NE, 0 to 7). The trace ends when it is back
// at the start going the same way as at first.
//
// The pixels come from the contours' bit masks (`bits`: on where the region's pixels are, nothing beyond the image),
// a pixel's three rows of three neighbours in three 16-bit loads, and the next direction comes from a table of
// them (kMooreNext): no branch on the neighbours. One border's steps wait on each other (the loads, then the
// table, then the next pixel's loads), so kLanes borders are traced in turn, one step each, and the processor
// overlaps them (tracing one border with a branch per neighbour mispredicted about once a step).
struct BorderTrace {
  cv::Point start;
  std::vector<cv::Point>* out;
};
// The Moore trace's step as a table: for the direction a pixel's scan starts from (0 to 7, E SE S SW W NW N NE,
// clockwise on screen) and its nine pixels (around() below: the row above in bits 0-2, its own row in 3-5, the row
// below in 6-8, each from x - 1), the direction of the first on neighbour clockwise from there (bits 0-2) and where
// the scan at that neighbour starts (bits 3-5): the background pixel examined just before the step, seen from the
// new pixel. kMooreNone when no neighbour is on.
constexpr uint8_t kMooreNone = 0xFF;
constexpr std::array<std::array<uint8_t, 512>, 8> moore_next_table() {
  std::array<std::array<uint8_t, 512>, 8> table{};
  for (int from = 0; from < 8; ++from)
    for (int nine = 0; nine < 512; ++nine) {
      const auto bit = [&](int k) { return (nine >> k) & 1; };
      // E SE S SW W NW N NE
      const int ring[8] = {bit(5), bit(8), bit(7), bit(6), bit(3), bit(0), bit(1), bit(2)};
      uint8_t entry = kMooreNone;
      for (int k = 0; k < 8; ++k) {
        const int d = (from + k) & 7;
        if (ring[d]) {
          entry = uint8_t(d | ((d & 1) ? (d + 5) & 7 : (d + 6) & 7) << 3);
          break;
        }
      }
      table[size_t(from)][size_t(nine)] = entry;
    }
  return table;
}
constexpr auto kMooreNext = moore_next_table();

void trace_outer_borders(const BitRows& bits, int w, int h, const std::vector<BorderTrace>& borders) {
  static constexpr int dx[8] = {1, 1, 0, -1, -1, -1, 0, 1};  // E SE S SW W NW N NE: clockwise on screen
  static constexpr int dy[8] = {0, 1, 1, 1, 0, -1, -1, -1};
  // A pixel is the bit index, from the masks' base (the padding's first word), of the pixel to its west: x - 1 of
  // its row.
  const int64_t row_bits = int64_t(bits.stride()) * 64;
  int64_t step[8];
  for (int k = 0; k < 8; ++k) step[k] = dy[k] * row_bits + dx[k];
  const uint8_t* base = reinterpret_cast<const uint8_t*>(bits.base);
  auto at = [&](cv::Point p) { return (int64_t(p.y) + BitRows::kPad) * row_bits + 64 + p.x - 1; };
  // The nine pixels around `b` as bits: x - 1, x and x + 1 of the row above (bits 0-2), of its own row (3-5) and of
  // the row below (6-8). The rows are a whole number of words apart, so the three share one shift.
  const int64_t row_bytes = row_bits / 8;
  auto around = [&](int64_t b) {
    const uint8_t* at_b = base + (b >> 3);
    const int sh = int(b & 7);
    uint16_t t, m, u;
    std::memcpy(&t, at_b - row_bytes, 2);
    std::memcpy(&m, at_b, 2);
    std::memcpy(&u, at_b + row_bytes, 2);
    return ((unsigned(t) >> sh) & 7u) | ((unsigned(m) >> sh) & 7u) << 3 | ((unsigned(u) >> sh) & 7u) << 6;
  };
  // A point's x and y as one word, x + 2^32 y (cv::Point's layout: x in the low half), moved by one addition: a
  // step is dx + 2^32 dy, and x stays within 0 .. 2^32 - 1, so a step west borrows as it should.
  auto pack = [](int64_t x, int64_t y) { return uint64_t(x + y * (int64_t(1) << 32)); };
  uint64_t move[8];
  for (int k = 0; k < 8; ++k) move[k] = pack(dx[k], dy[k]);
  static_assert(sizeof(cv::Point) == sizeof(uint64_t) && std::endian::native == std::endian::little,
                "a point is x then y in one word, and a mask word's bit k is its byte k / 8's bit k % 8");
  // Each lane writes its border's points into its vector, grown to the reserved length and cut to the points at the
  // end (push_back kept the vector's end in memory, a store and a load a step).
  struct Lane {
    int64_t p = 0, start = 0, second = 0;
    uint64_t xy = 0;
    int from = 0;   // where the next pixel's scan starts
    cv::Point *at = nullptr, *end = nullptr;
    std::vector<cv::Point>* out = nullptr;
  };
  constexpr int kLanes = 4;
  const size_t guard_limit = size_t(4) * size_t(w) * size_t(h) + 8;
  size_t next_border = 0;
  auto finish = [](Lane& lane) { lane.out->resize(size_t(lane.at - lane.out->data())); };
  // Lane takes the next border that is more than one pixel; false when none is left.
  auto begin = [&](Lane& lane) {
    while (next_border < borders.size()) {
      const BorderTrace& b = borders[next_border++];
      b.out->assign(std::max<size_t>(b.out->capacity(), 16), cv::Point());
      b.out->front() = b.start;
      const int64_t s = at(b.start);
      const int e = kMooreNext[4][around(s)];
      if (e == kMooreNone) {   // a single pixel
        b.out->resize(1);
        continue;
      }
      const int d = e & 7;
      lane = {s + step[d], s, s + step[d], pack(b.start.x + dx[d], b.start.y + dy[d]), e >> 3, b.out->data() + 1,
              b.out->data() + b.out->size(), b.out};
      return true;
    }
    return false;
  };
  // A lane out of room: its vector twice as long, or the border cut there (a guard; a border is at most four steps
  // a pixel).
  auto grow = [&](Lane& lane) {
    const size_t n = size_t(lane.at - lane.out->data());
    if (n >= guard_limit) return false;
    lane.out->resize(2 * n);
    lane.at = lane.out->data() + n;
    lane.end = lane.out->data() + lane.out->size();
    return true;
  };
  Lane lanes[kLanes];
  bool busy[kLanes];
  int running = 0;
  for (int l = 0; l < kLanes; ++l) running += busy[l] = begin(lanes[l]);
  while (running > 0) {
#pragma GCC unroll 4
    for (int l = 0; l < kLanes; ++l) {
      if (!busy[l]) continue;
      Lane& a = lanes[l];
      const int e = kMooreNext[a.from][around(a.p)];   // never kMooreNone: the pixel came from an on neighbour
      const int nd = e & 7;
      const int64_t q = a.p + step[nd];
      if ((a.p == a.start && q == a.second) || (a.at == a.end && !grow(a))) {
        finish(a);
        if (!(busy[l] = begin(a))) --running;
        continue;
      }
      std::memcpy(static_cast<void*>(a.at++), &a.xy, sizeof a.xy);
      a.p = q;
      a.xy += move[nd];
      a.from = e >> 3;
    }
  }
}

}  // namespace

std::vector<std::vector<cv::Point>> region_contours(const cv::Mat& binary, bool light, double min_perimeter_px,
                                                    int* region_count, std::vector<SmallRegion>* small, int factor,
                                                    int max_side_px, const std::function<bool(const cv::Rect&)>& keep) {
  factor = std::max(factor, 1);
  min_perimeter_px /= factor;
  CV_Assert(binary.type() == CV_8UC1);
  const int w = binary.cols, h = binary.rows;
  // The runs and boxes of one call, kept per thread from call to call: a noisy frame has tens of thousands of runs,
  // and growing and zeroing fresh buffers that large every frame would cost more than the scan.
  thread_local std::vector<int> ends;   // run i is [ends[2i], ends[2i + 1]) on its row
  thread_local std::vector<int> row_begin;   // row y's runs are from row_begin[y] to row_begin[y + 1]
  thread_local std::vector<int> parent;
  int run_count = 0;   // the runs so far (the buffers only grow: resizing them row by row zeroed each new part)
  // The image as bit masks, 64 pixels a word (one bit a pixel, set where it is on), row by row, with rows of
  // nothing above and below and a word of nothing at each end of a row.
  const int words = (w + 63) / 64;
  const kernels::Kernels& kern = kernels::kernels();
  thread_local std::vector<uint64_t> masks;
  BitRows bits{nullptr, words, h};
  at_least(masks, bits.size());
  bits.base = masks.data();
  bits.clear_padding();
  for (int y = 0; y < h; ++y) {
    const uint8_t* row = binary.ptr<uint8_t>(y);
    uint64_t* out = bits.row(y);
    out[-1] = out[words] = 0;
    kern.row_masks(row, w, words, out, light);
  }
  // Small regions: on a noisy frame nearly all regions are a few pixels, and they would make most of the runs. Those
  // whose box could not hold a border of min_perimeter_px are taken out of the masks and only counted (the region
  // count stays exact), never made runs: the one-pixel ones (specks), then the regions that fit in 5x5 pixels when a
  // 5x5 box's border, 20 pixels, is short and they need no count, else in 3x3 pixels (12). Not when `small` lists the
  // small regions: it keeps them in the regions' order.
  const int dropped = small ? 0 : drop_small_regions(kern, bits, min_perimeter_px, region_count != nullptr);
  int prev_begin = 0;
  thread_local RowEdges above, here;   // the row above's edges and this row's
  above.reserve(words);
  here.reserve(words);
  std::fill_n(above.bits.begin(), words + 1, 0);   // the row above the first: nothing
  std::fill_n(above.before.begin(), words + 1, 0);
  at_least(row_begin, size_t(h) + 1);
  for (int y = 0; y < h; ++y) {
    const int begin = row_begin[size_t(y)] = run_count;
    // A run begins or ends where a bit differs from the one before it: the row's edge bits (RowEdges::find), their
    // pixels written in turn (row_edges), and the runs are their pairs.
    kern.find_edges(bits.row(y), words, here.words());
    at_least(ends, 2 * size_t(begin) + size_t(w) + 1 + 16);   // a row's edges, and 16 more (row_edges' stores)
    const int n = kern.row_edges(here.bits.data(), words + 1, ends.data() + 2 * begin) / 2;
    run_count = begin + n;
    at_least(parent, size_t(run_count));
    kern.join_row(above.words(), prev_begin, ends.data() + 2 * begin, begin, n, parent.data());
    std::swap(above, here);
    prev_begin = begin;
  }
  row_begin[size_t(h)] = run_count;
  // Every run points at its root, in one pass (a run's parent is before it, so already points at its root), and
  // the bounding box of each region gathers at its root: the root is its first run in raster order, so it starts
  // the box and the last run seen ends it. Without a branch on the data (on a noisy frame a fifth of the runs are
  // roots, at no pattern): each run's box starts as its own, and a run widens its root's (a root, its own: no
  // change); the roots are listed as they come.
  struct Box {
    int x0, y0, x1, y1;
  };
  thread_local std::vector<Box> boxes;
  thread_local std::vector<int> roots;
  at_least(boxes, size_t(run_count));
  at_least(roots, size_t(run_count));
  for (int y = 0; y < h; ++y)
    for (int i = row_begin[size_t(y)]; i < row_begin[size_t(y) + 1]; ++i)
      boxes[size_t(i)] = {ends[2 * size_t(i)], y, ends[2 * size_t(i) + 1] - 1, y};
  int root_count = 0;
  for (int y = 0; y < h; ++y) {
    for (int i = row_begin[size_t(y)]; i < row_begin[size_t(y) + 1]; ++i) {
      const int r = parent[size_t(parent[size_t(i)])];
      parent[size_t(i)] = r;
      Box& b = boxes[size_t(r)];
      b.x0 = std::min(b.x0, ends[2 * size_t(i)]);
      b.x1 = std::max(b.x1, ends[2 * size_t(i) + 1] - 1);
      b.y1 = y;
      roots[size_t(root_count)] = i;
      root_count += r == i;
    }
  }
  std::vector<std::vector<cv::Point>> contours;
  thread_local std::vector<BorderTrace> borders;
  borders.clear();
  const int regions = root_count;
  for (int k = 0; k < root_count; ++k) {
    const int i = roots[size_t(k)];
    const Box& b = boxes[size_t(i)];
    const int bw = b.x1 - b.x0 + 1, bh = b.y1 - b.y0 + 1;
    if (2.0 * (bw + bh) < min_perimeter_px) {
      if (small) small->push_back({cv::Rect(b.x0 * factor, b.y0 * factor, bw * factor, bh * factor)});
      continue;
    }
    if (max_side_px > 0 && std::max(bw, bh) * factor > max_side_px) continue;
    if (keep) {
      const cv::Point tl = undecimate(cv::Point(b.x0, b.y0), factor), br = undecimate(cv::Point(b.x1, b.y1), factor);
      if (!keep(cv::Rect(tl, br + cv::Point(1, 1)))) continue;
    }
    contours.emplace_back().reserve(size_t(2 * (bw + bh)));   // a convex border's length: one allocation, mostly
    borders.push_back({cv::Point(ends[2 * size_t(i)], b.y0), nullptr});   // the root's run begins the box
  }
  for (size_t k = 0; k < borders.size(); ++k) borders[k].out = &contours[k];
  trace_outer_borders(bits, w, h, borders);
  if (factor > 1)
    for (auto& contour : contours)
      for (cv::Point& p : contour) p = undecimate(p, factor);
  if (region_count) *region_count = regions + dropped;
  return contours;
}


std::vector<std::vector<cv::Point>> find_contours(const cv::Mat& binary, double min_perimeter_px,
                                                  int* region_count, std::vector<SmallRegion>* small, int factor,
                                                  int max_side_px, const std::function<bool(const cv::Rect&)>& keep) {
  return region_contours(binary, false, min_perimeter_px, region_count, small, factor, max_side_px, keep);
}

}  // namespace arwb::stages
