#include "script/self_test_verdict.hpp"

namespace arwb::script {

std::map<int, std::vector<size_t>> mapped_ids(const SceneRuntime& runtime) {
  std::map<int, std::vector<size_t>> by_id;
  const auto ranges = runtime.mapping_ids();
  for (size_t mi = 0; mi < ranges.size(); ++mi)
    for (const auto& [first, last] : ranges[mi])
      for (int id = first; id <= last; ++id) {
        std::vector<size_t>& mappings = by_id[id];
        if (mappings.empty() || mappings.back() != mi) mappings.push_back(mi);   // overlapping ranges: once
      }
  return by_id;
}

MappingVerdict judge_mapping(int id, size_t mapping, bool detected, const SceneStatus& status,
                             const std::vector<Overlay>& overlays, const std::vector<std::string>& errors) {
  MappingVerdict v;
  const MappingRow* row = mapping < status.mappings.size() ? &status.mappings[mapping] : nullptr;
  v.line = row ? row->line : 0;
  v.media = row ? row->media : "?";
  const bool callbacks_only = row && row->media == "callbacks only";
  for (const Overlay& o : overlays)
    if (o.marker_id == id && o.mapping == int(mapping) && (o.content || o.solid)) v.shown = &o;
  const bool healthy = row && row->health == MappingHealth::ok;
  v.fired = detected && healthy && (v.shown || callbacks_only);
  if (!detected) v.detail = "not detected on its synthetic frame";
  else if (!healthy) v.detail = row ? row->reason : "no such mapping";
  else if (!v.fired) v.detail = errors.empty() ? "no media shown for it" : errors.front();
  if (v.media.empty() && v.shown) v.media = v.shown->media.describe();
  return v;
}

}  // namespace arwb::script
