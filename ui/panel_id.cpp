#include "ui/panel_id.hpp"

namespace arwb::ui {

namespace {
struct PanelName {
  const char* key;
  const char* title;
};
constexpr PanelName kPanels[kPanelCount] = {
    {"live_view", "Live view"},   {"pipeline", "Pipeline"},     {"candidates", "Candidates"},
    {"inspector", "Inspector"},   {"parameters", "Parameters"}, {"timings", "Timings"},
    {"dictionary", "Dictionary"}, {"peers", "Peers"},           {"source", "Source"},
    {"tour", "Tour"},             {"why", "Why not detected?"}, {"log", "Log"},
    {"scene", "Scene"},           {"script", "Script editor"},  {"console", "Console"},
    {"calibrate", "Calibrate"},   {"calibration_views", "Calibration views"},
    {"pose", "Pose"},             {"lab", "Lab"},
};
}  // namespace

const char* panel_title(Panel p) { return kPanels[static_cast<int>(p)].title; }
const char* panel_key(Panel p) { return kPanels[static_cast<int>(p)].key; }

bool panel_from_key(std::string_view key, Panel* out) {
  for (int i = 0; i < kPanelCount; ++i) {
    if (key == kPanels[i].key) {
      *out = static_cast<Panel>(i);
      return true;
    }
  }
  return false;
}

}  // namespace arwb::ui
