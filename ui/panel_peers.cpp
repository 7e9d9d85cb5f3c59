// Peers: other detectors run on the very frame arwb saw (OpenCV's aruco module, AprilTag 3), on the first
// detection dictionary. The switches turn them on (they cost worker time, so the detection rate drops) and
// choose whether the live view draws their corners. For the latest frame: each detector's time, markers and ids,
// and the markers one found and the other did not, as the worker matched them (detect/match.hpp: the rule the
// benchmark scores with).
#include "detect/quad.hpp"
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

namespace arwb::ui {

namespace {

constexpr ImU32 kOpenCvColour = IM_COL32(255, 120, 255, 255);    // as the live view draws them
constexpr ImU32 kAprilTagColour = IM_COL32(80, 200, 255, 255);

ImU32 peer_colour(const std::string& name) { return name == "opencv_aruco" ? kOpenCvColour : kAprilTagColour; }

void swatch(ImU32 colour, float scale) {
  const float s = ImGui::GetTextLineHeight() * 0.8f;
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const float pad = (ImGui::GetFrameHeight() - s) * 0.5f;
  ImGui::GetWindowDrawList()->AddRectFilled({p.x, p.y + pad}, {p.x + s, p.y + pad + s}, colour, 2.0f * scale);
  ImGui::Dummy({s, ImGui::GetFrameHeight()});
}

std::string id_list(const std::vector<Marker>& ms, size_t limit = 0) {
  std::multiset<int> ids;
  for (const Marker& m : ms) ids.insert(m.id);
  std::string s;
  size_t k = 0;
  for (int id : ids) {
    if (limit && k == limit) {
      s += " ...";
      break;
    }
    if (!s.empty()) s += ' ';
    s += std::to_string(id);
    ++k;
  }
  return s.empty() ? std::string("-") : s;
}

std::string where(const Marker& m) {
  const cv::Point2f c = quad_centre(m.corners);
  char buf[96];
  std::snprintf(buf, sizeof buf, "id %d at (%.0f, %.0f), side %.0f px", m.id, static_cast<double>(c.x),
                static_cast<double>(c.y), mean_side(m.corners));
  return buf;
}

void switches(Context& ctx) {
  Settings& s = ctx.settings;
  const std::string first = s.dictionaries.empty() ? std::string("ARUCO_ORIGINAL") : s.dictionaries[0];
  const float indent = ImGui::GetFrameHeight() + ImGui::GetStyle().ItemInnerSpacing.x;

  ImGui::Checkbox("Run OpenCV aruco", &s.peer_opencv);
  ImGui::SameLine(0, 20.0f * ctx.scale);
  swatch(kOpenCvColour, ctx.scale);
  ImGui::SameLine();
  ImGui::Checkbox("draw##opencv", &ctx.view.show_peer_opencv);
  ImGui::Indent(indent);
  ImGui::PushTextWrapPos(0.0f);
  ImGui::TextDisabled("OpenCV 4.6 cv::aruco with its default parameters, on %s. Runs after arwb on the worker "
                      "thread: its time (usually a few ms at 640x480) is added to every frame.",
                      first.c_str());
  ImGui::PopTextWrapPos();
  ImGui::Unindent(indent);

  ImGui::Checkbox("Run AprilTag", &s.peer_apriltag);
  ImGui::SameLine(0, 20.0f * ctx.scale);
  swatch(kAprilTagColour, ctx.scale);
  ImGui::SameLine();
  ImGui::Checkbox("draw##apriltag", &ctx.view.show_peer_apriltag);
  ImGui::Indent(indent);
  ImGui::PushTextWrapPos(0.0f);
  ImGui::TextDisabled("AprilTag 3 on %s; it reads only the APRILTAG_* families. Also on the worker thread, "
                      "usually slower than arwb and OpenCV (gradient clustering on the whole image).",
                      first.c_str());
  ImGui::PopTextWrapPos();
  ImGui::Unindent(indent);
}

void results_table(const Frame& f) {
  const ImGuiTableFlags tf = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_SizingFixedFit;
  if (!ImGui::BeginTable("peers", 5, tf)) return;
  ImGui::TableSetupColumn("detector");
  ImGui::TableSetupColumn("dictionary");
  ImGui::TableSetupColumn("ms");
  ImGui::TableSetupColumn("markers");
  ImGui::TableSetupColumn("ids", ImGuiTableColumnFlags_WidthStretch);
  ImGui::TableHeadersRow();
  auto row = [&](const char* name, ImU32 colour, const std::string& dict, double ms, const std::vector<Marker>& ms_list,
                 const std::string& error) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::PushStyleColor(ImGuiCol_Text, colour);
    ImGui::TextUnformatted(name);
    ImGui::PopStyleColor();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(dict.c_str());
    if (!error.empty()) {
      ImGui::TableNextColumn();
      ImGui::TextDisabled("-");
      ImGui::TableNextColumn();
      ImGui::TextDisabled("-");
      ImGui::TableNextColumn();
      ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 80, 80, 255));
      ImGui::TextUnformatted("did not run (below)");
      ImGui::PopStyleColor();
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", error.c_str());
      return;
    }
    ImGui::TableNextColumn();
    ImGui::Text("%.2f", ms);
    ImGui::TableNextColumn();
    ImGui::Text("%zu", ms_list.size());
    ImGui::TableNextColumn();
    const std::string short_ids = id_list(ms_list, 24);
    ImGui::TextUnformatted(short_ids.c_str());
    if (ImGui::IsItemHovered() && ms_list.size() > 24) ImGui::SetTooltip("%s", id_list(ms_list).c_str());
  };
  std::string ours;
  for (const std::string& d : f.dictionaries) {
    if (!ours.empty()) ours += ',';
    ours += d;
  }
  row("arwb", accepted_colour(), ours, f.detect_ms, f.trace.markers, "");
  for (const PeerDetections& p : f.peers) row(p.name.c_str(), peer_colour(p.name), p.dict, p.ms, p.markers, p.error);
  ImGui::EndTable();
  for (const PeerDetections& p : f.peers) {
    if (p.error.empty()) continue;
    ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 80, 80, 255));
    ImGui::PushTextWrapPos(0.0f);
    ImGui::Text("%s: %s", p.name.c_str(), p.error.c_str());
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
  }
}

