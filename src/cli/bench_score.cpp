#include "cli/bench_score.hpp"

#include "peers/match.hpp"

#include <algorithm>
#include <numeric>

namespace arwb {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double mean(const std::vector<double>& v) {
  return v.empty() ? 0 : std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
}

void score(const std::vector<Marker>& found, const std::vector<TruthMarker>& truth, Tally& t) {
  std::vector<Marker> reference;
  for (const TruthMarker& m : truth) reference.push_back({m.id, m.dict, m.corners, 0, 0});
  const MarkerMatching m = match_markers(reference, found);
  t.truth += int(truth.size());
  if (truth.empty()) ++t.empty_images;
  t.found += int(m.pairs.size());
  for (const MatchedPair& p : m.pairs) t.corner_err += p.corner_px;
  t.corner_n += int(m.pairs.size());
  t.false_pos += int(m.only_found.size());
  if (truth.empty()) t.false_pos_empty += int(m.only_found.size());
}

}  // namespace arwb
