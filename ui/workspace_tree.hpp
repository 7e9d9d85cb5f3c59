// The main window's tiling as data (Dear ImGui 1.86 has no docking, so it is ours). A workspace is a tree: a
// split cuts its rectangle in two (side by side or one above the other, at a ratio the user drags) and a leaf is
// a region, a tab bar of panels with one in front. Regions never overlap: the tree gives each its own rectangle.
// Each workspace keeps two trees, one for normal and one for presentation mode, since a teacher's screen wants
// the live view and the current stage large. The shipped workspaces are written with tabs()/columns()/rows() in
// ui/workspace_tree.cpp (shipped_workspaces): adding one (Calibrate, Lab) is a few lines there.
// Nothing here draws or needs a window (ImVec2 is only a pair of floats): the tree is tested on its own.
// ui/workspace.hpp draws it.
#pragma once

#include "ui/context.hpp"

#include <imgui.h>

#include <initializer_list>
#include <string>
#include <vector>

namespace arwb::ui {

struct LayoutNode {
  bool split = false;
  bool vertical = false;    // split: `first` above `second`; else `first` left of `second`
  float ratio = 0.5f;       // split: the first child's share of the length (the splitter's place)
  int first = -1, second = -1;
  std::vector<Panel> tabs;  // region: its panels, in tab order
  int active = 0;           // region: the tab in front
  bool select = true;       // region: ImGui's tab bar still has to be told which tab is in front
  ImVec2 pos{0, 0}, size{0, 0};   // where it was drawn last (screen pixels)
};

// nodes[0] is the root. A region emptied by moving its last panel away is folded into its parent; the nodes left
// unreachable are dropped when the layout is saved.
struct Layout {
  std::vector<LayoutNode> nodes;
};

// Node n of the layout (an index regions(), splits() or a split's first and second give).
inline LayoutNode& at(Layout& l, int n) { return l.nodes[static_cast<size_t>(n)]; }
inline const LayoutNode& at(const Layout& l, int n) { return l.nodes[static_cast<size_t>(n)]; }

// How shipped layouts are written: tabs({live_view, pipeline}), columns(0.6f, left, right), rows(0.5f, top, bottom).
struct Tile {
  LayoutNode node;
  std::vector<Tile> kids;
};
Tile tabs(std::initializer_list<Panel> panels);
Tile columns(float ratio, Tile left, Tile right);
Tile rows(float ratio, Tile top, Tile bottom);
Layout make_layout(const Tile& t);

struct Workspace {
  std::string name;
  bool shipped = false;
  Layout normal, presentation;
  Layout& layout(bool present) { return present ? presentation : normal; }
  const Layout& layout(bool present) const { return present ? presentation : normal; }
};

// Inspect, Script, Teach: one per kind of user, in the order of the switcher (Ctrl+1, Ctrl+2...).
std::vector<Workspace> shipped_workspaces();

// The leaves (regions) reachable from the root, in drawing order.
std::vector<int> regions(const Layout& l);
// The region showing panel p, or -1.
int region_of(const Layout& l, Panel p);
// The region a panel opened from the View menu goes to: beside a panel it sits with in the shipped layout of
// the same name (`shipped`, may be null), else the largest region not showing the live view.
int region_for(const Layout& l, const Layout* shipped, Panel p);
// Adds p (when absent) and puts its tab in front.
void bring_to_front(Layout& l, const Layout* shipped, Panel p);
// Removes p; a region left empty is folded into its parent (the root region stays, empty).
void remove_panel(Layout& l, Panel p);
// Moves p into region `to` (a leaf index), in front.
void move_panel(Layout& l, Panel p, int to);
// The splits reachable from the root, depth first (for the `splitter=I,RATIO` action).
std::vector<int> splits(const Layout& l);

// All workspaces and the one in use; kept in the config folder's workspaces.json.
struct Workspaces {
  std::vector<Workspace> list;
  int current = 0;
  // The switcher's own state: which workspace view.open was last made to show, the save-as name being typed.
  int shown = -1;
  bool shown_presentation = false;
  bool select = true;   // the switcher's tab bar still has to be told which workspace is current
  char new_name[48] = "";
  std::string save_problem;   // why the last save-as was refused
  Workspaces();   // the shipped ones
  Workspace& now() { return list[static_cast<size_t>(current)]; }
  const Workspace* shipped(const std::string& name) const;
  int find(const std::string& name) const;   // -1 when none has that name
  // Saves the current arrangement (both modes) under `name` and switches to it; false with a reason when the
  // name is empty, too long or a shipped workspace's.
  bool save_as(const std::string& name, std::string* error);
};

// The JSON file: {"version":1,"current":"Inspect","workspaces":[{"name":..,"normal":TREE,"presentation":TREE}]},
// a TREE being {"tabs":["live_view",..],"active":0} or {"split":"columns"|"rows","ratio":0.5,"first":TREE,
// "second":TREE}. Shipped workspaces in the file replace the shipped layout; others are the user's.
std::string workspaces_to_json(const Workspaces& w);
// False with a message naming what is wrong; `out` is then untouched.
bool workspaces_from_json(const std::string& text, Workspaces* out, std::string* error);

// Makes view.open show what the current workspace holds (after switching or loading).
void show_workspace(const Workspaces& ws, View& view);
// Makes workspace i current in view.presentation's arrangement, at once: a panel opened later in the same frame
// (an action, --scene) is added to it, not lost to the switch.
void switch_workspace(Workspaces& ws, int i, View& view);
// What the menus, actions and panels asked for since the last frame, taken into the current workspace: panels
// opened (placed beside the ones they sit with in the shipped layout) or closed in view.open, view.front brought
// to the front; after switching first when the workspace or the mode changed. view.open then mirrors the tree.
void follow_view(Workspaces& ws, View& view);

}  // namespace arwb::ui
