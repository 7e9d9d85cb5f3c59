#include "detect/trace.hpp"

#include <algorithm>

namespace arwb {
namespace {
constexpr std::string_view kStageNames[] = {
    "acquisition", "search_regions", "decimation", "adaptive_threshold", "contours", "coarse_search", "size_filter",
    "quad_fit", "nested_filter", "corner_refinement", "perspective_removal", "otsu", "bit_grid", "border_check",
    "identification", "fine_search", "duplicates", "accepted"};
static_assert(std::size(kStageNames) == kStageCount + 1);
}  // namespace

std::string_view stage_name(Stage s) { return kStageNames[static_cast<int>(s)]; }

bool stage_from_name(std::string_view name, Stage* out) {
  for (int i = 0; i <= kStageCount; ++i)
    if (kStageNames[i] == name) {
      *out = static_cast<Stage>(i);
      return true;
    }
  return false;
}

std::string_view trace_level_name(TraceLevel level) {
  switch (level) {
    case TraceLevel::off: return "off";
    case TraceLevel::summary: return "summary";
    case TraceLevel::full: return "full";
  }
  return "?";
}

int FrameTrace::search_factor() const {
  const StageRecord* th = stage(Stage::adaptive_threshold);
  if (!th || th->image.empty() || th->image.cols <= 0 || work_width <= 0) return 1;
  return std::max(1, work_width / th->image.cols);
}

int CandidateRecord::best_rotation() const {
  int best = -1;
  for (int k = 0; k < 4; ++k) {
    const DictMatch& m = per_rotation[size_t(k)];
    if (m.id >= 0 && (best < 0 || m.hamming < per_rotation[size_t(best)].hamming)) best = k;
  }
  return best;
}

const StageRecord* FrameTrace::stage(Stage s) const {
  for (const auto& r : stages)
    if (r.stage == s) return &r;
  return nullptr;
}

}  // namespace arwb
