// --stats: what the run sums frame by frame, and the one JSON line of figures printed at exit (ui/stats.cpp).
#pragma once

#include "detect/trace.hpp"

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>

namespace arwb {

struct App;

struct StatsTotals {
  int ui_frames = 0;
  uint64_t last_frame_index = 0;   // the newest finished frame counted
  int detected_seen = 0;           // finished frames the window showed
  double detect_ms_sum = 0;
  std::array<double, kStageCount> stage_ms_sum{};
  std::array<int, kStageCount> stage_ms_n{};
  std::map<std::string, std::pair<double, int>> peer_ms;   // name: summed ms, frames
  double composite_ms = 0;
  int composites = 0;              // -1: the compositor failed (said once)
  double draw_calls = 0, vertices = 0;
  double covered_px = 0, window_px = 0;   // the triangles' area drawn, and the framebuffer's, summed over frames
  std::array<double, 3> ui_ms{};   // building the panels, rendering them, swapping
};

// The run's figures as one JSON line: `elapsed` seconds of UI frames, `detected` frames the worker finished.
std::string stats_json(App& app, double elapsed, uint64_t detected);

}  // namespace arwb
