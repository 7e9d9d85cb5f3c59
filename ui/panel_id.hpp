// The panels by name: the View menu's order, their titles (the window names ImGui saves the layout under) and their
// keys (--actions open=KEY, the workspaces file).
#pragma once

#include <string_view>

namespace arwb::ui {

enum class Panel { live_view, pipeline, candidates, inspector, parameters, timings, dictionary, peers, source, tour,
                   why, log, scene, script, console, calibrate, calibration_views, pose, lab, count };
constexpr int kPanelCount = static_cast<int>(Panel::count);
const char* panel_title(Panel p);
const char* panel_key(Panel p);   // "live_view", "pipeline"... (for --actions N:open=KEY and the saved layout)
bool panel_from_key(std::string_view key, Panel* out);

}  // namespace arwb::ui
