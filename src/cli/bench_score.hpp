// What arwb bench's detection benchmarks count, shared by the image sets (cmd_bench.cpp) and the video sequences
// (bench_video.cpp): detections scored against the truth by the one matching rule (detect/match.hpp).
#pragma once

#include "detect/trace.hpp"
#include "synth/synth.hpp"

#include <vector>

namespace arwb {

struct Tally {
  std::vector<double> ms;
  int truth = 0, found = 0, false_pos = 0, false_pos_empty = 0, empty_images = 0;
  double corner_err = 0;
  int corner_n = 0;
};

double median(std::vector<double> v);
double mean(const std::vector<double>& v);

// A detection that matches no truth marker is a false positive.
void score(const std::vector<Marker>& found, const std::vector<TruthMarker>& truth, Tally& t);

}  // namespace arwb
