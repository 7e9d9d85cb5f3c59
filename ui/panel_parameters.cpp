// Parameters: the detector's parameter table as sliders, one collapsing header per pipeline stage in pipeline
// order. Everything shown comes from param_table() (name, stage, unit, range, default, help), so a parameter
// added to the table appears here by itself. Edits go through set_param into the settings; the workbench
// forwards them to the detector. Below: YAML presets (a path to load or save, and the presets shipped under
// assets/presets, which the window lists when asked) and the dictionaries the detector looks for.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace arwb::ui {

namespace {

struct ParametersState : PanelState {
  char path[512] = "my-preset";   // a bare name is saved in the user's presets folder (config_dir/presets)
  int drawn_frame = -10;    // the UI frame the panel was last drawn; a gap means it was (re)opened
  std::string error;        // the last edit set_param refused
};

bool differs(const DetectorParams& p, const ParamInfo& info) { return get_param(p, info) != info.default_value; }

void help_marker(const char* text) {
  ImGui::TextDisabled("(?)");
  if (ImGui::IsItemHovered()) {
    ImGui::BeginTooltip();
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 32.0f);
    ImGui::TextUnformatted(text);
    ImGui::PopTextWrapPos();
    ImGui::EndTooltip();
  }
}

// One row of a stage's table: name (?), slider, unit, reset.
void param_row(Context& ctx, ParametersState& st, const ParamInfo& info) {
  DetectorParams& p = ctx.settings.params;
  ImGui::PushID(info.name);
  ImGui::TableNextRow();
  ImGui::TableNextColumn();
  const bool changed = differs(p, info);
  if (changed) ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 220, 120, 255));
  ImGui::TextUnformatted(info.name);
  if (changed) ImGui::PopStyleColor();
  if (ImGui::IsItemHovered()) param_tooltip(info);
  ImGui::SameLine();
  help_marker(info.help);

  ImGui::TableNextColumn();
  ImGui::SetNextItemWidth(-FLT_MIN);
  std::string err;
  if (param_slider(p, info, &err)) st.error = err;

  ImGui::TableNextColumn();
  ImGui::TextDisabled("%s", info.unit);

  ImGui::TableNextColumn();
  if (changed) {
    if (ImGui::SmallButton("reset")) set_param(p, info, info.default_value);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Back to the default, %s", value_text(info, info.default_value).c_str());
  }
  ImGui::PopID();
}

void parameter_tables(Context& ctx, ParametersState& st) {
  const auto table = param_table();
  size_t i = 0;
  while (i < table.size()) {
    // The table is in pipeline order: consecutive rows of one stage form its group.
    size_t j = i;
    int changed = 0;
    while (j < table.size() && std::string_view(table[j].stage) == table[i].stage) {
      if (differs(ctx.settings.params, table[j])) ++changed;
      ++j;
    }
    Stage stage = Stage::acquisition;
    const bool known = stage_from_name(table[i].stage, &stage);
    char label[128];
    if (changed) std::snprintf(label, sizeof label, "%s  (%d changed)###%s", table[i].stage, changed, table[i].stage);
    else std::snprintf(label, sizeof label, "%s###%s", table[i].stage, table[i].stage);
    if (known) ImGui::PushStyleColor(ImGuiCol_Text, stage_colour(stage));
    const bool open = ImGui::CollapsingHeader(label, ImGuiTreeNodeFlags_DefaultOpen);
    if (known) ImGui::PopStyleColor();
    if (open) {
      // Names whole and a slider wide enough to read its value; a region narrower than that scrolls sideways.
      const ImGuiStyle& style = ImGui::GetStyle();
      float name_w = 0;
      for (size_t k = i; k < j; ++k) name_w = std::max(name_w, text_width(table[k].name));
      name_w += style.ItemSpacing.x + text_width("(?)");
      float unit_w = 0;
      for (const ParamInfo& info : table) unit_w = std::max(unit_w, text_width(info.unit));
      const float reset_w = button_width("reset");
      const float value_w = text_width("0000.000") + style.FramePadding.x * 2;
      const float need = name_w + value_w + unit_w + reset_w + style.CellPadding.x * 8;
      const bool narrow = need > ImGui::GetContentRegionAvail().x;
      ImGuiTableFlags tf = ImGuiTableFlags_SizingStretchProp | ImGuiTableFlags_RowBg;
      ImVec2 outer{0, 0};
      if (narrow) {
        tf |= ImGuiTableFlags_ScrollX;
        outer.y = static_cast<float>(j - i) * (ImGui::GetFrameHeight() + style.CellPadding.y * 2) + style.ScrollbarSize + 2;
      }
      if (ImGui::BeginTable(table[i].stage, 4, tf, outer, narrow ? need : 0.0f)) {
        ImGui::TableSetupColumn("name", ImGuiTableColumnFlags_WidthFixed, name_w);
        ImGui::TableSetupColumn("value", ImGuiTableColumnFlags_WidthStretch);
        ImGui::TableSetupColumn("unit", ImGuiTableColumnFlags_WidthFixed, unit_w);
        ImGui::TableSetupColumn("reset", ImGuiTableColumnFlags_WidthFixed, reset_w);
        for (size_t k = i; k < j; ++k) param_row(ctx, st, table[k]);
        ImGui::EndTable();
      }
    }
    i = j;
  }
}

