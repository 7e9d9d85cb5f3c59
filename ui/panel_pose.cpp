// Pose: each tracked marker's 3D pose as numbers and over time. The camera it was computed with (a calibration,
// or the paper's default values, said plainly), then per marker its position and distance in the unit of the
// marker side, its angles, the error of the solution used and of the other one, and the ambiguity ratio as a bar
// that fills towards "cannot tell"; the selected marker's distance, ambiguity and both errors as plots of the
// last frames. A marker seen nearly from the front fits two poses: the panel shows how close they are and when
// the previous frame chose between them. The live view's "Labels..." menu draws both cubes.
#include "pose/marker_pose.hpp"
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace arwb::ui {

namespace {

struct PoseState : PanelState {
  uint64_t selected = 0;   // a track id; 0: the first with a pose
};

// "7", or "7#2" for the second marker of id 7 in view.
std::string track_name(const TrackedMarker& t) {
  char text[32];
  if (t.instance > 0) std::snprintf(text, sizeof text, "%d#%d", t.id, t.instance + 1);
  else std::snprintf(text, sizeof text, "%d", t.id);
  return text;
}

void plot(const char* label, const std::deque<PoseSample>& h, float PoseSample::*field, float lo, float hi,
          float height) {
  std::vector<float> v;
  v.reserve(h.size());
  for (const PoseSample& s : h) v.push_back(s.*field);
  char overlay[64];
  std::snprintf(overlay, sizeof overlay, "%s %.3g", label, v.empty() ? 0.0 : static_cast<double>(v.back()));
  const std::string id = std::string("##") + label;
  ImGui::PlotLines(id.c_str(), v.data(), static_cast<int>(v.size()), 0, overlay, lo, hi,
                   ImVec2(ImGui::GetContentRegionAvail().x, height));
}

}  // namespace

void draw_pose(Context& ctx) {
  if (waiting_for_frame(ctx)) return;
  const Frame& f = *ctx.frame;
  PoseState& st = panel_state<PoseState>(ctx.view, Panel::pose);
  if (f.pose_camera.assumed) {
    ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 220, 60, 255));
    ImGui::TextWrapped("Camera: assumed (%s). No calibration is loaded: positions and angles are the paper's "
                       "default values' guess. Load one with --calib or calibrate in the Calibrate workspace.",
                       f.pose_camera.source.c_str());
    ImGui::PopStyleColor();
  } else {
    ImGui::TextWrapped("Camera: %s", f.pose_camera.source.c_str());
  }
  // The printed size: positions in its unit. Sent to the worker when it changes (window.cpp); 0 goes back to
  // marker sides.
  ImGui::SetNextItemWidth(ImGui::GetFontSize() * 7);
  double size = ctx.settings.marker_size;
  if (ImGui::InputDouble("marker side", &size, 0, 0, "%.4g", ImGuiInputTextFlags_EnterReturnsTrue) &&
      std::isfinite(size))
    ctx.settings.marker_size = std::clamp(size, 0.0, 1e6);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("The printed marker's side measured on its outer black edge, in the unit you want positions\n"
                      "in (mm, cm, m); Enter applies it. 0: positions in marker sides. Lua's m.pose follows it.");
  text_disabled_wrapped(f.pose_marker_side != 1 ? "Positions in the unit of the marker side above; x right, y down, z "
                                                  "away from the camera."
                                                : "Positions in marker sides; x right, y down, z away from the camera.");
  std::vector<const TrackedMarker*> with;
  for (const TrackedMarker& t : f.tracks)
    if (t.pose) with.push_back(&t);
  if (with.empty()) {
    text_disabled_wrapped(f.tracks.empty() ? "No marker in view: a pose needs a detected marker."
                                           : "The markers in view have no pose (their corners gave none).");
    return;
  }
  const TrackedMarker* sel = with.front();
  for (const TrackedMarker* t : with)
    if (t->track_id == st.selected) sel = t;
  st.selected = sel->track_id;

  const ImGuiTableFlags tf = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_SizingFixedFit |
                             ImGuiTableFlags_ScrollX | ImGuiTableFlags_ScrollY;
  if (ImGui::BeginTable("poses", 9, tf, scroll_table_size(static_cast<int>(with.size()) + 1))) {
    for (const char* h : {"marker", "x", "y", "z", "distance", "tilt", "error px", "other px", "ambiguity"})
      ImGui::TableSetupColumn(h, std::string(h) == "ambiguity" ? ImGuiTableColumnFlags_WidthStretch : 0);
    ImGui::TableSetupScrollFreeze(1, 1);
    ImGui::TableHeadersRow();
    for (const TrackedMarker* t : with) {
      const MarkerPose& p = *t->pose;
      const PoseAngles a = pose_angles(p.pose);
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      if (ImGui::Selectable(track_name(*t).c_str(), t == sel, ImGuiSelectableFlags_SpanAllColumns))
        st.selected = t->track_id;
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip("yaw %.1f, pitch %.1f, roll %.1f degrees%s", a.yaw_deg, a.pitch_deg, a.roll_deg,
                          t->detected ? "" : "\n(held: not detected on this frame)");
      for (double x : {p.pose.tvec[0], p.pose.tvec[1], p.pose.tvec[2], a.distance}) {
        ImGui::TableNextColumn();
        ImGui::Text("%.3g", x);
      }
      ImGui::TableNextColumn();
      ImGui::Text("%.1f", a.tilt_deg);
      ImGui::TableNextColumn();
      ImGui::Text("%.2f", p.pose.error_px);
      ImGui::TableNextColumn();
      ImGui::Text("%.2f", p.alternative.error_px);
      ImGui::TableNextColumn();
      char text[48];
      std::snprintf(text, sizeof text, "%.2f%s", p.ambiguity, p.chosen_by_previous ? " kept by the last frame" : "");
      ImGui::PushStyleColor(ImGuiCol_PlotHistogram, p.ambiguity >= 0.3 ? IM_COL32(255, 200, 60, 220)
                                                                       : IM_COL32(80, 200, 120, 220));
      ImGui::ProgressBar(static_cast<float>(p.ambiguity), {-FLT_MIN, ImGui::GetTextLineHeight()}, text);
      ImGui::PopStyleColor();
    }
    ImGui::EndTable();
  }
  const MarkerPose& p = *sel->pose;
  const PoseAngles a = pose_angles(p.pose);
  ImGui::Separator();
  ImGui::PushTextWrapPos(0.0f);
  ImGui::Text("Marker %s: distance %.3g, tilt %.1f, yaw %.1f, pitch %.1f, roll %.1f degrees", track_name(*sel).c_str(),
              a.distance, a.tilt_deg, a.yaw_deg, a.pitch_deg, a.roll_deg);
  if (p.ambiguity >= 0.3)
    ImGui::TextColored(ImVec4(1, 0.86f, 0.24f, 1),
                       "Ambiguous: the other pose (tilted the other way) explains the corners almost as well "
                       "(%.2f px against %.2f px). %s",
                       p.alternative.error_px, p.pose.error_px,
                       p.chosen_by_previous ? "The previous frame's pose chose the one used."
                                            : "The one with the lower error is used.");
  else
    ImGui::TextDisabled("Clear: the other pose's error is %.1f times this one's.",
                        p.pose.error_px > 0 ? p.alternative.error_px / p.pose.error_px : 0.0);
  ImGui::PopTextWrapPos();
  const auto it = ctx.status.pose_history.find(sel->track_id);
  if (it == ctx.status.pose_history.end() || it->second.size() < 2) return;
  const std::deque<PoseSample>& h = it->second;
  const float height = 48.0f * ctx.scale;
  float dmax = 0, emax = 0;
  for (const PoseSample& s : h) {
    dmax = std::max(dmax, s.distance);
    emax = std::max({emax, s.error_px, s.alternative_error_px});
  }
  plot("distance", h, &PoseSample::distance, 0, dmax * 1.1f + 1e-6f, height);
  plot("ambiguity", h, &PoseSample::ambiguity, 0, 1, height);
  plot("error px", h, &PoseSample::error_px, 0, emax * 1.1f + 1e-6f, height);
  plot("other px", h, &PoseSample::alternative_error_px, 0, emax * 1.1f + 1e-6f, height);
}

}  // namespace arwb::ui
