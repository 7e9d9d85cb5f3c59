// The trace: a per-frame record of every detection stage, filled by the detector and read by the UI, the CLI
// and the tests. It is plain data: the pipeline never draws and never writes files; whoever reads the trace does.
//
// Levels: off records nothing but the markers; summary records each stage's time and counts and each quad
// candidate's fate; full adds the stage images, every contour, and per candidate its frontal view, Otsu
// histogram and bit grid.
#pragma once

#include "detect/dictionary.hpp"
#include "detect/quad.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace arwb {

// The pipeline's stages in the order the detector runs them. Their names (stage_name) are used unchanged in the
// trace, the UI, Lua, the tour and docs, always in this order.
enum class Stage {
  acquisition,          // acquisition's resize (capture/source.hpp) and the grey conversion; of a colour video
                        // frame searched by regions, only where later stages look (its time is acquisition's)
  search_regions,       // where the search looks: the whole frame, or (video) around the previous frame's markers
  decimation,           // the grey image shrunk for the search (adaptive_threshold .. quad_fit); a whole colour
                        // frame at 2 is made grey in the same pass (its time is decimation's); candidates are read
                        // on the full grey
  adaptive_threshold,   // dark-against-neighbourhood binary image
  contours,             // borders of the binary regions
  coarse_search,        // the whole frame searched again, coarser, for large markers; its contours join the others
  size_filter,          // drop contours too short or too long
  quad_fit,             // approximate to convex quadrilaterals
  nested_filter,        // merge quads that trace the same border twice, keeping the outer (or finer) one
  corner_refinement,    // subpixel corners, before the warp so that the cell grid lines up with the printed cells
  perspective_removal,  // homography to a frontal view
  otsu,                 // global threshold of the frontal view
  bit_grid,             // one bit per cell
  border_check,         // the outer ring of cells must be black
  identification,       // inner bits against the dictionary in 4 rotations, within a Hamming budget
  fine_search,          // small shapes a decimated search could not close or read, searched again at full resolution
  duplicates,           // one marker per id and place
  accepted,             // not a stage: the fate of a candidate that became a marker
};
constexpr int kStageCount = static_cast<int>(Stage::duplicates) + 1;
std::string_view stage_name(Stage s);
// The stage with that name, or false.
bool stage_from_name(std::string_view name, Stage* out);

enum class TraceLevel { off, summary, full };
std::string_view trace_level_name(TraceLevel level);

// A detected marker. Corners are in the input image's pixels (pixel centres at integer coordinates), the marker's
// own top-left corner first, then clockwise as the marker is printed (OpenCV's order).
struct Marker {
  int id = -1;
  std::string dict;
  Quad corners{};
  int hamming = 0;   // bits corrected
  int rotation = 0;  // quarter-turns of the marker in the image relative to the candidate's corner order
};

struct StageRecord {
  Stage stage = Stage::acquisition;
  double ms = 0;       // summed over candidates for the per-candidate stages
  int in = 0;          // items entering (pixels are not counted: contours, quads, candidates)
  int out = 0;         // items passing on
  cv::Mat image;       // full level: the stage's output image where it has one (grey, binary); decimation's and
                       // adaptive_threshold's are the decimated image's size (trace_view stretches them)
};

// Why a candidate stopped: the stage, the parameter that decided it and the two numbers compared.
struct Rejection {
  Stage stage = Stage::accepted;
  std::string_view param;  // a name from the parameter table (static), or "" when none decides (e.g. not convex)
  double value = 0;    // what the candidate had
  double limit = 0;    // what the parameter allowed
  std::string message; // e.g. "perimeter 31 px < min_perimeter_px 48 px"
};

struct CandidateRecord {
  int contour = -1;            // index into FrameTrace::contours (full level), else -1
  cv::Rect bbox;               // of the contour, in working-image pixels
  double perimeter = 0;        // contour length in px
  bool has_quad = false;
  Quad quad{};                 // fitted quad, clockwise on screen, working-image pixels
  cv::Mat warp;                // full: the frontal view, (n+2)*warp_cell_px*view_scale square, grey
  int otsu_threshold = -1;
  double stddev = 0;
  std::vector<int> histogram;  // full: 256 bins of the frontal view
  cv::Mat bits;                // full: (n+2)x(n+2) CV_8U 0/1 cells, border included
  int border_errors = -1;
  int border_cells = 0;
  std::string dict;            // the dictionary the grid was read for
  bool local_thresholds = false;  // bits and fate are of bit_grid's second read, a threshold per cell
  bool read_as_found = false;  // stopped by its read before corner_refinement (unrefined_miss_rate): the frontal
                               // view, bits and fate are of the unrefined quad
  std::array<DictMatch, 4> per_rotation{};  // nearest id in each rotation (when identification ran)
  int marker = -1;             // index into FrameTrace::markers when accepted
  Rejection fate;              // stage == Stage::accepted when it became a marker

  // The rotation whose nearest id is closest (lowest rotation on ties); -1 when identification did not run.
  int best_rotation() const;
  // The nearest id in that rotation (id -1 when identification did not run).
  DictMatch nearest() const { return best_rotation() < 0 ? DictMatch{} : per_rotation[size_t(best_rotation())]; }
};

// search_regions: where one frame's search looked. The whole frame at decimation_factor, or, in video
// (detect/video_search.hpp), regions around the markers the previous frame found, at a decimation chosen from the
// smallest of them.
struct SearchRecord {
  bool whole = true;               // the whole frame at decimation_factor
  std::vector<cv::Rect> regions;   // working pixels; the frame's rectangle when whole
  int factor = 1;                  // the decimation the regions were searched at
  int known = 0;                   // markers the previous frames told of
  std::string why;                 // e.g. "full search: every 5th frame (full_search_interval)"
};

struct FrameTrace {
  TraceLevel level = TraceLevel::off;
  int width = 0, height = 0;              // the input image
  int work_width = 0, work_height = 0;    // after acquisition's resize (the working image)
  double scale_x = 1, scale_y = 1;        // input pixels per working pixel
  double total_ms = 0;
  std::vector<StageRecord> stages;                  // in pipeline order (summary, full)
  SearchRecord search;                              // summary, full
  std::vector<std::vector<cv::Point>> contours;     // full: every contour found
  std::vector<CandidateRecord> candidates;          // summary: quads and later; full: every contour
  std::vector<Marker> markers;                      // always

  const StageRecord* stage(Stage s) const;
  // How many working pixels a pixel of the search's pictures (decimation, adaptive_threshold) covers across:
  // the decimation factor used, 1 when there is no such picture.
  int search_factor() const;
};

}  // namespace arwb
