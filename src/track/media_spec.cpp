#include "track/media_spec.hpp"

#include <cstdio>

namespace arwb {

bool is_solid(MediaKind k) { return k == MediaKind::cube || k == MediaKind::axes || k == MediaKind::model; }

const char* media_kind_name(MediaKind k) {
  switch (k) {
    case MediaKind::none: break;
    case MediaKind::image: return "image";
    case MediaKind::video: return "video";
    case MediaKind::web: return "web";
    case MediaKind::text: return "text";
    case MediaKind::stage: return "stage";
    case MediaKind::cube: return "cube";
    case MediaKind::axes: return "axes";
    case MediaKind::model: return "model";
  }
  return "none";
}

std::string MediaSpec::describe() const {
  switch (kind) {
    case MediaKind::none: return "callbacks only";
    case MediaKind::image: return "image " + source;
    case MediaKind::video: return "video " + source + (loop ? " (loop)" : "");
    case MediaKind::web: return "web " + url;
    case MediaKind::stage: return "stage " + stage;
    case MediaKind::cube:
    case MediaKind::axes:
    case MediaKind::model: {
      std::string d = kind == MediaKind::cube ? "cube" : kind == MediaKind::axes ? "axes" : "model " + source;
      char b[96];
      if (size != 1.0) {
        std::snprintf(b, sizeof b, " size %g", size);
        d += b;
      }
      if (offset != cv::Vec3d(0, 0, 0)) {
        std::snprintf(b, sizeof b, " offset %g,%g,%g", offset[0], offset[1], offset[2]);
        d += b;
      }
      if (rotate_deg != cv::Vec3d(0, 0, 0)) {
        std::snprintf(b, sizeof b, " rotate %g,%g,%g", rotate_deg[0], rotate_deg[1], rotate_deg[2]);
        d += b;
      }
      return d;
    }
    case MediaKind::text: {
      // One line, short enough for a table cell.
      std::string t = text;
      for (char& c : t) if (c == '\n' || c == '\t') c = ' ';
      if (t.size() > 40) t = t.substr(0, 37) + "...";
      // A computed text has no words until it runs (a mapping's row, the export's self-test): `text (computed)`
      // rather than an empty pair of quotes that reads like a mistake.
      if (source == "function") return t.empty() ? "text (computed)" : "text \"" + t + "\" (computed)";
      return "text \"" + t + "\"";
    }
  }
  return {};
}

}  // namespace arwb
