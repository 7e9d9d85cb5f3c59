// The main window's tiling drawn (the tree: ui/workspace_tree.hpp). draw_workspace turns the current workspace's
// tree into child windows of one host window, with tab bars, splitters and drag and drop, and audits what ImGui
// drew (regions overlapping, items or table cells cut off) for --stats and the tests.
#pragma once

#include "ui/workspace_tree.hpp"

#include <imgui.h>

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace arwb::ui {

// What draw_workspace saw this frame, for --stats and the tests: each region's rectangle and panels, regions
// overlapping, and items ImGui drew past the edge of a region (a direction without a scrollbar) or past a table
// column's edge (without the table scrolling sideways). A panel's entries are those of the last frame it was drawn
// (after it settled: drawn_in_a_row).
struct LayoutAudit {
  struct Region {
    std::vector<Panel> tabs;
    Panel front = Panel::count;
    ImVec2 pos, size;
  };
  std::vector<Region> regions;
  int overlaps = 0;
  std::array<std::vector<std::string>, kPanelCount> clipped;      // cut in the last two frames the panel was audited
  std::array<std::vector<std::string>, kPanelCount> last_frame;   // what was cut in its last audited frame
  // Frames each panel has been drawn in a row: its entries are taken from the third on, once ImGui's tables and
  // scrollbars have fitted themselves to it (they lag a frame or two behind a change).
  std::array<int, kPanelCount> drawn_in_a_row{};
  // Top-level windows (Help windows, dialogs, open menus and popups; the workspace's and the status bar's own
  // are placed inside) that reach past the screen's edge in the last frame, by title: cut, for a class at a
  // projector ("Keyboard shortcuts 1240x840 at -60,120").
  std::vector<std::string> off_screen;
};

// Draws the switcher row, then the current workspace's regions and splitters in the rectangle given, each panel
// by `draw` inside its region; honours view.open (panels opened or closed by menus, actions and panels) and
// view.front. Fills `audit`.
void draw_workspace(Context& ctx, Workspaces& ws, ImVec2 pos, ImVec2 size, const std::function<void(Panel)>& draw,
                    LayoutAudit* audit);

}  // namespace arwb::ui
