// Scene: the Lua scene (or XML database) in use and its state, loading and unloading one, the examples shipped
// under scripts/, whether its media are drawn, the mappings it declared (ids -> media, placement, state, line)
// and the markers in view as the tracker follows them. Everything comes from the frame's SceneStatus and
// tracks; loading is a request the workbench forwards to the worker.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace arwb::ui {

namespace {

struct SceneViewState : PanelState {
  char path[1024] = "";
  std::string followed;            // the scene file the path input was last set from
};


void load_controls(Context& ctx, SceneViewState& st) {
  // A scene in use, or one whose load failed (the worker watches it for a fix).
  const bool loaded = ctx.frame && (!ctx.frame->scene.file.empty() || !ctx.frame->scene.error.empty());
  ImGui::SetNextItemWidth(-(ImGui::CalcTextSize("Load").x + ImGui::CalcTextSize("Unload").x +
                            ImGui::GetStyle().FramePadding.x * 4 + ImGui::GetStyle().ItemSpacing.x * 2));
  const bool enter = ImGui::InputTextWithHint("##scene_path", "scene file (.lua or .xml)", st.path, sizeof st.path,
                                              ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  if ((ImGui::Button("Load") || enter) && st.path[0] != '\0') ctx.request(LoadScene{st.path});
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Loads the scene; it reloads by itself whenever the file changes.");
  ImGui::SameLine();
  ImGui::BeginDisabled(!loaded);
  if (ImGui::Button("Unload")) ctx.request(LoadScene{""});
  ImGui::EndDisabled();

  ImGui::SetNextItemWidth(std::max(160.0f * ctx.scale, ImGui::GetContentRegionAvail().x * 0.45f));
  if (ImGui::BeginCombo("##examples", "Examples...", ImGuiComboFlags_HeightLarge)) {
    // The window reads the folder when the list opens, not every frame.
    if (ImGui::IsWindowAppearing()) ctx.request(ListExamples{});
    for (const ExampleScene& e : ctx.status.examples) {
      const bool current = ctx.frame && ctx.frame->scene.file == e.path;
      if (ImGui::Selectable(e.label.c_str(), current)) {
        std::snprintf(st.path, sizeof st.path, "%s", e.path.c_str());
        ctx.request(LoadScene{e.path});
      }
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", e.path.c_str());
    }
    if (ctx.status.examples.empty()) ImGui::TextDisabled("%s", ctx.status.examples_error.c_str());
    ImGui::EndCombo();
  }
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("The example scenes shipped in %s",
                      ctx.status.scripts_dir.empty() ? "scripts/" : ctx.status.scripts_dir.c_str());
  }
  ImGui::SameLine();
  ImGui::Checkbox("Show media", &ctx.view.show_media);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Draw the scene's media on the live view.");
}

// The file, ok or error, the generation; the dictionary the scene asked for.
void scene_state(Context& ctx) {
  const SceneStatus& s = ctx.frame->scene;
  ImGui::TextDisabled("Scene");
  ImGui::SameLine();
  const std::string failed = s.file.empty() ? scene_file_to_edit(s) : std::string();
  if (!s.file.empty()) ImGui::TextUnformatted(s.file.c_str());
  else if (!failed.empty()) ImGui::Text("(none: %s did not load)", failed.c_str());
  else ImGui::TextUnformatted("(none)");
  const auto faulty = std::count_if(s.mappings.begin(), s.mappings.end(),
                                    [](const MappingRow& r) { return r.health != MappingHealth::ok; });
  if (s.ok && s.error.empty() && faulty > 0) {
    // Runs, but not all of it: never "ok" while a mapping is skipped, disabled or failing.
    ImGui::TextColored(kRed, "%d of %zu mappings not working", static_cast<int>(faulty), s.mappings.size());
    ImGui::SameLine();
    ImGui::TextDisabled("generation %llu: see the red rows", static_cast<unsigned long long>(s.generation));
  } else if (s.ok) {
    ImGui::TextColored(s.error.empty() ? kGreen : kYellow, "%s", s.error.empty() ? "ok" : "reload failed");
    ImGui::SameLine();
    ImGui::TextDisabled("generation %llu%s", static_cast<unsigned long long>(s.generation),
                        s.error.empty() ? "" : ": the last good version still runs");
  } else if (!s.error.empty()) {
    ImGui::TextColored(kRed, "error");
    ImGui::SameLine();
    ImGui::TextDisabled("nothing runs");
  } else if (!s.file.empty()) {
    ImGui::TextDisabled("loading...");
  }
  if (!s.error.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kRed);
    ImGui::TextWrapped("%s", s.error.c_str());
    ImGui::PopStyleColor();
    if (s.error_line > 0) {
      if (ImGui::SmallButton("Show in the editor")) {
        show_script_line(ctx, s.error_line);
      }
      ImGui::SameLine();
    }
    if (ImGui::SmallButton("Console")) ctx.view.show(Panel::console);
  } else if (!s.file.empty()) {
    if (ImGui::SmallButton("Edit script")) show_script_line(ctx, 0);
    ImGui::SameLine();
    if (ImGui::SmallButton("Console")) ctx.view.show(Panel::console);
  }
  if (!s.dictionary.empty()) {
    const std::string& reads = ctx.settings.dictionaries.empty() ? std::string() : ctx.settings.dictionaries[0];
    ImGui::TextDisabled("dictionary %s", s.dictionary.c_str());
    if (std::find(ctx.settings.dictionaries.begin(), ctx.settings.dictionaries.end(), s.dictionary) ==
        ctx.settings.dictionaries.end()) {
      ImGui::SameLine();
      ImGui::TextColored(kYellow, "the detector reads %s", reads.empty() ? "nothing" : reads.c_str());
      ImGui::SameLine();
      if (ImGui::SmallButton("Detect this dictionary")) ctx.settings.dictionaries = {s.dictionary};
    }
  }
}

