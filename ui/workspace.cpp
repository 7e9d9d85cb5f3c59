// [SECTION] Index
//   Shipped      the workspaces one per kind of user (add Calibrate and Lab here)
//   Tree         regions, finding, adding, moving and removing panels
//   File         workspaces.json, written and read back with every field checked
//   Drawing      the switcher row, regions as child windows, tab bars, splitters, drag and drop
//   Audit        regions overlapping, items and table cells cut off, from ImGui's own rectangles
#include "ui/workspace.hpp"

#include <imgui_internal.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <utility>

namespace arwb::ui {

// [SECTION] Shipped
Tile tabs(std::initializer_list<Panel> panels) {
  Tile t;
  t.node.tabs = panels;
  return t;
}

namespace {
Tile split(bool vertical, float ratio, Tile a, Tile b) {
  Tile t;
  t.node.split = true;
  t.node.vertical = vertical;
  t.node.ratio = ratio;
  t.kids = {std::move(a), std::move(b)};
  return t;
}

int add_tile(Layout& l, const Tile& t) {
  const int at = static_cast<int>(l.nodes.size());
  l.nodes.push_back(t.node);
  if (t.node.split) {
    const int a = add_tile(l, t.kids[0]);
    const int b = add_tile(l, t.kids[1]);
    l.nodes[static_cast<size_t>(at)].first = a;
    l.nodes[static_cast<size_t>(at)].second = b;
  }
  return at;
}
}  // namespace

Tile columns(float ratio, Tile left, Tile right) { return split(false, ratio, std::move(left), std::move(right)); }
Tile rows(float ratio, Tile top, Tile bottom) { return split(true, ratio, std::move(top), std::move(bottom)); }

Layout make_layout(const Tile& t) {
  Layout l;
  add_tile(l, t);
  return l;
}

std::vector<Workspace> shipped_workspaces() {
  using P = Panel;
  auto ws = [](const char* name, const Tile& normal, const Tile& presentation) {
    return Workspace{name, true, make_layout(normal), make_layout(presentation)};
  };
  return {
      // Someone tuning the detector: the image and its stages, the ledger, one candidate, the knobs.
      ws("Inspect",
         columns(0.46f, rows(0.62f, tabs({P::live_view}), tabs({P::pipeline})),
                 columns(0.5f, rows(0.48f, tabs({P::candidates, P::log}), tabs({P::inspector, P::why, P::dictionary})),
                         rows(0.58f, tabs({P::parameters, P::source}), tabs({P::timings, P::peers})))),
         columns(0.6f, rows(0.6f, tabs({P::live_view}), tabs({P::pipeline})),
                 rows(0.5f, tabs({P::candidates, P::inspector, P::why}),
                      tabs({P::parameters, P::source, P::timings, P::log})))),
      // Someone writing a scene: the augmented view, the editor, what the scene did and printed.
      ws("Script",
         columns(0.48f, rows(0.6f, tabs({P::live_view}), tabs({P::scene, P::pose})),
                 rows(0.66f, tabs({P::script}), tabs({P::console, P::log}))),
         columns(0.58f, rows(0.68f, tabs({P::live_view}), tabs({P::scene, P::console, P::pose, P::log})),
                 tabs({P::script}))),
      // A teacher: the frame and the stage being explained, large, and the tour beside them; in front of a class
      // the two pictures side by side (4:3 pictures use a wide screen better so) and the tour's text under them.
      ws("Teach",
         columns(0.7f, rows(0.6f, tabs({P::live_view}), tabs({P::pipeline})),
                 tabs({P::tour, P::inspector, P::candidates, P::pose})),
         rows(0.62f, columns(0.5f, tabs({P::live_view}), tabs({P::pipeline})), tabs({P::tour, P::inspector, P::pose}))),
      // Someone calibrating a camera: the board as found, the coach (checklist, coverage, the camera and its
      // uncertainty) beside it, the views and where the result can be trusted under it; in front of a class the
      // live view large and the coach beside it.
      ws("Calibrate",
         columns(0.56f, rows(0.64f, tabs({P::live_view}), tabs({P::calibration_views, P::log})),
                 tabs({P::calibrate, P::source})),
         columns(0.6f, tabs({P::live_view}), rows(0.62f, tabs({P::calibrate}), tabs({P::calibration_views, P::source})))),
      // Someone running the paper's experiment: the plan and the grid filling in beside the live view, which shows
      // a clicked cell's frames; under it the question a failed cell raises (why not detected, which candidate,
      // which stage) and the frame's pipeline.
      ws("Lab",
         columns(0.5f, rows(0.6f, tabs({P::live_view}), tabs({P::why, P::inspector, P::pipeline, P::log})),
                 tabs({P::lab, P::candidates, P::parameters, P::source})),
         columns(0.62f, rows(0.64f, tabs({P::live_view}), tabs({P::why, P::inspector, P::pipeline})),
                 tabs({P::lab, P::candidates}))),
  };
}

// [SECTION] Tree
namespace {
void collect(const Layout& l, int n, std::vector<int>* leaves, std::vector<int>* splits_out) {
  if (n < 0 || n >= static_cast<int>(l.nodes.size())) return;
  const LayoutNode& node = l.nodes[static_cast<size_t>(n)];
  if (node.split) {
    if (splits_out) splits_out->push_back(n);
    collect(l, node.first, leaves, splits_out);
    collect(l, node.second, leaves, splits_out);
  } else if (leaves) {
    leaves->push_back(n);
  }
}

LayoutNode& at(Layout& l, int n) { return l.nodes[static_cast<size_t>(n)]; }
const LayoutNode& at(const Layout& l, int n) { return l.nodes[static_cast<size_t>(n)]; }

int parent_of(const Layout& l, int n) {
  std::vector<int> s;
  collect(l, 0, nullptr, &s);
  for (int p : s)
    if (at(l, p).first == n || at(l, p).second == n) return p;
  return -1;
}

void mark_all_select(Layout& l) {
  for (LayoutNode& n : l.nodes) n.select = true;
}
}  // namespace

std::vector<int> regions(const Layout& l) {
  std::vector<int> out;
  collect(l, 0, &out, nullptr);
  return out;
}

std::vector<int> splits(const Layout& l) {
  std::vector<int> out;
  collect(l, 0, nullptr, &out);
  return out;
}

int region_of(const Layout& l, Panel p) {
  for (int r : regions(l)) {
    const auto& t = at(l, r).tabs;
    if (std::find(t.begin(), t.end(), p) != t.end()) return r;
  }
  return -1;
}

int region_for(const Layout& l, const Layout* shipped, Panel p) {
  if (shipped) {
    // A panel it shares a region with in the shipped layout, if that one is here.
    const int home = region_of(*shipped, p);
    if (home >= 0) {
      for (Panel q : at(*shipped, home).tabs) {
        if (q == p) continue;
        const int r = region_of(l, q);
        if (r >= 0) return r;
      }
    }
  }
  int best = -1;
  float best_area = -1;
  for (int r : regions(l)) {
    const LayoutNode& n = at(l, r);
    if (std::find(n.tabs.begin(), n.tabs.end(), Panel::live_view) != n.tabs.end()) continue;
    const float area = n.size.x * n.size.y + static_cast<float>(n.tabs.size()) * 1e-3f;   // before the first draw: any
    if (area > best_area) best = r, best_area = area;
  }
  return best >= 0 ? best : regions(l).front();
}

void bring_to_front(Layout& l, const Layout* shipped, Panel p) {
  int r = region_of(l, p);
  if (r < 0) {
    r = region_for(l, shipped, p);
    at(l, r).tabs.push_back(p);
  }
  LayoutNode& n = at(l, r);
  n.active = static_cast<int>(std::find(n.tabs.begin(), n.tabs.end(), p) - n.tabs.begin());
  n.select = true;
}

void remove_panel(Layout& l, Panel p) {
  const int r = region_of(l, p);
  if (r < 0) return;
  auto& t = at(l, r).tabs;
  const int i = static_cast<int>(std::find(t.begin(), t.end(), p) - t.begin());
  t.erase(t.begin() + i);
  LayoutNode& n = at(l, r);
  if (n.active > i || n.active >= static_cast<int>(t.size())) n.active = std::max(0, n.active - 1);
  n.select = true;
  if (!t.empty()) return;
  const int parent = parent_of(l, r);
  if (parent < 0) return;   // the root region stays, empty
  const int sibling = at(l, parent).first == r ? at(l, parent).second : at(l, parent).first;
  const LayoutNode keep = at(l, sibling);
  at(l, parent) = keep;   // the sibling takes the parent's place; its old slot and the empty region are garbage now
  mark_all_select(l);
}

void move_panel(Layout& l, Panel p, int to) {
  const int from = region_of(l, p);
  if (from == to || to < 0 || to >= static_cast<int>(l.nodes.size()) || at(l, to).split) return;
  // Added first, then removed: removing may fold the source region, which moves nodes but never the target's content.
  if (from >= 0) {
    auto& t = at(l, from).tabs;
    t.erase(std::find(t.begin(), t.end(), p));
    at(l, from).active = std::min(at(l, from).active, std::max(0, static_cast<int>(t.size()) - 1));
  }
  at(l, to).tabs.push_back(p);
  at(l, to).active = static_cast<int>(at(l, to).tabs.size()) - 1;
  mark_all_select(l);
  if (from >= 0 && at(l, from).tabs.empty()) {
    const int parent = parent_of(l, from);
    if (parent >= 0) {
      const int sibling = at(l, parent).first == from ? at(l, parent).second : at(l, parent).first;
      const LayoutNode keep = at(l, sibling);
      at(l, parent) = keep;
    }
  }
}

Workspaces::Workspaces() : list(shipped_workspaces()) {}

const Workspace* Workspaces::shipped(const std::string& name) const {
  static const std::vector<Workspace> kShipped = shipped_workspaces();
  for (const Workspace& w : kShipped)
    if (w.name == name) return &w;
  return nullptr;
}

int Workspaces::find(const std::string& name) const {
  for (size_t i = 0; i < list.size(); ++i)
    if (list[i].name == name) return static_cast<int>(i);
  return -1;
}

bool Workspaces::save_as(const std::string& name, std::string* error) {
  if (name.empty() || name.size() > 40) {
    *error = "a workspace's name has 1 to 40 characters";
    return false;
  }
  if (shipped(name)) {
    *error = "'" + name + "' is a shipped workspace; choose another name";
    return false;
  }
  Workspace w = now();
  w.name = name;
  w.shipped = false;
  const int i = find(name);
  if (i >= 0) list[static_cast<size_t>(i)] = std::move(w);
  else list.push_back(std::move(w));
  current = find(name);
  select = true;
  shown = current;   // the same arrangement, under its new name: view.open stays as it is
  return true;
}

// [SECTION] File
namespace {
using Json = nlohmann::ordered_json;

Json tree_json(const Layout& l, int n) {
  const LayoutNode& node = at(l, n);
  if (node.split) {
    return Json{{"split", node.vertical ? "rows" : "columns"},
                {"ratio", std::round(node.ratio * 1000) / 1000},
                {"first", tree_json(l, node.first)},
                {"second", tree_json(l, node.second)}};
  }
  Json t = Json::array();
  for (Panel p : node.tabs) t.push_back(panel_key(p));
  return Json{{"tabs", t}, {"active", node.active}};
}

// Reads a TREE into `l`; a panel named twice keeps its first place. Throws std::runtime_error naming the problem.
int tree_from(const Json& j, Layout& l, std::array<bool, kPanelCount>& seen, int depth) {
  if (depth > 12) throw std::runtime_error("splits nested deeper than 12");
  if (!j.is_object()) throw std::runtime_error("a layout node is not an object");
  const int me = static_cast<int>(l.nodes.size());
  l.nodes.emplace_back();
  if (j.contains("split")) {
    const Json& s = j["split"];
    if (!s.is_string() || (s != "rows" && s != "columns")) throw std::runtime_error("\"split\" is not rows or columns");
    if (!j.contains("ratio") || !j["ratio"].is_number()) throw std::runtime_error("a split has no numeric \"ratio\"");
    const double ratio = j["ratio"].get<double>();
    if (!(ratio >= 0.05 && ratio <= 0.95)) throw std::runtime_error("a split's ratio is outside 0.05..0.95");
    if (!j.contains("first") || !j.contains("second")) throw std::runtime_error("a split lacks \"first\" or \"second\"");
    const int a = tree_from(j["first"], l, seen, depth + 1);
    const int b = tree_from(j["second"], l, seen, depth + 1);
    LayoutNode& n = at(l, me);
    n.split = true;
    n.vertical = s == "rows";
    n.ratio = static_cast<float>(ratio);
    n.first = a;
    n.second = b;
    return me;
  }
  if (!j.contains("tabs") || !j["tabs"].is_array()) throw std::runtime_error("a region has no \"tabs\" list");
  std::vector<Panel> t;
  for (const Json& k : j["tabs"]) {
    Panel p;
    if (!k.is_string() || !panel_from_key(k.get<std::string>(), &p)) {
      throw std::runtime_error("no panel " + k.dump());
    }
    if (seen[static_cast<size_t>(p)]) continue;
    seen[static_cast<size_t>(p)] = true;
    t.push_back(p);
  }
  LayoutNode& n = at(l, me);
  n.tabs = std::move(t);
  const int active = j.contains("active") && j["active"].is_number_integer() ? j["active"].get<int>() : 0;
  n.active = std::clamp(active, 0, std::max(0, static_cast<int>(n.tabs.size()) - 1));
  return me;
}

Layout layout_from(const Json& j) {
  Layout l;
  std::array<bool, kPanelCount> seen{};
  tree_from(j, l, seen, 0);
  return l;
}
}  // namespace

std::string workspaces_to_json(const Workspaces& w) {
  Json list = Json::array();
  for (const Workspace& s : w.list) {
    list.push_back({{"name", s.name}, {"normal", tree_json(s.normal, 0)}, {"presentation", tree_json(s.presentation, 0)}});
  }
  const Json j = {{"version", 1}, {"current", w.list[static_cast<size_t>(w.current)].name}, {"workspaces", list}};
  return j.dump(1) + "\n";
}

bool workspaces_from_json(const std::string& text, Workspaces* out, std::string* error) {
  try {
    const Json j = Json::parse(text);
    if (!j.is_object() || !j.contains("workspaces") || !j["workspaces"].is_array()) {
      throw std::runtime_error("no \"workspaces\" list");
    }
    if (!j.contains("version") || j["version"] != 1) throw std::runtime_error("\"version\" is not 1");
    Workspaces w;
    for (const Json& s : j["workspaces"]) {
      if (!s.is_object() || !s.contains("name") || !s["name"].is_string()) {
        throw std::runtime_error("a workspace has no \"name\"");
      }
      const std::string name = s["name"].get<std::string>();
      if (name.empty() || name.size() > 40) throw std::runtime_error("a workspace's name is empty or over 40 characters");
      if (!s.contains("normal") || !s.contains("presentation")) {
        throw std::runtime_error("workspace '" + name + "' lacks \"normal\" or \"presentation\"");
      }
      Workspace ws{name, w.shipped(name) != nullptr, {}, {}};
      try {
        ws.normal = layout_from(s["normal"]);
        ws.presentation = layout_from(s["presentation"]);
      } catch (const std::runtime_error& e) {
        throw std::runtime_error("workspace '" + name + "': " + e.what());
      }
      const int i = w.find(name);
      if (i >= 0) w.list[static_cast<size_t>(i)] = std::move(ws);
      else if (w.list.size() < 32) w.list.push_back(std::move(ws));
    }
    if (j.contains("current") && j["current"].is_string()) w.current = std::max(0, w.find(j["current"].get<std::string>()));
    *out = std::move(w);
    return true;
  } catch (const std::exception& e) {   // nlohmann's parse and type errors, and ours
    *error = e.what();
    return false;
  }
}

// [SECTION] Drawing
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

void audit_windows_and_tables(const std::vector<std::pair<ImGuiWindow*, Panel>>& shown, LayoutAudit* audit);
}  // namespace

