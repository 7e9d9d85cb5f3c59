// The tiling as data (ui/workspace_tree.hpp): no ImGui call here.
// [SECTION] Index
//   Shipped      the workspaces one per kind of user (add Calibrate and Lab here)
//   Tree         regions, finding, adding, moving and removing panels
//   File         workspaces.json, written and read back with every field checked
//   View         view.open and view.front followed, workspaces switched
#include "ui/workspace_tree.hpp"

#include "base/json_depth.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
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
      throw std::runtime_error("no panel " + json_text(k));
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
  return json_text(j, 1) + "\n";
}

bool workspaces_from_json(const std::string& text, Workspaces* out, std::string* error) {
  if (arwb::Status depth = check_json_depth(text, ""); !depth) {
    *error = depth.error();
    return false;
  }
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
// [SECTION] View

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

void follow_view(Workspaces& ws, View& view) {
  if (ws.shown != ws.current || ws.shown_presentation != view.presentation) switch_workspace(ws, ws.current, view);
  Layout& l = ws.now().layout(view.presentation);
  const Layout* shipped = shipped_layout(ws, ws.current, view.presentation);
  apply_open(l, shipped, view);
  if (view.front != Panel::count) bring_to_front(l, shipped, view.front);
  view.front = Panel::count;
  show_workspace(ws, view);
}

}  // namespace arwb::ui