// A reason without its "scene.lua:12: " (the row's line column says where), as the table has little room.
std::string without_location(const std::string& reason) {
  for (size_t i = reason.find(':'); i != std::string::npos; i = reason.find(':', i + 1)) {
    size_t j = i + 1;
    while (j < reason.size() && reason[j] >= '0' && reason[j] <= '9') ++j;
    if (j == i + 1 || j >= reason.size() || reason[j] != ':') continue;
    const std::string_view named(reason.data(), i);
    auto ends = [&](std::string_view ext) {
      return named.size() > ext.size() && named.substr(named.size() - ext.size()) == ext;
    };
    if (!ends(".lua") && !ends(".xml")) return reason;
    return reason.substr(j + (j + 1 < reason.size() && reason[j + 1] == ' ' ? 2 : 1));
  }
  return reason;
}

ImVec4 state_colour(const MappingRow& r) {
  const std::string& state = r.state;
  if (r.health != MappingHealth::ok) return kRed;
  if (state.rfind("visible", 0) == 0) return kGreen;
  if (state.rfind("held", 0) == 0) return kYellow;
  return ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled);
}

void mappings_table(Context& ctx) {
  const SceneStatus& s = ctx.frame->scene;
  ImGui::Spacing();
  ImGui::TextDisabled("Mappings (%zu)", s.mappings.size());
  ImGui::Separator();
  if (s.mappings.empty()) {
    ImGui::TextDisabled("The scene maps no marker.");
    return;
  }
  const ImGuiTableFlags tf = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_Resizable |
                             ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_ScrollY | ImGuiTableFlags_ScrollX;
  const float rows_h = ImGui::GetTextLineHeightWithSpacing() * static_cast<float>(std::min<size_t>(s.mappings.size(), 10) + 1);
  // Columns as wide as their text; a narrow region scrolls the table sideways rather than cutting them.
  if (!ImGui::BeginTable("mappings", 5, tf,
                         {0, rows_h + ImGui::GetStyle().CellPadding.y * 2 + ImGui::GetStyle().ScrollbarSize})) return;
  ImGui::TableSetupScrollFreeze(0, 1);
  ImGui::TableSetupColumn("ID(s)");
  ImGui::TableSetupColumn("media");
  ImGui::TableSetupColumn("placement");
  ImGui::TableSetupColumn("state");
  ImGui::TableSetupColumn("line");
  ImGui::TableHeadersRow();
  for (size_t i = 0; i < s.mappings.size(); ++i) {
    const MappingRow& r = s.mappings[i];
    const bool bad = r.health != MappingHealth::ok;
    ImGui::PushID(static_cast<int>(i));
    ImGui::TableNextRow();
    // A row that is not ok stays, in red, with its reason in the state column.
    if (bad) ImGui::TableSetBgColor(ImGuiTableBgTarget_RowBg1, IM_COL32(120, 30, 30, 90));
    if (bad) ImGui::PushStyleColor(ImGuiCol_Text, kRed);
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(r.ids.c_str());
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(r.media.c_str());
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", r.media.c_str());
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(r.placement.c_str());
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", r.placement.c_str());
    ImGui::TableNextColumn();
    // A faulty row says what it is here; its reason is listed in full under the table.
    ImGui::TextColored(state_colour(r), "%s", bad ? mapping_health_name(r.health) : r.state.c_str());
    if (ImGui::IsItemHovered() && (bad || r.state.size() > 20)) ImGui::SetTooltip("%s", r.state.c_str());
    ImGui::TableNextColumn();
    // The line the reason points at (a callback's failing statement) for a faulty row, else the declaration.
    const int line = bad && r.reason_line > 0 ? r.reason_line : r.line;
    if (line > 0) {
      char label[24];
      std::snprintf(label, sizeof label, "%d", line);
      if (ImGui::Selectable(label)) {
        show_script_line(ctx, line);
      }
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("Show line %d in the Script editor", line);
    } else {
      ImGui::TextDisabled("-");
    }
    if (bad) ImGui::PopStyleColor();
    ImGui::PopID();
  }
  ImGui::EndTable();
  // The reasons, wrapped: each faulty row's ids, line and what went wrong, a click away from the editor.
  for (size_t i = 0; i < s.mappings.size(); ++i) {
    const MappingRow& r = s.mappings[i];
    if (r.health == MappingHealth::ok) continue;
    ImGui::PushID(static_cast<int>(i) + 100000);
    ImGui::PushStyleColor(ImGuiCol_Text, kRed);
    const int line = r.reason_line > 0 ? r.reason_line : r.line;
    ImGui::TextWrapped("marker(%s), line %d, %s: %s", r.ids.c_str(), line, mapping_health_name(r.health),
                       without_location(r.reason).c_str());
    ImGui::PopStyleColor();
    if (ImGui::IsItemClicked() && line > 0) show_script_line(ctx, line);
    if (ImGui::IsItemHovered() && line > 0) ImGui::SetTooltip("Click: show line %d in the Script editor", line);
    ImGui::PopID();
  }
}

