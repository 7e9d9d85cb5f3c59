// What the detector's end-to-end tests share: a found marker's corners against the truth, and a marker by id.
#pragma once

#include "detect/detector.hpp"
#include "synth/synth.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <vector>

namespace arwb::test {

// The mean distance of the four corners from the truth's, px.
inline double mean_corner_error(const Marker& m, const TruthMarker& t) {
  double e = 0;
  for (int k = 0; k < 4; ++k) e += cv::norm(m.corners[size_t(k)] - t.corners[size_t(k)]);
  return e / 4;
}

// The first marker (detected, or of the truth) with `id`; end() when there is none.
template <class T>
typename std::vector<T>::const_iterator with_id(const std::vector<T>& all, int id) {
  return std::find_if(all.begin(), all.end(), [id](const T& k) { return k.id == id; });
}

}  // namespace arwb::test
