#include "track/media_spec.hpp"

namespace arwb {

std::string MediaSpec::describe() const {
  switch (kind) {
    case MediaKind::none: return "callbacks only";
    case MediaKind::image: return "image " + source;
    case MediaKind::video: return "video " + source + (loop ? " (loop)" : "");
    case MediaKind::web: return "web " + url;
    case MediaKind::stage: return "stage " + stage;
    case MediaKind::text: {
      // One line, short enough for a table cell.
      std::string t = text;
      for (char& c : t) if (c == '\n' || c == '\t') c = ' ';
      if (t.size() > 40) t = t.substr(0, 37) + "...";
      return "text \"" + t + "\"" + (source == "function" ? " (computed)" : "");
    }
  }
  return {};
}

}  // namespace arwb
