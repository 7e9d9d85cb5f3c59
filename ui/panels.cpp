#include "ui/panels.hpp"

namespace arwb::ui {

void draw_panels(Context& ctx) {
  using Fn = void (*)(Context&);
  static constexpr Fn kDraw[kPanelCount] = {draw_live_view, draw_pipeline,  draw_candidates, draw_inspector,
                                            draw_parameters, draw_timings,  draw_dictionary, draw_peers,
                                            draw_source,     draw_tour,     draw_why,        draw_log,
                                            draw_scene,      draw_script,   draw_console};
  for (int i = 0; i < kPanelCount; ++i) {
    if (!ctx.view.open[static_cast<size_t>(i)]) continue;
    if (ctx.place) ctx.place(static_cast<Panel>(i));
    // A collapsed or hidden window draws nothing, so its textures are neither uploaded nor kept.
    if (ImGui::Begin(panel_title(static_cast<Panel>(i)), &ctx.view.open[static_cast<size_t>(i)])) kDraw[i](ctx);
    ImGui::End();
  }
}

}  // namespace arwb::ui
