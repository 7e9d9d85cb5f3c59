#include "ui/context.hpp"

#include "render/texture.hpp"

#include <cstdint>
#include <utility>

namespace arwb::ui {

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

void Context::request(Request r) { requests.push_back(std::move(r)); }

ImTextureID Context::texture(const std::string& key, const cv::Mat& image, uint64_t version, bool nearest) {
  const render::Texture& t = textures.get(key, image, version, nearest);
  return reinterpret_cast<ImTextureID>(static_cast<uintptr_t>(t.id()));
}

}  // namespace arwb::ui