void presets_section(Context& ctx, ParametersState& st) {
  if (!ImGui::CollapsingHeader("Presets", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const float button_w = ImGui::CalcTextSize("Load").x + ImGui::CalcTextSize("Save").x +
                         ImGui::CalcTextSize("Browse...").x + ImGui::GetStyle().FramePadding.x * 6 +
                         ImGui::GetStyle().ItemSpacing.x * 3;
  // The buttons go under the path when the region is too narrow for both on one line.
  const float field_w = ImGui::GetContentRegionAvail().x - button_w;
  const bool one_line = field_w >= 120.0f * ctx.scale;
  ImGui::SetNextItemWidth(one_line ? field_w : -FLT_MIN);
  if (ctx.view.focus_field == TextField::preset_path) {   // --actions focus=preset_path
    ImGui::SetKeyboardFocusHere();
    ctx.view.focus_field = TextField::none;
  }
  ImGui::InputText("##preset_path", st.path, sizeof st.path);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("A name (saved in %s/presets, rounded to each parameter's precision) or a path to a YAML file.",
                      ctx.status.config_dir.c_str());
  }
  if (one_line) ImGui::SameLine();
  const bool has_path = st.path[0] != 0;
  if (ImGui::Button("Load") && has_path) ctx.request(LoadPreset{st.path});
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Every key is checked against the table; on an error nothing changes.");
  ImGui::SameLine();
  // The window writes the file, making the folder it goes into so "presets/..." works on the first save.
  if (ImGui::Button("Save") && has_path) ctx.request(SavePreset{st.path});
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Writes every parameter of the table with its current value.");
  ImGui::SameLine();
  if (ImGui::Button("Browse...")) ctx.request(Browse{FileKind::preset});

  if (!ctx.status.user_presets.empty()) {
    ImGui::Spacing();
    ImGui::TextUnformatted("Your presets");
    ImGui::SameLine();
    ImGui::TextDisabled("%s/presets", ctx.status.config_dir.c_str());
    for (const PresetFile& up : ctx.status.user_presets) {
      ImGui::PushID(up.path.c_str());
      if (ImGui::SmallButton("Load")) ctx.request(LoadPreset{up.path});
      ImGui::SameLine();
      ImGui::TextUnformatted(up.name.c_str());
      ImGui::PopID();
    }
  }
  ImGui::Spacing();
  ImGui::TextUnformatted("Shipped presets");
  ImGui::SameLine();
  if (ImGui::SmallButton("Refresh")) ctx.request(ListPresets{});
  if (ctx.status.presets_dir.empty()) {
    ImGui::TextDisabled("No assets/presets folder found (from the working folder or the executable).");
    return;
  }
  text_disabled_wrapped(ctx.status.presets_dir.c_str());
  if (ctx.status.presets.empty()) ImGui::TextDisabled("No .yml files there.");
  for (const PresetFile& sp : ctx.status.presets) {
    ImGui::PushID(sp.path.c_str());
    if (ImGui::SmallButton("Load")) ctx.request(LoadPreset{sp.path});
    ImGui::SameLine();
    ImGui::TextUnformatted(sp.name.c_str());
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", sp.path.c_str());
    if (!sp.comment.empty()) {
      ImGui::SameLine();
      ImGui::PushTextWrapPos(0.0f);
      ImGui::TextDisabled("- %s", sp.comment.c_str());
      ImGui::PopTextWrapPos();
    }
    ImGui::PopID();
  }
}

void dictionaries_section(Context& ctx) {
  if (!ImGui::CollapsingHeader("Dictionaries", ImGuiTreeNodeFlags_DefaultOpen)) return;
  std::vector<std::string>& sel = ctx.settings.dictionaries;
  std::string preview = sel.empty() ? std::string("(none)") : sel[0];
  if (sel.size() > 1) preview += " +" + std::to_string(sel.size() - 1);
  ImGui::SetNextItemWidth(std::min(ImGui::GetContentRegionAvail().x, 260.0f * ctx.scale));
  if (ImGui::BeginCombo("##dicts", preview.c_str(), ImGuiComboFlags_HeightLarge)) {
    for (const std::string& name : dictionary_names()) {
      const auto it = std::find(sel.begin(), sel.end(), name);
      bool on = it != sel.end();
      const bool last = on && sel.size() == 1;
      if (last) ImGui::BeginDisabled();
      if (ImGui::Checkbox(name.c_str(), &on)) {
        if (on) sel.push_back(name);
        else sel.erase(it);
      }
      if (last) {
        ImGui::EndDisabled();
        if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
          ImGui::SetTooltip("At least one dictionary stays selected.");
        }
      }
    }
    ImGui::EndCombo();
  }
  flow(text_width("99 selected"));
  ImGui::TextDisabled("%zu selected", sel.size());
  ImGui::TextWrapped("Each candidate is read against every selected dictionary; more dictionaries cost time and "
                     "raise the chance of a false identification. The first (%s) is the one the peers run on and "
                     "marker sheets are printed from.",
                     sel.empty() ? "none" : sel[0].c_str());
}

}  // namespace

