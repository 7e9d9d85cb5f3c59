// The guided tour for teaching: the frame is frozen and the tour steps through the stages one at a time, each
// with the stage's picture, its figures for this frame, a short explanation read from assets/teaching/tour.txt
// (teachers edit or translate that file) and the parameters that step is about. The pipeline panel follows the
// tour's stage, so the large view shows what the text explains.
#include "inspect/trace_view.hpp"
#include "teach/tour.hpp"
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cstdio>

namespace arwb::ui {

namespace {

// The stage's figures for this frame, on the line of what precedes them when they fit there (flow).
void stage_figures(Context& ctx, const TourStep& step) {
  if (!ctx.frame || !step.is_stage) return;
  const StageRecord* r = ctx.frame->trace.stage(step.stage);
  if (!r) return;
  char line[96];
  std::snprintf(line, sizeof line, "this frame: %.2f ms, %d in, %d out", r->ms, r->in, r->out);
  flow(text_width(line));
  ImGui::TextDisabled("%s", line);
}

// The stage's picture and what it shows on this frame (decimation at 1 on a small frame, a search in regions
// only), when no Pipeline panel shows them large.
void stage_picture(Context& ctx, const TourStep& step) {
  if (!ctx.frame || !step.is_stage || ctx.view.open[static_cast<size_t>(Panel::pipeline)]) return;
  const Frame& f = *ctx.frame;
  if (const std::string caption = stage_view_caption(f.trace, step.stage); !caption.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, stage_colour(step.stage));
    ImGui::TextWrapped("This frame's picture: %s.", caption.c_str());
    ImGui::PopStyleColor();
  }
  const cv::Mat& view = f.views[static_cast<size_t>(step.stage)];
  if (!view.empty()) {
    const float w = std::min(ImGui::GetContentRegionAvail().x, 520.0f * ctx.scale);
    const float h = w * static_cast<float>(view.rows) / static_cast<float>(view.cols);
    image_button(ctx, "tour:" + step.key, view, f.index, {w, h});
    if (ImGui::IsItemClicked()) ctx.view.show(Panel::pipeline);
    ImageMapping m;   // the button shows the picture whole, edge to edge
    m.min = m.origin = ImGui::GetItemRectMin();
    m.max = ImGui::GetItemRectMax();
    m.zoom = w / static_cast<float>(view.cols);
    if (!stage_view_is_mosaic(step.stage)) ctx.view.stage_zoom = m.zoom;
    if (!f.view_style.text)
      draw_stage_labels(ImGui::GetWindowDrawList(), m, f.view_labels[static_cast<size_t>(step.stage)]);
  }
}

void step_params(Context& ctx, const TourStep& step) {
  bool first = true;
  for (const std::string& name : step.params) {
    const ParamInfo* info = find_param(name);
    if (!info) continue;
    // Side by side while they fit on the line (flow), each slider with its name.
    const float w = (ctx.view.presentation ? 150 : 220) * ctx.scale;   // two a line beside a projector's text
    if (!first) flow(w + ImGui::GetStyle().ItemInnerSpacing.x + text_width(info->name));
    first = false;
    fit_item_width(w, info->name);
    param_slider(ctx.settings.params, *info);
    ImGui::SameLine(0, ImGui::GetStyle().ItemInnerSpacing.x);   // as fit_item_width counts it
    ImGui::TextUnformatted(info->name);
  }
}

// The step's title, its figures for this frame, the Look line and the Try controls (and the stage's picture when
// no Pipeline panel shows it); how far they ran past the panel's bottom goes to View::tour_overflow_px.
void step_head(Context& ctx, const TourStep& step) {
  View& v = ctx.view;
  if (step.is_stage) ImGui::PushStyleColor(ImGuiCol_Text, stage_colour(step.stage));
  ImGui::TextWrapped("%s", step.title.c_str());
  if (step.is_stage) ImGui::PopStyleColor();
  if (step.is_stage && !v.presentation) ImGui::TextDisabled("stage: %s", step.key.c_str());
  stage_figures(ctx, step);
  if (!step.look.empty()) {
    ImGui::TextColored({1.0f, 0.85f, 0.4f, 1}, "Look: ");
    ImGui::SameLine();
    ImGui::TextWrapped("%s", step.look.c_str());
  }
  if (step.key == "pose") {
    // The step is about what the live view can draw: both cubes, and the Pose panel's numbers.
    if (ImGui::Button("Show both cubes and the Pose panel")) {
      v.show_cube = v.show_alternative = true;
      v.show(Panel::pose);
    }
  }
  if (!step.params.empty()) {
    ImGui::TextDisabled("Try:");
    ImGui::SameLine();
    step_params(ctx, step);
  }
  const float overflow = ImGui::GetCursorScreenPos().y - (ImGui::GetWindowPos().y + ImGui::GetWindowSize().y);
  v.tour_overflow_px = std::max(v.tour_overflow_px, std::max(0.0f, overflow));
  stage_picture(ctx, step);
}

}  // namespace

