#include "ui/context.hpp"

#include "render/texture.hpp"

#include <cstdint>

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

View::View() {
  open.fill(true);
  // The first start opens what fits the default layout side by side; the rest are one click away (View menu).
  for (Panel p : {Panel::tour, Panel::why, Panel::dictionary, Panel::peers, Panel::scene, Panel::script,
                  Panel::console, Panel::calibrate, Panel::calibration_views, Panel::pose, Panel::lab}) {
    open[static_cast<size_t>(p)] = false;
  }
  show_rejected_stage.fill(true);
  // Regions too small to trace are hundreds of specks per frame: the ledger and the overlay hide them at first.
  show_rejected_stage[static_cast<size_t>(Stage::size_filter)] = false;
}

ImTextureID Context::texture(const std::string& key, const cv::Mat& image, uint64_t version, bool nearest) {
  const render::Texture& t = textures.get(key, image, version, nearest);
  return reinterpret_cast<ImTextureID>(static_cast<uintptr_t>(t.id()));
}

}  // namespace arwb::ui
