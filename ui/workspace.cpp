// The tiling drawn (ui/workspace.hpp): the switcher row, the regions as child windows with their tab bars, the
// splitters, drag and drop; what ImGui drew is audited by ui/workspace_audit.cpp.
#include "ui/workspace.hpp"

#include "ui/workspace_audit.hpp"

#include <imgui_internal.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace arwb::ui {

namespace {
constexpr const char* kPayload = "ARWB_PANEL";

struct Sizes {
  float gap;       // splitter thickness
  ImVec2 leaf;     // smallest region
};

ImVec2 min_size(const Layout& l, int n, const Sizes& s) {
  const LayoutNode& node = at(l, n);
  if (!node.split) return s.leaf;
  const ImVec2 a = min_size(l, node.first, s), b = min_size(l, node.second, s);
  return node.vertical ? ImVec2(std::max(a.x, b.x), a.y + b.y + s.gap) : ImVec2(a.x + b.x + s.gap, std::max(a.y, b.y));
}

// The first child's length along the split: the ratio, kept within the children's minimum sizes when they fit.
float first_length(const Layout& l, const LayoutNode& node, float length, const Sizes& s) {
  const float avail = length - s.gap;
  const ImVec2 a = min_size(l, node.first, s), b = min_size(l, node.second, s);
  const float amin = node.vertical ? a.y : a.x, bmin = node.vertical ? b.y : b.x;
  if (amin + bmin > avail) return std::floor(avail * amin / std::max(1.0f, amin + bmin));
  return std::floor(std::clamp(avail * node.ratio, amin, avail - bmin));
}

void place(Layout& l, int n, ImVec2 pos, ImVec2 size, const Sizes& s) {
  LayoutNode& node = at(l, n);
  node.pos = pos;
  node.size = size;
  if (!node.split) return;
  const float len = node.vertical ? size.y : size.x;
  const float a = first_length(l, node, len, s);
  const float b = std::max(0.0f, len - s.gap - a);
  if (node.vertical) {
    place(l, node.first, pos, {size.x, a}, s);
    place(l, node.second, {pos.x, pos.y + a + s.gap}, {size.x, b}, s);
  } else {
    place(l, node.first, pos, {a, size.y}, s);
    place(l, node.second, {pos.x + a + s.gap, pos.y}, {b, size.y}, s);
  }
}

std::string region_label(const LayoutNode& n) {
  std::string s;
  for (Panel p : n.tabs) s += (s.empty() ? "" : ", ") + std::string(panel_title(p));
  return s.empty() ? "(empty region)" : s;
}

struct Pending {
  enum Kind { none, move, close } kind = none;
  Panel panel = Panel::count;
  int to = -1;
};

void switcher(Workspaces& ws, View& view) {
  const ImGuiIO& io = ImGui::GetIO();
  int switch_to = -1;
  // Ctrl+1..9 (ImGui 1.86 indexes keys by GLFW's key codes, which are the ASCII codes for digits).
  for (int i = 0; i < std::min<int>(9, static_cast<int>(ws.list.size())); ++i) {
    if (io.KeyCtrl && !io.KeyShift && ImGui::IsKeyPressed('1' + i, false)) switch_to = i;
  }
  if (ImGui::BeginTabBar("##workspaces", ImGuiTabBarFlags_FittingPolicyScroll | ImGuiTabBarFlags_NoTooltip)) {
    int remove = -1;
    bool agreed = false;
    for (int i = 0; i < static_cast<int>(ws.list.size()); ++i) {
      Workspace& w = ws.list[static_cast<size_t>(i)];
      const ImGuiTabItemFlags f = ws.select && i == ws.current ? ImGuiTabItemFlags_SetSelected : 0;
      const std::string label = w.name + "###ws" + w.name;
      const bool on = ImGui::BeginTabItem(label.c_str(), nullptr, f);
      if (i < 9 && ImGui::IsItemHovered()) ImGui::SetTooltip("Ctrl+%d", i + 1);
      if (ImGui::BeginPopupContextItem()) {
        if (const Workspace* home = ws.shipped(w.name)) {
          if (ImGui::MenuItem("Reset to the shipped layout")) {
            w.normal = home->normal;
            w.presentation = home->presentation;
            ws.shown = -1;   // view.open follows the reset tree, not the other way round
            switch_workspace(ws, i, view);
          }
        } else if (ImGui::MenuItem("Delete this workspace")) {
          remove = i;
        }
        ImGui::EndPopup();
      }
      if (on) {
        // Until ImGui's tab bar shows the current workspace, the switcher decides; then a click on a tab does.
        if (ws.select) agreed = i == ws.current;
        else if (i != ws.current && switch_to < 0) switch_to = i;
        ImGui::EndTabItem();
      }
    }
    if (agreed) ws.select = false;
    if (ImGui::TabItemButton("+", ImGuiTabItemFlags_Trailing | ImGuiTabItemFlags_NoTooltip)) {
      ImGui::OpenPopup("Save workspace");
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Save this arrangement as a workspace of your own");
    ImGui::EndTabBar();
    if (remove >= 0 && remove != ws.current) {
      const std::string cur = ws.now().name;
      ws.list.erase(ws.list.begin() + remove);
      ws.shown = -1;
      switch_workspace(ws, std::max(0, ws.find(cur)), view);
    }
  }
  if (ImGui::BeginPopup("Save workspace")) {
    ImGui::TextUnformatted("Name of the new workspace:");
    if (ImGui::IsWindowAppearing()) ImGui::SetKeyboardFocusHere();
    const bool enter = ImGui::InputText("##name", ws.new_name, sizeof ws.new_name, ImGuiInputTextFlags_EnterReturnsTrue);
    std::string& problem = ws.save_problem;
    if (ImGui::Button("Save") || enter) {
      if (ws.save_as(ws.new_name, &problem)) {
        problem.clear();
        ws.new_name[0] = 0;
        ImGui::CloseCurrentPopup();
      }
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) ImGui::CloseCurrentPopup();
    if (!problem.empty()) ImGui::TextColored({1, 0.4f, 0.3f, 1}, "%s", problem.c_str());
    ImGui::EndPopup();
  }
  if (switch_to >= 0 && switch_to != ws.current) switch_workspace(ws, switch_to, view);
}

// One region: its tab bar (each tab a drag source, with a menu to move or close it), the region a drop target,
// and the panel in front drawn by `draw` inside a child window of its own, recorded in `shown` for the audit.
void draw_region(Layout& l, int r, const std::vector<int>& leaves, const std::function<void(Panel)>& draw,
                 Pending& pending, std::vector<std::pair<ImGuiWindow*, Panel>>& shown) {
  LayoutNode& node = at(l, r);
  ImGui::SetCursorScreenPos(node.pos);
  ImGui::PushID(r);
  ImGui::BeginChild("##region", node.size, false, ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoScrollWithMouse);
  const ImRect region_rect(node.pos, {node.pos.x + node.size.x, node.pos.y + node.size.y});
  if (ImGui::BeginTabBar("##tabs", ImGuiTabBarFlags_FittingPolicyScroll | ImGuiTabBarFlags_NoTooltip)) {
    bool agreed = false;
    for (int i = 0; i < static_cast<int>(node.tabs.size()); ++i) {
      const Panel p = node.tabs[static_cast<size_t>(i)];
      bool keep = true;
      const ImGuiTabItemFlags f = node.select && i == node.active ? ImGuiTabItemFlags_SetSelected : 0;
      const bool on = ImGui::BeginTabItem(panel_title(p), &keep, f);
      if (ImGui::BeginDragDropSource()) {
        const int payload = static_cast<int>(p);
        ImGui::SetDragDropPayload(kPayload, &payload, sizeof payload);
        ImGui::Text("Move %s", panel_title(p));
        ImGui::EndDragDropSource();
      }
      if (ImGui::BeginPopupContextItem("##tabmenu")) {
        if (ImGui::BeginMenu("Move to")) {
          for (int other : leaves) {
            if (other == r) continue;
            ImGui::PushID(other);
            if (ImGui::MenuItem(region_label(at(l, other)).c_str())) pending = {Pending::move, p, other};
            ImGui::PopID();
          }
          ImGui::EndMenu();
        }
        if (ImGui::MenuItem("Close")) pending = {Pending::close, p, -1};
        ImGui::EndPopup();
      }
      if (on) {
        // Until ImGui's tab bar shows the tab the layout wants in front, the layout decides; then a click does.
        if (node.select) agreed = i == node.active;
        else node.active = i;
        ImGui::EndTabItem();
      }
      if (!keep) pending = {Pending::close, p, -1};
    }
    if (agreed) node.select = false;
    ImGui::EndTabBar();
  }
  if (ImGui::BeginDragDropTargetCustom(region_rect, ImGui::GetID("##drop"))) {
    if (const ImGuiPayload* pl = ImGui::AcceptDragDropPayload(kPayload)) {
      pending = {Pending::move, static_cast<Panel>(*static_cast<const int*>(pl->Data)), r};
    }
    ImGui::EndDragDropTarget();
  }
  if (node.tabs.empty()) {
    ImGui::TextDisabled("Empty: drag a tab here, or open a panel from the View menu.");
  } else {
    const Panel p = node.tabs[static_cast<size_t>(std::clamp(node.active, 0, static_cast<int>(node.tabs.size()) - 1))];
    ImGui::BeginChild(panel_key(p), {0, 0}, false, ImGuiWindowFlags_AlwaysUseWindowPadding);
    draw(p);
    shown.emplace_back(ImGui::GetCurrentWindow(), p);
    ImGui::EndChild();
  }
  ImGui::EndChild();
  ImGui::PopID();
}

// Splitters: the gap between a split's two children, dragged to change the ratio.
void draw_splitters(Layout& l, const Sizes& sizes) {
  for (int sidx : splits(l)) {
    LayoutNode& node = at(l, sidx);
    const LayoutNode& a = at(l, node.first);
    const ImVec2 p0 = node.vertical ? ImVec2(node.pos.x, a.pos.y + a.size.y) : ImVec2(a.pos.x + a.size.x, node.pos.y);
    const ImVec2 sz = node.vertical ? ImVec2(node.size.x, sizes.gap) : ImVec2(sizes.gap, node.size.y);
    if (sz.x <= 0 || sz.y <= 0) continue;
    ImGui::SetCursorScreenPos(p0);
    ImGui::PushID(sidx);
    ImGui::InvisibleButton("##splitter", sz);
    ImGui::PopID();
    const bool hot = ImGui::IsItemHovered() || ImGui::IsItemActive();
    if (hot) ImGui::SetMouseCursor(node.vertical ? ImGuiMouseCursor_ResizeNS : ImGuiMouseCursor_ResizeEW);
    if (ImGui::IsItemActive()) {
      const float len = (node.vertical ? node.size.y : node.size.x) - sizes.gap;
      const float mouse = node.vertical ? ImGui::GetIO().MousePos.y - node.pos.y : ImGui::GetIO().MousePos.x - node.pos.x;
      if (len > 0) node.ratio = std::clamp((mouse - sizes.gap * 0.5f) / len, 0.05f, 0.95f);
    }
    ImGui::GetWindowDrawList()->AddRectFilled(p0, {p0.x + sz.x, p0.y + sz.y},
                                              ImGui::GetColorU32(hot ? ImGuiCol_SeparatorHovered : ImGuiCol_Separator));
  }
}

}  // namespace

void draw_workspace(Context& ctx, Workspaces& ws, ImVec2 pos, ImVec2 size, const std::function<void(Panel)>& draw,
                    LayoutAudit* audit) {
  View& view = ctx.view;
  follow_view(ws, view);

  const ImGuiWindowFlags host_flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                      ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus |
                                      ImGuiWindowFlags_NoScrollWithMouse | ImGuiWindowFlags_NoNavFocus |
                                      ImGuiWindowFlags_NoBackground;
  ImGui::SetNextWindowPos(pos);
  ImGui::SetNextWindowSize(size);
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, {0, 0});
  ImGui::PushStyleVar(ImGuiStyleVar_WindowRounding, 0);
  ImGui::Begin("##workspace", nullptr, host_flags);
  ImGui::PopStyleVar(2);
  switcher(ws, view);
  Layout& l = ws.now().layout(view.presentation);

  const float font = ImGui::GetFontSize();
  const Sizes sizes{std::round(font * 0.4f), {std::round(font * 11), std::round(font * 6)}};
  const float top = ImGui::GetCursorScreenPos().y;
  place(l, 0, {pos.x, top}, {size.x, pos.y + size.y - top}, sizes);

  Pending pending;
  std::vector<std::pair<ImGuiWindow*, Panel>> shown;
  const std::vector<int> leaves = regions(l);
  for (int r : leaves) draw_region(l, r, leaves, draw, pending, shown);
  draw_splitters(l, sizes);
  ImGui::End();

  // view.open keeps what panels changed in it this frame (applied at the next); a tab closed here is closed there.
  switch (pending.kind) {
    case Pending::move: move_panel(l, pending.panel, pending.to); break;
    case Pending::close:
      remove_panel(l, pending.panel);
      view.open[static_cast<size_t>(pending.panel)] = false;
      break;
    case Pending::none: break;
  }

  if (audit) audit_layout(l, leaves, shown, audit);
}

}  // namespace arwb::ui
