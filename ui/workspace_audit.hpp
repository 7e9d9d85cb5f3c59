// What draw_workspace checks in what ImGui drew (internal to the workspace's drawing, ui/workspace_audit.cpp):
// regions overlapping, and items or table cells cut off, from ImGui's own rectangles.
#pragma once

#include "ui/workspace.hpp"

#include <utility>
#include <vector>

struct ImGuiWindow;

namespace arwb::ui {

// Fills `audit` for the frame just drawn: the regions `leaves` of `l` and their overlaps, then what is cut off in
// the panels `shown` (each panel's content window as draw_workspace made it).
void audit_layout(const Layout& l, const std::vector<int>& leaves,
                  const std::vector<std::pair<ImGuiWindow*, Panel>>& shown, LayoutAudit* audit);

// The top-level windows (not tooltips) that reach past the main viewport this frame, for LayoutAudit::off_screen.
// Called after everything is drawn.
std::vector<std::string> windows_off_screen();

}  // namespace arwb::ui
