// What a lab run measures: the axes of the experiment and how many frames each cell gets. The paper's plan
// (section 5.1) by default: 25 random ARUCO_ORIGINAL markers printed at 250, 150 and 100 pixels of 0.26 mm (65,
// 39 and 26 mm), seen at 2, 1 and 0.5 m under about 1000, 850 and 500 lux, turned in plane over 360 degrees and
// tilted about x and y.
#pragma once

#include "base/result.hpp"

#include <string>
#include <vector>

namespace arwb::lab {

struct Cell {
  double size_mm = 0, distance_m = 0, lux = 0;
};

struct LabPlan {
  std::string name = "paper";
  std::string dictionary = "ARUCO_ORIGINAL";
  int markers = 25;                                  // distinct random ids, drawn with the seed
  std::vector<double> sizes_mm{65, 39, 26};
  std::vector<double> distances_m{2, 1, 0.5};
  std::vector<double> lux{1000, 850, 500};
  double max_tilt_deg = 40;                          // about x and about y, each uniform in +-this
  int frames_per_cell = 40;
  // Frames without a marker per cell, for false positives: this share of frames_per_cell (at least one).
  double empty_share = 0.25;
  int empty_frames_per_cell() const;
  // Every combination, sizes outermost, then distances, then light (the paper's table's order).
  std::vector<Cell> cells() const;
};

LabPlan paper_plan();

// The plan's lists, with the range each value must be in: the plan file and the Lab panel check them alike.
struct PlanAxis {
  const char* key;                       // the field's name in a plan file
  double lo, hi;
  const char* what;                      // "a size in mm"
  std::vector<double> LabPlan::*values;
};
const std::vector<PlanAxis>& plan_axes();   // sizes_mm, distances_m, lux
// Numbers separated by commas or spaces ("65, 39, 26"), 1 to 50 of them, each in the axis's range; else the
// one-line reason naming the key and the value: "sizes_mm: value 2 (-5) must be a size in mm from 1 to 2000".
Result<std::vector<double>> parse_axis(const PlanAxis& axis, const std::string& text);
// The same list as text, for the panel's field.
std::string axis_text(const std::vector<double>& values);

// A plan file (YAML): any of the fields above by name, the others the paper's; the file's name (without .yml)
// names the plan unless it says `name`. Every problem is one line naming the file and the field:
// "p.yml: sizes_mm: value 2 (-5) must be a size in mm from 1 to 2000", "p.yml: dictionary: unknown 'X'",
// "p.yml: unknown field 'size_mm' (did you mean 'sizes_mm'?)", "p.yml: 12000 cells, more than 10000".
Result<LabPlan> read_plan(const std::string& path);

}  // namespace arwb::lab
