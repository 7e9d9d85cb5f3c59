// Helpers for the lab's tests (test_lab, test_lab_axes, test_lab_session): the smallest plan, and a results table
// without its times.
#pragma once

#include "lab/plan.hpp"

#include <string>

namespace arwb::lab {

// One cell: a 65 mm marker at 0.5 m in 1000 lx, `frames` frames of it.
inline LabPlan one_cell(int frames) {
  LabPlan p;
  p.sizes_mm = {65};
  p.distances_m = {0.5};
  p.lux = {1000};
  p.frames_per_cell = frames;
  return p;
}

// The table without its last column, the detection times (which differ from run to run).
inline std::string without_times(const std::string& csv) {
  std::string out, line;
  for (char c : csv) {
    if (c != '\n') {
      line += c;
      continue;
    }
    out += line.substr(0, line.rfind(',')) + "\n";
    line.clear();
  }
  return out;
}

}  // namespace arwb::lab
