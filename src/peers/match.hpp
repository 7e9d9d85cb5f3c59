// The one rule that says whether two detections are the same marker, used wherever detections are compared:
// `arwb bench` (a detector's markers against the synthetic truth) and the workbench's Peers panel (arwb's
// markers against OpenCV's or AprilTag's, matched on the worker). One rule, so the panel and the README agree.
//
// Two markers match when dictionary and id agree and their corners, taken in order, lie on average within
// max(3 px, a tenth of the reference marker's mean side) of each other. The reference is the first list: the
// truth for the bench, arwb for the peers.
#pragma once

#include "detect/trace.hpp"

#include <cstddef>
#include <vector>

namespace arwb {

constexpr double kMatchMinPx = 3.0;        // the tolerance's floor, for small markers
constexpr double kMatchSideRate = 0.1;     // and its share of the reference marker's side

double mean_side(const Quad& q);                               // the mean of its four sides' lengths
double mean_corner_distance(const Quad& a, const Quad& b);     // corner k of a to corner k of b, averaged
double match_tolerance_px(const Quad& reference);              // max(kMatchMinPx, kMatchSideRate * mean_side)

struct MatchedPair {
  size_t reference = 0;   // index into the reference list
  size_t found = 0;       // index into the found list
  double corner_px = 0;   // mean_corner_distance of the two
};

struct MarkerMatching {
  std::vector<MatchedPair> pairs;        // in the order of the found list
  std::vector<size_t> only_reference;    // reference markers nothing matched (ascending)
  std::vector<size_t> only_found;        // found markers that matched nothing (ascending)
  double mean_corner_px() const;         // over the pairs; 0 when there is none
};

// Each found marker, in order, takes the closest reference marker within the tolerance that no earlier one took.
MarkerMatching match_markers(const std::vector<Marker>& reference, const std::vector<Marker>& found);

}  // namespace arwb
