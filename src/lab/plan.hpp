// What a lab run measures: the axes of the experiment and how many frames each cell gets. The paper's plan
// (section 5.1) by default: 25 random ARUCO_ORIGINAL markers printed at 250, 150 and 100 pixels of 0.26 mm (65,
// 39 and 26 mm), seen at 2, 1 and 0.5 m under about 1000, 850 and 500 lux, turned in plane over 360 degrees and
// tilted about x and y.
#pragma once

#include "base/result.hpp"

#include <string>
#include <vector>

namespace arwb::lab {

// One combination of the plan's axes. The axes past size, distance and light are a plan file's own (sides_px,
// tilts_deg, blurs_px, noises, occlusions); their defaults leave a cell as the paper's.
struct Cell {
  double size_mm = 0, distance_m = 0, lux = 0;
  double side_px = 0;       // the plan's sides_px value (size_mm was derived from it), 0 when it gives sizes_mm
  double tilt_deg = -1;     // the marker's tilt, exactly; negative: random up to the plan's max_tilt_deg
  double blur_px = 0;       // a Gaussian blur (sigma, px) on top of the optics' defocus and the hand's motion
  double noise = 0;         // a Gaussian noise (sigma, grey levels) on top of the sensor's
  double occlusion = 0;     // the share of the marker covered along one of its sides
  // 0: a cell of the plan's grid; kBlurCurve or kNoiseCurve: a point of the report's blur or noise curve, the
  // grid's cell at LabPlan::curve_at with only blur_px or noise changed.
  int curve = 0;
};
inline constexpr int kBlurCurve = 1, kNoiseCurve = 2;

struct LabPlan {
  std::string name = "paper";
  std::string dictionary = "ARUCO_ORIGINAL";
  int markers = 25;                                  // distinct random ids, drawn with the seed
  std::vector<double> sizes_mm{65, 39, 26};
  std::vector<double> distances_m{2, 1, 0.5};
  std::vector<double> lux{1000, 850, 500};
  double max_tilt_deg = 40;                          // about x and about y, each uniform in +-this
  // The axes a plan file may add (empty or {0}: the paper's). sides_px, when given, replaces sizes_mm: the
  // marker's side in pixels at the image centre, its printed size derived per distance through the camera.
  // tilts_deg, when given, replaces the random tilt by exactly each angle, about a random axis in the marker's
  // plane. blurs_px, noises and occlusions are Cell's blur_px, noise and occlusion.
  std::vector<double> sides_px;
  std::vector<double> tilts_deg;
  std::vector<double> blurs_px{0};
  std::vector<double> noises{0};
  std::vector<double> occlusions{0};
  // The report's blur and noise curves: at curve_at (size in mm, distance in m, light in lux: a cell of the grid),
  // a cell per added blur and per added noise, each on that cell's very frames with only the one factor changed.
  // None when the grid has no such cell, is sized by sides_px, or has added axes of its own (curve_base()).
  std::vector<double> curve_at{39, 1, 500};
  std::vector<double> curve_blurs_px{0.5, 1, 1.5, 2};
  std::vector<double> curve_noises{15, 30, 45, 60};
  int frames_per_cell = 400;   // 95 % intervals of at most about +-5 points (the Wilson interval at 50 %)
  // Frames without a marker per cell, for false positives: this share of frames_per_cell (at least one).
  double empty_share = 0.25;
  int empty_frames_per_cell() const;
  // Every combination, sizes (or sides) outermost, then distances, tilts, blurs, noises, occlusions, and light
  // innermost (the paper's table's order: a row per everything but light, a column per light level). A sides_px
  // plan's cells get their size_mm through the camera's focal length `focal_px`.
  // Then the curves' cells, blurs first, after the grid's.
  std::vector<Cell> cells(double focal_px) const;
  size_t cell_count() const;
  size_t grid_count() const;   // the grid's cells, the first of cells()
  // The index of the grid's cell the curves vary; -1 when there are no curves (the reason in *why, when given).
  long curve_base(std::string* why = nullptr) const;
  // "8 cells for the blur and noise curves at 39 mm, 1 m, 500 lx", or "" without curves.
  std::string curves_text() const;
  // The cell of the paper's three axes (size or side, distance, light) cell `index` belongs to, as an index into
  // those axes' product: cells that differ only in the added axes share it, and with it their frames' markers,
  // poses and noise (so the added axes are compared on the same frames). For the paper's plan it is `index`; for a
  // curve's cell, its base cell's.
  size_t pose_index(size_t index) const;
  // Which of the added axes the plan varies (a tilt given, or a blur, noise or occlusion other than none).
  bool has_tilts() const { return !tilts_deg.empty(); }
  bool has_blurs() const;
  bool has_noises() const;
  bool has_occlusions() const;
};

// The added axes' values of a cell, for the axes the plan has: "tilt 60 blur 1.5 noise 8 occluded 0.4" (empty for
// the paper's plan). Row labels of the table and the Lab workspace's grid.
std::string added_axes_text(const LabPlan& plan, const Cell& cell);

LabPlan paper_plan();

// The plan's lists, with the range each value must be in: the plan file and the Lab panel check them alike.
struct PlanAxis {
  const char* key;                       // the field's name in a plan file
  double lo, hi;
  const char* what;                      // "a size in mm"
  std::vector<double> LabPlan::*values;
};
// sizes_mm, distances_m, lux, then the added axes: sides_px, tilts_deg, blurs_px, noises, occlusions.
const std::vector<PlanAxis>& plan_axes();
// Numbers separated by commas or spaces ("65, 39, 26"), 1 to 50 of them, each in the axis's range; else the
// one-line reason naming the key and the value: "sizes_mm: value 2 (-5) must be a size in mm from 1 to 2000".
Result<std::vector<double>> parse_axis(const PlanAxis& axis, const std::string& text);
// The same list as text, for the panel's field.
std::string axis_text(const std::vector<double>& values);

// The most cells a plan (or a videos.csv's grid of sizes, distances and lights) may have: checked before any is
// made.
inline constexpr size_t kMaxLabCells = 10000;

// A plan file (YAML): any of the fields above by name, the others the paper's; the file's name (without .yml)
// names the plan unless it says `name`. Every problem is one line naming the file and the field:
// "p.yml: sizes_mm: value 2 (-5) must be a size in mm from 1 to 2000", "p.yml: dictionary: unknown 'X'",
// "p.yml: unknown field 'size_mm' (did you mean 'sizes_mm'?)", "p.yml: 12000 cells, more than 10000",
// "p.yml: sides_px and sizes_mm: give one of them (sides_px derives the printed size)".
Result<LabPlan> read_plan(const std::string& path);

}  // namespace arwb::lab