void draw_tour(Context& ctx) {
  View& v = ctx.view;
  if (ctx.tour.empty()) {
    ImGui::TextWrapped("No tour was loaded: the log says why (the text lives in assets/teaching/tour.txt).");
    return;
  }
  const int n = static_cast<int>(ctx.tour.size());
  v.tour_step = std::clamp(v.tour_step, 0, n - 1);
  const TourStep& step = ctx.tour[static_cast<size_t>(v.tour_step)];
  if (v.tour_active && step.is_stage) v.pipeline_stage = static_cast<int>(step.stage);

  // Navigation, wrapping in a narrow region (flow).
  ImGui::BeginDisabled(v.tour_step == 0);
  if (ImGui::Button("< Back")) --v.tour_step;
  ImGui::EndDisabled();
  flow(button_width("Next >"));
  ImGui::BeginDisabled(v.tour_step == n - 1);
  if (ImGui::Button("Next >")) ++v.tour_step;
  ImGui::EndDisabled();
  flow(text_width("Step 00 of 00"));
  ImGui::Text("Step %d of %d", v.tour_step + 1, n);
  flow(checkbox_width("Freeze"));
  ImGui::Checkbox("Freeze", &ctx.settings.frozen);
  flow(button_width("Next frame"));
  if (ImGui::Button("Next frame")) ctx.request(NextFrame{});
  flow(checkbox_width("Presentation"));
  ImGui::Checkbox("Presentation", &v.presentation);
  flow(button_width("Print markers"));
  if (ImGui::Button("Print markers")) ctx.request(OpenSheetDialog{ctx.settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : ctx.settings.dictionaries[0]});
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("An A4 PDF of markers at a true size, as `arwb markers` writes.");
  if (!v.tour_active) {
    flow(button_width("Start the lesson"));
    if (ImGui::Button("Start the lesson")) {
      v.tour_active = true;
      ctx.settings.frozen = true;  // a lesson explains one frame; "Next frame" moves on
    }
  }
  ImGui::Separator();

  // In presentation mode the step's title, Look line, figures and Try controls on the left and its text on the
  // right, scrolling by itself: under pictures that take most of a projected screen, the lines the class and the
  // teacher act on stay in view. Otherwise one column, the text under them.
  const float height = ImGui::GetContentRegionAvail().y;
  if (v.presentation && ImGui::BeginTable("##step", 2, ImGuiTableFlags_SizingStretchProp | ImGuiTableFlags_BordersInnerV)) {
    ImGui::TableSetupColumn("head", ImGuiTableColumnFlags_WidthStretch, 2);
    ImGui::TableSetupColumn("text", ImGuiTableColumnFlags_WidthStretch, 1);
    ImGui::TableNextColumn();
    step_head(ctx, step);
    ImGui::TableNextColumn();
    ImGui::BeginChild("text", {0, std::max(height - ImGui::GetStyle().CellPadding.y * 2 - 2, 1.0f)});
    ImGui::TextWrapped("%s", step.text.c_str());
    ImGui::EndChild();
    ImGui::EndTable();
    return;
  }
  ImGui::BeginChild("step");
  step_head(ctx, step);
  ImGui::Spacing();
  ImGui::TextWrapped("%s", step.text.c_str());
  ImGui::EndChild();
}

}  // namespace arwb::ui
