#include "lab/plan.hpp"

#include <algorithm>
#include <cmath>

namespace arwb::lab {

std::vector<Cell> LabPlan::cells() const {
  std::vector<Cell> out;
  for (double s : sizes_mm)
    for (double d : distances_m)
      for (double l : lux) out.push_back({s, d, l});
  return out;
}

int LabPlan::empty_frames_per_cell() const {
  return std::max(1, int(std::ceil(frames_per_cell * std::max(0.0, empty_share))));
}

LabPlan paper_plan() { return LabPlan{}; }

}  // namespace arwb::lab
