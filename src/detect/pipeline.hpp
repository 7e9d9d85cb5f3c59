// The detection pipeline's stages as functions, each readable and testable on its own (the paper, section 4.2.2),
// one file each under stages/, named as the stage is in the trace (the reading stages share reading.cpp). The
// detector (detector.cpp) chains them and fills the trace; tests call them directly on crafted images. Their vector
// code is in kernels/, reached through one table (kernels/kernels.hpp).
#pragma once

#include "capture/acquisition.hpp"
#include "detect/dictionary.hpp"
#include "detect/kernels/types.hpp"
#include "detect/params.hpp"
#include "detect/trace.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <functional>
#include <optional>
#include <span>
#include <vector>

namespace arwb::stages {

// acquisition: the frame resized as acquisition says (capture/acquisition.hpp) and made grey. scale_x/scale_y: input
// pixels per output pixel. `acquired`, when given, receives the resized frame in its own channels (a copy when
// nothing was resized), for callers that show it; the grey is then made from it.
cv::Mat acquire(const cv::Mat& input, const AcquisitionSettings& a, double* scale_x, double* scale_y,
                cv::Mat* acquired = nullptr);

// The working frame's grey image, converted from a colour frame only where the stages look: a video frame searched
// around its known markers needs grey pixels only in those regions and around its candidates. A half-size search of
// the whole frame converts it all and takes its 2x2 block means as it goes (convert_all_and_halve), while the rows
// are in the cache. A grey frame is used as it is; another depth, or RGB, converted at once.
class GreyOnDemand {
 public:
  // 1, 3 (BGR, or RGB when rgb) or 4 (BGRA, or RGBA) channels.
  explicit GreyOnDemand(const cv::Mat& frame = {}, bool rgb = false);
  // The grey image; of a colour frame only the tiles need() was asked for hold grey levels yet.
  const cv::Mat& image() const { return grey_; }
  // The colour frame the grey levels come from, or empty when the frame was grey.
  const cv::Mat& colour() const { return colour_; }
  // Converts the 32x32 tiles that r (clipped to the image) touches and that are not converted yet.
  void need(const cv::Rect& r);
  void need_all() { need(cv::Rect(0, 0, grey_.cols, grey_.rows)); }
  // need_all, returning the grey image's 2x2 block means (decimate(image(), 2)), made as it converts.
  cv::Mat convert_all_and_halve();
  // The share of the image converted so far (1 for a grey frame).
  double converted() const {
    return done_.empty() ? 1.0 : double(std::count(done_.begin(), done_.end(), 1)) / double(done_.size());
  }
  static constexpr int kTile = 32;

