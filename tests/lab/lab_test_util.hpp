// Helpers for the lab's tests (test_lab, test_lab_axes): the smallest plan.
#pragma once

#include "lab/plan.hpp"

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

}  // namespace arwb::lab
