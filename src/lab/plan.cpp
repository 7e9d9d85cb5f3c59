#include "lab/plan.hpp"

namespace arwb::lab {

std::vector<Cell> LabPlan::cells() const {
  std::vector<Cell> out;
  for (double s : sizes_mm)
    for (double d : distances_m)
      for (double l : lux) out.push_back({s, d, l});
  return out;
}

LabPlan paper_plan() { return LabPlan{}; }

}  // namespace arwb::lab