 private:
  cv::Mat colour_, grey_;
  bool rgb_ = false;
  int tiles_x_ = 0;
  std::vector<uint8_t> done_;   // per tile, row by row
};

// acquisition as above, the grey conversion left to the stages that look (GreyOnDemand). Resizing a frame nobody
// shows resizes its grey image, converted here: a third of the work.
GreyOnDemand acquire_on_demand(const cv::Mat& input, const AcquisitionSettings& a, double* scale_x, double* scale_y,
                               cv::Mat* acquired = nullptr);

// search_regions: where the search (decimation .. quad_fit) looks on this frame. Without known markers, the whole
// frame at decimation_used. With the markers earlier frames found (`known`, working pixels), a region around each:
// its bounding box widened by region_margin_rate of its side each way, overlapping regions merged, each a whole
// number of decimated pixels; all searched at the decimation that keeps the smallest known marker at least
// region_min_side_px a side (1 to 4). Regions that would cover most of the frame become the frame.
struct SearchPlan {
  bool whole = true;
  std::vector<cv::Rect> regions;
  int factor = 1;
};
SearchPlan plan_search(cv::Size grey, const std::vector<Quad>& known, const DetectorParams& p);
// A contour found in `region` that reaches the region's edge where it is not the image's: its shape is cut there.
bool cut_by_region(const cv::Rect& contour_box, const cv::Rect& region, cv::Size grey, int factor);

// Overlapping rectangles become their bounding box, until none overlap (sorted top to bottom, left to right).
void merge_overlapping(std::vector<cv::Rect>& rects);

// decimation: the search image, the grey image shrunk `factor` times (each pixel the mean of a factor x factor
// block); the grey image itself when factor is 1. The factor used for a frame is decimation_factor (0: 2 when the
// frame's shorter side is at least 720 px, else 1), lowered so that the search image keeps at least 64 pixels a side.
int decimation_used(cv::Size grey, const DetectorParams& p);
cv::Mat decimate(const cv::Mat& grey, int factor);
// The search image of `region` (the grey image's pixels) at `factor`: decimate over the region's grey pixels
// (converted here; of a whole colour frame at 2, all of it in one pass with the decimation).
cv::Mat search_image(GreyOnDemand& grey, const cv::Rect& region, int factor);
// A point of the search image in the grey image's pixels (the centre of its block, rounded down), and back.
inline cv::Point undecimate(cv::Point p, int factor) {
  return factor == 1 ? p : cv::Point(p.x * factor + (factor - 1) / 2, p.y * factor + (factor - 1) / 2);
}

// adaptive_threshold: 255 where a pixel is darker than its window mean by more than threshold_offset. Windows of 9
// pixels and more take their mean over 2x2 block means (half the window), brought back to each pixel bilinearly;
// `block_means`, when given, receives those (the image halved, its whole 2x2 blocks), or is left empty.
cv::Mat adaptive_threshold(const cv::Mat& grey, const DetectorParams& p, cv::Mat* block_means = nullptr);

// contours: the outer border of every connected region (8-connected) of the binary image, all points kept,
// clockwise on screen from the region's top-left pixel. A marker's black frame is a region of its own (the quiet
// zone separates it), so its outer border is the marker's edge; hole borders are not needed.
// Regions whose bounding box is too small to hold a border of min_perimeter_px (a convex border is never longer
// than the box's perimeter) are not traced: they are most regions of a frame. They are returned in `small`.
// With `factor` > 1 the binary image is the decimated search image: min_perimeter_px is in the grey image's pixels,
// and the contours and boxes returned are mapped to the grey image (undecimate), so every later stage, the trace
// and the views work in one set of pixels.
struct SmallRegion {
  cv::Rect bbox;
};
// Regions whose box is longer than max_side_px (the grey image's pixels; 0: no limit) are counted, not traced; so
// are those `keep`, when given, says false of (asked with the region's box in the grey image's pixels, from the
// binary's origin).
std::vector<std::vector<cv::Point>> find_contours(const cv::Mat& binary, double min_perimeter_px,
                                                  int* region_count = nullptr,
                                                  std::vector<SmallRegion>* small = nullptr, int factor = 1,
                                                  int max_side_px = 0,
                                                  const std::function<bool(const cv::Rect&)>& keep = {});
// A contour's length in the grey image's pixels: its points, each a step of `factor` pixels.
inline double contour_length(const std::vector<cv::Point>& contour, int factor) {
  return double(contour.size()) * factor;
}

// coarse_search: the whole frame once more, `coarse_factor` times coarser than the first search, for large markers.
// It shrinks the first search's image (`search`), or at an even factor its 2x2 block means (`block_means`, when the
// threshold made them: a quarter of its pixels). Its contours, in the grey image's pixels (`factor`: the coarse
// search's decimation of the grey image), and its binary image in `binary`.
std::vector<std::vector<cv::Point>> coarse_search(const cv::Mat& search, const cv::Mat& block_means, int factor,
                                                  const DetectorParams& p, cv::Mat* binary);

// corner_refinement's profiles: profile.size() samples from `from` in steps of `step`, bilinear, as grey levels times
// 65536. Inside the image, positions step in 1/65536 pixel and each sample is the fixed-point blend of its four
// pixels with weights in 1/256 (bilinear_q8); where the line leaves the image, clamped floating point.
void sample_line(const cv::Mat& grey, cv::Point2d from, cv::Point2d step, std::span<int> profile);

// quad_fit's search, in the polygon approximation: the first of the points c[0, n) farthest from p0, or when
// `from_line` from the line through p0 along `dir` (as |cross product|: the distance times dir's length), in
// integers; at -1 when n is 0.
using Farthest = kernels::Farthest;
Farthest farthest_point(const cv::Point* c, int n, cv::Point p0, cv::Point dir, bool from_line);

// size_filter: nullopt when the contour may go on, else the rejection. Most contours of a frame stop here, so the
// message is only written when `explain` asks for it.
std::optional<Rejection> size_filter(const std::vector<cv::Point>& contour, cv::Size image, const DetectorParams& p,
                                     bool explain = true, int factor = 1);

// quad_fit: a convex quad, clockwise on screen, or the rejection (its message only when `explain` asks: most
// contours of a frame stop here too). With cut_thin_lines, a shape that is a quad joined to thin lines (a line that
// crosses a marker's quiet zone into its border joins the two, and whatever else it touches, in one shape) gives the
// quad, its sides fitted without the lines' points, and `cut` (when given) true.
std::optional<Rejection> fit_quad(const std::vector<cv::Point>& contour, cv::Size image, const DetectorParams& p,
                                  Quad* quad, int factor = 1, bool explain = true, bool* cut = nullptr);
// quad_fit's split_thin_lines, for a contour (found at `factor`) that fit_quad refused for its corners: the shape
// split where its outline runs along both sides of a line at most split_thin_lines_px wide. A marker that lines
// join to other shapes, which cut_thin_lines finds no four sides in (they are lost among the outline's many
// corners), comes out as its own outline, with a gap a line's width where each line met it. The outline's points
// within that width of a point many steps away along it, for 3 widths or more (shorter: a pinch where two shapes
// touch at a corner), are the lines'; the arcs between them are chained, each to the one that starts nearest where
// it ends, and each closed chain is a part, in the grey image's pixels as the contour's. None when the shape has no
// line, or is not a square with lines (its perimeter under 6 roots of its area; a square's is 4), or is mostly
// lines (twice its area over its perimeter under 1.6 split_thin_lines_px).
std::vector<std::vector<cv::Point>> split_thin_lines(const std::vector<cv::Point>& contour, int factor,
                                                     const DetectorParams& p);

// fine_search's holes: the light insides of the dark regions of a decimated search's binary image (`origin`: where
// it lies in the grey image) that are quads at most fine_max_side_px on their longer side, as boxes in the grey
// image's pixels. A small marker whose quiet zone the decimation closed is part of a larger dark shape that no quad
// fits (or a quad that the small marker bumps by less than polygon_epsilon_rate), but its inside, within the black
// border, is still a quad-shaped hole. Only the dark regions longer than fine_max_side_px are looked into (`dark`:
// their bounding boxes in the grey image's pixels; a smaller shape is searched again whole), each within its box,
// where its holes lie: at 1920x1080 the light regions of the whole image had cost as much as the dark ones.
// `markers`: the quads (grey image's pixels) that read as markers; nothing inside them is a hole, nor a hole whose
// centre is inside one (the quiet zone of a marker on a dark ground).
std::vector<cv::Rect> quad_holes(const cv::Mat& binary, const std::vector<cv::Rect>& dark, cv::Point origin,
                                 cv::Size grey, const DetectorParams& p, int factor,
                                 const std::vector<Quad>& markers = {});

// fine_search: where a decimated search is searched again at full resolution. `shapes`: the boxes (grey image's
// pixels) of its contours that size_filter found too short or quad_fit could not close, of the quads that did not
// read, and of the quad-shaped holes (quad_holes) not inside a marker it read. Those at most
// fine_max_side_px on their longer side and at least a third as wide as long are searched again, with a margin of
// their side and at least the threshold's window each way; overlapping regions are merged.
std::vector<cv::Rect> plan_fine_search(const std::vector<cv::Rect>& shapes, cv::Size grey, const DetectorParams& p);

// nested_filter: for each quad, -1 to keep it or the index of the quad that replaces it (same border, outer kept).
// `factors` (optional, per quad): the decimation it was found at. Of two quads of one border found at different
// factors the finer is kept: a coarse search's blocks can bloat a low-contrast quad past the marker's edge.
std::vector<int> nested_filter(const std::vector<Quad>& quads, const DetectorParams& p,
                               const std::vector<int>* factors = nullptr);

// perspective_removal: how many times warp_cell_px a cell the quad's frontal view has: 1, or for a quad whose
// samples would lie more than warp_max_step_px image pixels apart, the least multiple that brings them within it
// (at most 4, and 16 px a cell). The view's cell centres are the same; only their samples are denser.
int view_scale(const Quad& quad, int cells, const DetectorParams& p);
// perspective_removal: the quad seen from the front, `cells` cells of warp_cell_px x view_scale pixels a side,
// bilinear.
cv::Mat remove_perspective(const cv::Mat& grey, const Quad& quad, int cells, const DetectorParams& p);

// otsu: the threshold that best separates the frontal view's two grey populations; also its histogram and stddev.
struct OtsuResult {
  int threshold = 0;
  double stddev = 0;
  std::array<int, 256> histogram{};
};
OtsuResult otsu(const cv::Mat& warp);

// bit_grid: cells x cells bits (1 white), each the majority of its cell's centre (margins ignored).
cv::Mat sample_bits(const cv::Mat& warp, int cells, int threshold, const DetectorParams& p);

// bit_grid's local thresholds (local_thresholds): a threshold per cell, for a view that a shadow edge or a steep
// gradient crosses, where no one threshold parts black from white. Light multiplies the print's black and white
// alike, so the border is one share of the quiet zone beside it (half a cell outside) all round: at each border cell
// the mid level is the quiet zone times the share half way from the median border share to 1, and the ring of mid
// levels is spread inside by Coons' patch (exact for a gradient and for a shadow edge parallel to a side). Ring cells
// are read against their mid level too, so border_check tests each border cell against the quiet zone beside it.
// ok is false, and nothing read, when the quiet zone leaves the image, the median step from border to quiet zone is
// under otsu_min_stddev, or the mid levels vary by less than a quarter of that step (light even enough for otsu's
// one threshold).
struct LocalRead {
  bool ok = false;
  cv::Mat bits;              // as sample_bits's
  double median_step = 0;    // grey levels from border to quiet zone, the ring's median
  bool stripe = false;       // the inside is one row or one column repeated: what a ramp or edge the patch does not
                             // follow reads as (ARUCO_ORIGINAL 0 and 1023), so no marker
};
LocalRead read_local(const cv::Mat& grey, const Quad& quad, const cv::Mat& warp, int cells, const DetectorParams& p);

// bit_grid's shading planes (local_thresholds): for a view whose bits reach identification and miss, under light
// that varies smoothly. Least-squares planes through the black cells' means (the ring always among them) and the
// white ones', a cell read against the level half way between them; classes and planes again until they agree (at
// most 3 rounds). Empty when the white cells fix no plane or the planes come within otsu_min_stddev of each other.
cv::Mat read_shaded(const cv::Mat& warp, int cells, const cv::Mat& bits, const DetectorParams& p);

// border_check: the number of white cells in the outer ring.
int border_errors(const cv::Mat& bits);

// A bits grid's inside as stripes: rows when every inner row is the same (bands running down the view, from its
// first side to its third), columns when every inner column is (bands across), none otherwise. A bar's or an
// outlined rectangle's inside, uniform along its length, reads so (ARUCO_ORIGINAL 0 and 1023).
enum class Stripes { none, rows, columns };
Stripes inner_stripes(const cv::Mat& bits);

// border_check: a marker's black border has a light quiet zone around it. Along each side, one pair per cell: half
// a cell outside the border and half a cell inside it (pairs off the image do not count). A pair is dark when the
// quiet zone is less than an eighth of the frontal view's black-to-white gap lighter than the border. The darkest
// side's share of dark pairs, and that side (k: from corner k to corner k + 1).
struct QuietZone {
  double dark_share = 0;
  int side = 0;
};
QuietZone quiet_zone(const cv::Mat& grey, const Quad& quad, int cells, const OtsuResult& otsu);

// identification: the inner bits as a packed code (see Dictionary).
uint64_t inner_code(const cv::Mat& bits);
// The largest Hamming distance accepted for a dictionary under these parameters.
int correction_budget(const Dictionary& dict, const DetectorParams& p);

// corner_refinement: the four corners refined to subpixel accuracy on the grey image. The detector runs it on each
// quad before perspective_removal, so that the frontal view's cell grid lines up with the printed cells.
// `factor`: the decimation the quad was found at; its corners may then be off by about that many pixels, so the
// first pass looks that much further and one more pass is made.
void refine_corners(const cv::Mat& grey, Quad& corners, int cells, const DetectorParams& p, int factor = 1);

// duplicates: of the markers read, one per id and place. A marker whose centre is inside a larger marker is dropped.
// The same id seen twice in one place keeps the reading of the finer search (its quad started nearer the corners: a
// coarse search's blocks can start a low-contrast quad on a shadow's edge), or of two from one search the larger.
struct FoundMarker {
  Quad corners;       // the marker's corners
  int dict = -1;      // its dictionary's index
  int id = -1;
  int factor = 1;     // the decimation its quad was found at
  size_t key = 0;     // ties in size and in id are kept in this order
};
// The indices into `found` kept, by dictionary, id and key; `reasons` gets, per marker dropped, why (else "").
std::vector<size_t> drop_duplicates(const std::vector<FoundMarker>& found, std::vector<std::string>* reasons);

}  // namespace arwb::stages
