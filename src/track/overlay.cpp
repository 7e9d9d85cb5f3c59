#include "track/overlay.hpp"

namespace arwb {

const char* mapping_health_name(MappingHealth h) {
  switch (h) {
    case MappingHealth::ok: return "ok";
    case MappingHealth::error: return "error";
    case MappingHealth::disabled: return "disabled";
    case MappingHealth::skipped: return "skipped";
  }
  return "ok";
}

int overlay_at(const std::vector<Overlay>& overlays, cv::Point2d p, bool web_only) {
  for (size_t i = overlays.size(); i-- > 0;) {
    const Overlay& o = overlays[i];
    if (web_only && (o.media.kind != MediaKind::web || o.media.url.empty())) continue;
    if (o.quad.contains(p)) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace arwb