namespace {
// What menus, actions and panels changed in view.open since it last mirrored layout `l`: panels opened are added
// (beside the ones they sit with in the shipped layout `shipped`), panels closed removed.
void apply_open(Layout& l, const Layout* shipped, const View& view) {
  for (int i = 0; i < kPanelCount; ++i) {
    const Panel p = static_cast<Panel>(i);
    const bool here = region_of(l, p) >= 0;
    if (view.open[static_cast<size_t>(i)] && !here) bring_to_front(l, shipped, p);
    if (!view.open[static_cast<size_t>(i)] && here) remove_panel(l, p);
  }
}

const Layout* shipped_layout(const Workspaces& ws, int i, bool present) {
  const Workspace* home = ws.shipped(ws.list[static_cast<size_t>(i)].name);
  return home ? &home->layout(present) : nullptr;
}
}  // namespace

void switch_workspace(Workspaces& ws, int i, View& view) {
  // view.open mirrors the arrangement shown last; what changed in it since belongs there, before it goes.
  if (ws.shown >= 0 && ws.shown < static_cast<int>(ws.list.size())) {
    apply_open(ws.list[static_cast<size_t>(ws.shown)].layout(ws.shown_presentation),
               shipped_layout(ws, ws.shown, ws.shown_presentation), view);
  }
  ws.current = std::clamp(i, 0, static_cast<int>(ws.list.size()) - 1);
  ws.select = true;
  mark_all_select(ws.now().layout(view.presentation));
  show_workspace(ws, view);
  ws.shown = ws.current;
  ws.shown_presentation = view.presentation;
}

