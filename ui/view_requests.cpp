// What the window shows, as asked by a menu, a key or a script: panels opened and closed, workspaces switched and
// rearranged, the tour, the selection, the live view's labels and 3D, a click on it, the field that types.
#include "ui/app.hpp"

#include "base/decimals.hpp"

#include <algorithm>

namespace arwb {

void App::set_panel_open(const ui::SetPanelOpen& r) {
  if (!r.panel) return view.open.fill(r.open);
  view.open[static_cast<size_t>(*r.panel)] = r.open;
  if (r.open) view.front = *r.panel;   // the active tab of its region in the current workspace
}

void App::switch_workspace(const std::string& name) {
  const int i = workspaces.find(name);
  if (i < 0) return warn("--actions: no workspace '" + name + "'");
  ui::switch_workspace(workspaces, i, view);
}

void App::move_panel(const ui::MovePanel& r) {
  ui::Layout& l = workspaces.now().layout(view.presentation);
  const int region = ui::region_of(l, r.beside);
  if (region < 0) {
    return warn(std::string("--actions: move wants PANEL>PANEL_IN_THE_TARGET_REGION, not '") + ui::panel_key(r.panel) +
                ">" + ui::panel_key(r.beside) + "'");
  }
  ui::move_panel(l, r.panel, region);
  view.open[static_cast<size_t>(r.panel)] = true;   // a panel moved in from nowhere is open now
}

void App::set_splitter(const ui::SetSplitter& r) {
  ui::Layout& l = workspaces.now().layout(view.presentation);
  const std::vector<int> s = ui::splits(l);
  if (r.index >= static_cast<int>(s.size())) {
    return warn("--actions: splitter wants I,RATIO (I < " + std::to_string(s.size()) + ", RATIO in 0.05..0.95), not '" +
                std::to_string(r.index) + "," + decimals_text(r.ratio, 3) + "'");
  }
  l.nodes[static_cast<size_t>(s[static_cast<size_t>(r.index)])].ratio = r.ratio;
}

void App::start_tour(const std::string& step) {
  view.tour_active = true;
  settings.frozen = true;   // a lesson explains one frame; "Next frame" moves on
  view.show(ui::Panel::tour);
  if (step.empty()) return;
  const int n = static_cast<int>(tour.size());
  for (int i = 0; i < n; ++i)
    if (tour[size_t(i)].key == step) {
      view.tour_step = i;
      return;
    }
  if (step.find_first_not_of("0123456789") == std::string::npos && step.size() < 6) {
    if (const int i = std::stoi(step); i < n) {
      view.tour_step = i;
      return;
    }
    return warn("tour=" + step + (n == 0 ? std::string(": the tour has no steps")
                                         : ": the tour has " + std::to_string(n) + " steps, 0 to " + std::to_string(n - 1)));
  }
  std::string names;
  for (const TourStep& s : tour) names += (names.empty() ? "" : ", ") + s.key;
  warn("tour=" + step + ": no step of that name; the steps are " + names);
}

void App::select_candidate(std::optional<int> index) {
  view.selected_candidate = index.value_or(0);
  if (!index && frame) {   // the candidate that became the frame's first marker
    view.selected_candidate = -1;
    for (size_t i = 0; i < frame->trace.candidates.size(); ++i) {
      if (frame->trace.candidates[i].marker == 0) view.selected_candidate = static_cast<int>(i);
    }
  }
  if (view.selected_candidate >= 0) view.show(ui::Panel::inspector);
}

void App::set_labels(const ui::SetLabels& r) {
  view.label_ids = r.ids;
  view.label_dict = r.dictionary;
  view.show_rejected = r.rejected;
  view.show_truth = r.truth;
  view.show_peer_opencv = view.show_peer_apriltag = r.peers;
}

void App::set_pose_drawing(const ui::SetPoseDrawing& r) {
  view.show_axes = r.axes;
  view.show_cube = r.cube;
  view.show_alternative = r.alternative;
}

// What a user's click on a web card does.
void App::click_live_view(cv::Point2d at) {
  const int hit = frame ? overlay_at(frame->overlays, at, true) : -1;
  if (hit >= 0) return carry_out(ui::OpenUrl{frame->overlays[size_t(hit)].media.url});
  info("click " + decimals_text(at.x, 3) + "," + decimals_text(at.y, 3) + ": no web card there");
}

void App::focus(ui::TextField field) {
  view.focus_field = field;
  if (field == ui::TextField::script) view.show(ui::Panel::script);
  if (field == ui::TextField::source_path) view.show(ui::Panel::source);
  if (field == ui::TextField::preset_path) view.show(ui::Panel::parameters);
}

// What the Why panel's "Add ... to the searched dictionaries" button does.
void App::add_dictionary(const std::string& name) {
  if (std::find(settings.dictionaries.begin(), settings.dictionaries.end(), name) == settings.dictionaries.end())
    settings.dictionaries.push_back(name);
}

}  // namespace arwb