void differences(Context& ctx, const Frame& f) {
  for (const PeerDetections& p : f.peers) {
    if (!p.error.empty()) continue;
    const MarkerMatching& c = p.matching;
    ImGui::Spacing();
    ImGui::PushStyleColor(ImGuiCol_Text, peer_colour(p.name));
    ImGui::Text("arwb vs %s", p.name.c_str());
    ImGui::PopStyleColor();
    ImGui::SameLine();
    if (!c.pairs.empty()) {
      ImGui::Text("%zu found by both, corners %.2f px apart on average", c.pairs.size(), c.mean_corner_px());
      if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("Same dictionary and id, corners within %.0f px or a tenth of arwb's marker side on\n"
                          "average (the rule arwb bench scores with).", kMatchMinPx);
      }
    } else {
      ImGui::TextDisabled("no marker found by both");
    }
    if (p.other_dicts) {
      ImGui::SameLine();
      ImGui::TextDisabled("(%d arwb markers of other dictionaries not compared)", p.other_dicts);
    }
    ImGui::Indent(12.0f * ctx.scale);
    if (c.only_reference.empty() && c.only_found.empty()) {
      ImGui::TextDisabled(c.pairs.empty() ? "Neither found a marker of %s." : "Same markers.", p.dict.c_str());
    }
    for (size_t i : c.only_reference) {
      if (i >= f.trace.markers.size()) continue;
      const Marker& m = f.trace.markers[i];
      ImGui::PushStyleColor(ImGuiCol_Text, accepted_colour());
      ImGui::TextUnformatted("only arwb:");
      ImGui::PopStyleColor();
      ImGui::SameLine();
      ImGui::Text("%s, %d bit(s) corrected", where(m).c_str(), m.hamming);
    }
    for (size_t j : c.only_found) {
      if (j >= p.markers.size()) continue;
      ImGui::PushStyleColor(ImGuiCol_Text, peer_colour(p.name));
      ImGui::Text("only %s:", p.name.c_str());
      ImGui::PopStyleColor();
      ImGui::SameLine();
      ImGui::Text("%s", where(p.markers[j]).c_str());
      if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("Drag a rectangle around it with the live view's 'Why? (drag)' tool to see where arwb\n"
                          "dropped it.");
      }
    }
    ImGui::Unindent(12.0f * ctx.scale);
  }
}

}  // namespace

void draw_peers(Context& ctx) {
  switches(ctx);
  ImGui::Separator();
  if (!ctx.settings.peer_opencv && !ctx.settings.peer_apriltag) {
    ImGui::TextWrapped("Peers are off. Tick one above to run another detector on every frame and compare its "
                       "markers, ids and time with arwb's.");
    return;
  }
  if (waiting_for_frame(ctx)) return;
  const Frame& f = *ctx.frame;
  ImGui::Text("Frame %llu", static_cast<unsigned long long>(f.index));
  if (f.peers.empty()) ImGui::TextDisabled("(the peers' results come with the next frame)");
  results_table(f);
  differences(ctx, f);
}

}  // namespace arwb::ui