void markers_table(Context& ctx) {
  const Frame& f = *ctx.frame;
  ImGui::Spacing();
  ImGui::TextDisabled("Markers in view (%zu)", f.tracks.size());
  ImGui::SameLine();
  ImGui::TextDisabled("  Lua %.2f ms this frame", f.scene.script_ms);
  ImGui::Separator();
  if (f.tracks.empty()) {
    ImGui::TextDisabled("No marker in view.");
    return;
  }
  const ImGuiTableFlags tf = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_SizingFixedFit |
                             ImGuiTableFlags_ScrollX;
  if (!ImGui::BeginTable("tracks", 5, tf, scroll_table_size(static_cast<int>(f.tracks.size()) + 1))) return;
  ImGui::TableSetupColumn("id");
  ImGui::TableSetupColumn("dictionary");
  ImGui::TableSetupColumn("visible");
  ImGui::TableSetupColumn("side");
  ImGui::TableSetupColumn("state");
  ImGui::TableHeadersRow();
  for (const TrackedMarker& t : f.tracks) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    // A second print of an id is its own track: "5 #2" (m.instance 1 in Lua).
    if (t.instance > 0) ImGui::Text("%d #%d", t.id, t.instance + 1);
    else ImGui::Text("%d", t.id);
    ImGui::TableNextColumn();
    ImGui::TextDisabled("%s", t.dict.c_str());
    ImGui::TableNextColumn();
    ImGui::Text("%.1f s", t.visible_s);
    ImGui::TableNextColumn();
    ImGui::Text("%.0f px", t.side_px);
    ImGui::TableNextColumn();
    if (t.detected) ImGui::TextColored(kGreen, "detected");
    else ImGui::TextColored(kYellow, "held");
    if (!t.detected && ImGui::IsItemHovered()) {
      ImGui::SetTooltip("Missed on this frame: kept with its last corners for a moment so media do not flicker.");
    }
  }
  ImGui::EndTable();
}

}  // namespace

void draw_scene(Context& ctx) {
  SceneViewState& st = panel_state<SceneViewState>(ctx.view, Panel::scene);
  // The path input shows the scene in use (or the one that failed) whenever that changes: a load from here, the
  // menu or --scene.
  const std::string current = ctx.frame ? scene_file_to_edit(ctx.frame->scene) : std::string();
  if (ctx.frame && current != st.followed) {
    st.followed = current;
    if (!current.empty()) std::snprintf(st.path, sizeof st.path, "%s", current.c_str());
  }
  load_controls(ctx, st);
  ImGui::Separator();
  if (waiting_for_frame(ctx)) return;
  const SceneStatus& s = ctx.frame->scene;
  if (s.file.empty() && s.error.empty()) {
    ImGui::Spacing();
    ImGui::TextDisabled("No scene loaded. Pick an example or load a .lua / .xml file.");
    return;
  }
  scene_state(ctx);
  mappings_table(ctx);
  markers_table(ctx);
}

}  // namespace arwb::ui