void show_workspace(const Workspaces& ws, View& view) {
  const Layout& l = ws.list[static_cast<size_t>(ws.current)].layout(view.presentation);
  for (int i = 0; i < kPanelCount; ++i) view.open[static_cast<size_t>(i)] = region_of(l, static_cast<Panel>(i)) >= 0;
}

void draw_workspace(Context& ctx, Workspaces& ws, ImVec2 pos, ImVec2 size, const std::function<void(Panel)>& draw,
                    LayoutAudit* audit) {
  View& view = ctx.view;
  // What the menus, actions and panels asked for since the last frame: panels opened or closed, one brought up.
  if (ws.shown != ws.current || ws.shown_presentation != view.presentation) switch_workspace(ws, ws.current, view);
  {
    Layout& l = ws.now().layout(view.presentation);
    const Layout* shipped = shipped_layout(ws, ws.current, view.presentation);
    apply_open(l, shipped, view);
    if (view.front != Panel::count) bring_to_front(l, shipped, view.front);
    view.front = Panel::count;
    show_workspace(ws, view);
  }

  const ImGuiWindowFlags host_flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                      ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus |
                                      ImGuiWindowFlags_NoScrollWithMouse | ImGuiWindowFlags_NoNavFocus;
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
  for (int r : leaves) {
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

  if (!audit) return;
  audit->regions.clear();
  audit->overlaps = 0;
  for (int r : leaves) {
    const LayoutNode& n = at(l, r);
    const int front = std::clamp(n.active, 0, std::max(0, static_cast<int>(n.tabs.size()) - 1));
    LayoutAudit::Region reg{n.tabs, n.tabs.empty() ? Panel::count : n.tabs[static_cast<size_t>(front)], n.pos, n.size};
    for (const LayoutAudit::Region& o : audit->regions) {
      const float w = std::min(o.pos.x + o.size.x, reg.pos.x + reg.size.x) - std::max(o.pos.x, reg.pos.x);
      const float h = std::min(o.pos.y + o.size.y, reg.pos.y + reg.size.y) - std::max(o.pos.y, reg.pos.y);
      if (w > 0 && h > 0) ++audit->overlaps;
    }
    audit->regions.push_back(std::move(reg));
  }
  audit_windows_and_tables(shown, audit);
}

// [SECTION] Audit
namespace {
// The panel whose content window `w` is or lies in; Panel::count when none.
Panel panel_of(ImGuiWindow* w, const std::vector<std::pair<ImGuiWindow*, Panel>>& shown) {
  for (; w; w = w->ParentWindow) {
    for (const auto& s : shown)
      if (s.first == w) return s.second;
    if (!(w->Flags & ImGuiWindowFlags_ChildWindow)) break;
  }
  return Panel::count;
}

std::string window_what(const ImGuiWindow* w, const char* side, float by) {
  const char* name = std::strrchr(w->Name, '/');
  char buf[160];
  std::snprintf(buf, sizeof buf, "window %s: content %.0f px past its %s edge", name ? name + 1 : w->Name, by, side);
  return buf;
}

// The part of an entry that names what is cut ("table column 'parameter'"), without by how much.
std::string_view cut_item(std::string_view what) { return what.substr(0, what.find(':')); }

void audit_windows_and_tables(const std::vector<std::pair<ImGuiWindow*, Panel>>& shown, LayoutAudit* audit) {
  ImGuiContext& g = *ImGui::GetCurrentContext();
  std::array<bool, kPanelCount> settled{};
  std::array<std::vector<std::string>, kPanelCount> now;   // this frame's entries
  for (int i = 0; i < kPanelCount; ++i) {
    const bool drawn = std::any_of(shown.begin(), shown.end(), [i](const auto& s) { return static_cast<int>(s.second) == i; });
    int& n = audit->drawn_in_a_row[static_cast<size_t>(i)];
    n = drawn ? n + 1 : 0;
    settled[static_cast<size_t>(i)] = n >= 3;
    if (!settled[static_cast<size_t>(i)]) audit->last_frame[static_cast<size_t>(i)].clear();
  }
  for (ImGuiWindow* w : g.Windows) {
    if (!w->Active || w->Hidden) continue;
    const Panel p = panel_of(w, shown);
    if (p == Panel::count || !settled[static_cast<size_t>(p)]) continue;
    auto& out = now[static_cast<size_t>(p)];
    // Sideways: cut off unless the window scrolls sideways. Downwards: only a window without a scrollbar cuts.
    // Against the window's own inner rectangle, not its clip rectangle: a child scrolled out of its parent's view
    // is the parent's scrolling (the parent's own overflow is checked on the parent).
    const ImRect& clip = w->InnerRect;
    // A nested child may reach its padding: ImGui's InputTextMultiline sizes its own child's content a frame
    // padding past its edge (1.86) with nothing drawn there.
    const bool content = std::any_of(shown.begin(), shown.end(), [w](const auto& s) { return s.first == w; });
    const float tolerance = content ? 1.0f : std::max(w->WindowPadding.x, ImGui::GetStyle().FramePadding.x) + 0.5f;
    const float right = w->DC.CursorMaxPos.x - clip.Max.x;
    if (!(w->Flags & ImGuiWindowFlags_HorizontalScrollbar) && !w->ScrollbarX && right > tolerance) {
      out.push_back(window_what(w, "right", right));
    }
    const float below = w->DC.CursorMaxPos.y - clip.Max.y;
    if ((w->Flags & ImGuiWindowFlags_NoScrollbar) && !w->ScrollbarY && below > 1) {
      out.push_back(window_what(w, "bottom", below));
    }
  }
  for (int i = 0; i < g.Tables.GetMapSize(); ++i) {
    ImGuiTable* t = g.Tables.TryGetMapData(i);
    if (!t || t->LastFrameActive != g.FrameCount) continue;
    const Panel p = panel_of(t->OuterWindow, shown);
    if (p == Panel::count || !settled[static_cast<size_t>(p)]) continue;
    const bool scroll_x = (t->Flags & ImGuiTableFlags_ScrollX) != 0;
    // A table that scrolls downwards but has no room for a row under its header shows nothing (the Candidates
    // ledger in presentation mode once did).
    if (t->Flags & ImGuiTableFlags_ScrollY) {
      const float row = ImGui::GetTextLineHeight() + g.Style.CellPadding.y * 2;
      const float need = row * 2 + (scroll_x ? g.Style.ScrollbarSize : 0.0f);
      if (t->OuterRect.GetHeight() < need) {
        char buf[120];
        std::snprintf(buf, sizeof buf, "table: %.0f px high, no room for a row under its header", t->OuterRect.GetHeight());
        now[static_cast<size_t>(p)].push_back(buf);
      }
    }
    for (int c = 0; c < t->ColumnsCount; ++c) {
      const ImGuiTableColumn& col = t->Columns[c];
      if (!col.IsEnabled) continue;
      const float content = std::max(col.ContentMaxXFrozen, col.ContentMaxXUnfrozen);
      // A table that scrolls sideways shows a column whole when scrolled to; else what passes the table's edge is lost.
      const float edge = scroll_x ? col.MaxX : col.ClipRect.Max.x;
      const char* name = t->ColumnsNames.Buf.Size && col.NameOffset >= 0 ? t->ColumnsNames.c_str() + col.NameOffset : "";
      char buf[200];
      if (content > edge + 1) {
        std::snprintf(buf, sizeof buf, "table column '%s': content %.0f px past its edge", name, content - edge);
        now[static_cast<size_t>(p)].push_back(buf);
      } else if (col.ContentMaxXHeadersIdeal > edge + 1) {
        std::snprintf(buf, sizeof buf, "table column '%s': header %.0f px past its edge", name,
                      col.ContentMaxXHeadersIdeal - edge);
        now[static_cast<size_t>(p)].push_back(buf);
      }
    }
  }
  // Reported: what is cut in this frame and was in the one before. A table's columns fit new content a frame
  // after it appears (a longer parameter name in a new row), which no one sees; what stays cut is a fault.
  for (size_t i = 0; i < now.size(); ++i) {
    if (!settled[i]) continue;
    std::vector<std::string>& out = audit->clipped[i];
    out.clear();
    for (const std::string& w : now[i]) {
      const auto& last = audit->last_frame[i];
      if (std::any_of(last.begin(), last.end(), [&](const std::string& l) { return cut_item(l) == cut_item(w); })) {
        out.push_back(w);
      }
    }
    audit->last_frame[i] = std::move(now[i]);
  }
}
}  // namespace

}  // namespace arwb::ui
