// "Why not detected?": the rectangle dragged on the live view, a marker of a dictionary that is not searched
// (with a button adding it), every candidate the pipeline had there and where it was dropped, or the early stage
// that lost the marker; and the parameter sweep that finds the smallest change making a marker appear there.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

namespace arwb::ui {

namespace {

const ImVec4 kAdvice{1.0f, 0.8f, 0.3f, 1.0f};

// Adds a dictionary to those searched; the workbench forwards the change to the detector.
void add_dictionary_button(Context& ctx, const std::string& dict) {
  auto& d = ctx.settings.dictionaries;
  if (std::find(d.begin(), d.end(), dict) != d.end()) {
    ImGui::TextDisabled("%s is searched now", dict.c_str());
    return;
  }
  const std::string label = "Add " + dict + " to the searched dictionaries";
  if (ImGui::Button(label.c_str())) d.push_back(dict);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("The detector then reads every quad as %s too.", dict.c_str());
}

void dictionary_advice(Context& ctx, const RegionReport& rep) {
  if (rep.other_dictionaries.empty()) return;
  const OtherDictionary& o = rep.other_dictionaries.front();
  ImGui::PushStyleColor(ImGuiCol_Text, kAdvice);
  ImGui::TextWrapped("%s", rep.advice.c_str());
  ImGui::PopStyleColor();
  add_dictionary_button(ctx, o.dict);
  std::string also;
  for (size_t i = 1; i < rep.other_dictionaries.size() && i < 6; ++i) {
    const OtherDictionary& x = rep.other_dictionaries[i];
    also += (also.empty() ? "" : ", ") + x.dict + " id " + std::to_string(x.id);
  }
  if (!also.empty()) ImGui::TextDisabled("It also reads as %s.", also.c_str());
}

void sweep_section(Context& ctx) {
  const SweepStatus& s = ctx.status.sweep;
  ImGui::Separator();
  if (s.running) {
    ImGui::ProgressBar(static_cast<float>(s.progress), {-1, 0}, "sweeping the parameter table...");
    return;
  }
  if (ImGui::Button("Find the smallest change that detects it")) {
    ctx.request(Sweep{});
  }
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("Re-runs the detector on this frame with each parameter moved across its range (nearest values\n"
                      "first), then pairs of parameters, and reports the smallest change that finds a marker here.");
  }
  if (!s.has_result) return;
  const SweepResult& r = s.result;
  ImGui::TextWrapped("%s", r.message.c_str());
  ImGui::TextDisabled("%d detector runs", r.runs);
  if (!r.add_dictionary.empty()) {
    ImGui::PushID("sweep");   // the advice above has a button of the same label
    add_dictionary_button(ctx, r.add_dictionary);
    ImGui::PopID();
  }
  if (r.found && !r.changes.empty()) {
    for (const SweepChange& c : r.changes) ImGui::BulletText("%s: %g -> %g", c.param.c_str(), c.from, c.to);
    if (ImGui::Button("Apply this change")) {
      for (const SweepChange& c : r.changes) {
        if (const ParamInfo* info = find_param(c.param)) set_param(ctx.settings.params, *info, c.to);
      }
    }
  }
}

}  // namespace

void draw_why(Context& ctx) {
  View& v = ctx.view;
  if (!v.has_region) {
    ImGui::TextWrapped("Tick 'Why? (drag)' in the live view, then drag a rectangle around a marker that is not "
                       "detected. This panel lists every candidate the pipeline had there and where it was dropped.");
    if (!v.region_tool && ImGui::Button("Start: pick a region")) v.region_tool = true;
    return;
  }
  ImGui::Text("Region %.0f,%.0f  %.0fx%.0f px", static_cast<double>(v.region.x), static_cast<double>(v.region.y),
              static_cast<double>(v.region.width), static_cast<double>(v.region.height));
  flow(button_width("Clear"));
  if (ImGui::SmallButton("Clear")) {
    v.has_region = false;
    v.region_tool = false;
  }
  const RegionReport& rep = v.region_report;
  if (rep.lost_at != Stage::accepted) {
    ImGui::PushStyleColor(ImGuiCol_Text, stage_colour(rep.lost_at));
    ImGui::TextWrapped("Lost at %s", std::string(stage_name(rep.lost_at)).c_str());
    ImGui::PopStyleColor();
  }
  dictionary_advice(ctx, rep);
  // The summary without the advice drawn above it.
  const bool advised = !rep.advice.empty() && rep.summary.rfind(rep.advice, 0) == 0;
  ImGui::TextWrapped("%s", rep.summary.c_str() + (advised ? rep.advice.size() + (rep.summary.size() > rep.advice.size()) : 0));
  if (!rep.candidates.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("%zu candidate(s) here, hover to highlight, click to inspect:", rep.candidates.size());
    ImGui::PopStyleColor();
    // Long lines scroll sideways rather than being cut.
    ImGui::BeginChild("cands", {0, 160 * ctx.scale}, true, ImGuiWindowFlags_HorizontalScrollbar);
    for (const RegionCandidate& c : rep.candidates) {
      ImGui::PushStyleColor(ImGuiCol_Text, c.fate.stage == Stage::accepted ? accepted_colour() : stage_colour(c.fate.stage));
      ImGui::PushID(c.index);
      if (ImGui::Selectable(c.line.c_str(), v.selected_candidate == c.index)) {
        v.selected_candidate = c.index;
        v.show(Panel::inspector);
      }
      if (ImGui::IsItemHovered()) v.hovered_candidate = c.index;
      ImGui::PopID();
      ImGui::PopStyleColor();
    }
    ImGui::EndChild();
  }
  sweep_section(ctx);
}

}  // namespace arwb::ui
