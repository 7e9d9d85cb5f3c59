// What a self-test judges, shared by `arwb export`'s (bundle/self_test.cpp, on the workbench's pipeline) and the
// phone player's (web/core/web_self_test.cpp, in the page): each id the scene maps is shown alone on a synthetic
// frame, and each mapping that covers it must fire.
#pragma once

#include "script/scene_runtime.hpp"
#include "track/overlay.hpp"

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace arwb::script {

// Every id the loaded scene maps, ascending, with the mappings (indices into status().mappings) that cover it.
std::map<int, std::vector<size_t>> mapped_ids(const SceneRuntime& runtime);

struct MappingVerdict {
  int line = 0;                   // the mapping's line in the scene file (0: no such mapping)
  std::string media;              // what it shows (MediaSpec::describe()), or "callbacks only"
  bool fired = false;
  std::string detail;             // why not, one line; "" when it fired
  const Overlay* shown = nullptr; // its overlay for the id, when it made one with pixels
};

// Whether mapping `mapping` fired for marker `id` on its frame: the marker was detected, the mapping is healthy,
// and it made an overlay for that marker with its pixels (a picture, a card, a video frame or a mesh), or it is a
// callbacks-only mapping whose callbacks ran. `errors`: the scene's new error lines of that frame.
MappingVerdict judge_mapping(int id, size_t mapping, bool detected, const SceneStatus& status,
                             const std::vector<Overlay>& overlays, const std::vector<std::string>& errors);

}  // namespace arwb::script
