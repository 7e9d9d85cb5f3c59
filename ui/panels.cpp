#include "ui/panels.hpp"

namespace arwb::ui {

void draw_panel(Panel p, Context& ctx) {
  using Fn = void (*)(Context&);
  static constexpr Fn kDraw[kPanelCount] = {draw_live_view, draw_pipeline,  draw_candidates, draw_inspector,
                                            draw_parameters, draw_timings,  draw_dictionary, draw_peers,
                                            draw_source,     draw_tour,     draw_why,        draw_log,
                                            draw_scene,      draw_script,   draw_console,
                                            draw_calibrate,  draw_calibration_views, draw_pose,
                                            draw_lab};
  kDraw[static_cast<int>(p)](ctx);
}

}  // namespace arwb::ui