void draw_parameters(Context& ctx) {
  ParametersState& st = panel_state<ParametersState>(ctx.view, Panel::parameters);
  // The shipped presets are listed again whenever the panel is (re)opened.
  const int frame = ImGui::GetFrameCount();
  if (frame - st.drawn_frame > 1) ctx.request(ListPresets{});
  st.drawn_frame = frame;

  int changed = 0;
  for (const ParamInfo& info : param_table())
    if (differs(ctx.settings.params, info)) ++changed;
  if (changed) ImGui::Text("%d of %zu parameters differ from their defaults", changed, param_table().size());
  else ImGui::TextDisabled("All %zu parameters at their defaults", param_table().size());
  flow(button_width("Reset all"));
  if (changed == 0) ImGui::BeginDisabled();
  if (ImGui::Button("Reset all")) {
    ctx.settings.params = DetectorParams();
    st.error.clear();
  }
  if (changed == 0) ImGui::EndDisabled();
  if (!st.error.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, IM_COL32(255, 80, 80, 255));
    ImGui::TextWrapped("%s", st.error.c_str());
    ImGui::PopStyleColor();
  }
  text_disabled_wrapped("Hover a name for what raising it trades; Ctrl+click a slider to type.");

  parameter_tables(ctx, st);
  ImGui::Spacing();
  presets_section(ctx, st);
  dictionaries_section(ctx);
}

}  // namespace arwb::ui
