// Pipeline: every stage as a thumbnail in pipeline order, with its time and counts. The one clicked is shown
// large. Stages drawn over the frame use the live view's zoom and pan (one shared ImageViewState), so a pixel
// here is the same pixel there; the per-candidate mosaics (frontal views, grids) have a view of their own.
#include "inspect/trace_view.hpp"
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace arwb::ui {

namespace {

const cv::Mat& stage_view(const Frame& f, int stage, bool thumb) {
  if (stage < 0) return thumb ? f.image_thumb : f.image;
  return thumb ? f.thumbs[static_cast<size_t>(stage)] : f.views[static_cast<size_t>(stage)];
}

struct PipelineState : PanelState {
  ImageViewState mosaic_view;  // the mosaics' own zoom and pan
};

}  // namespace

void draw_pipeline(Context& ctx) {
  ImageViewState& mosaic_view = panel_state<PipelineState>(ctx.view, Panel::pipeline).mosaic_view;
  if (waiting_for_frame(ctx)) return;
  const Frame& f = *ctx.frame;
  const FrameTrace& t = f.trace;
  if (t.level != TraceLevel::full) {
    ImGui::TextWrapped("The trace is at level '%s': stage pictures are made only at the full level.",
                       std::string(trace_level_name(t.level)).c_str());
  }
  // Thumbnails in a scrolling column on the left, so the large view keeps most of the panel. In presentation mode
  // the stage alone fills the panel: the tour (or a click in the normal mode) chooses it.
  const bool stage_only = ctx.view.presentation;
  const float thumb_w = 104.0f * ctx.scale;
  const float thumb_h = thumb_w * 0.75f;
  // As wide as the longest stage name and timing line too, so neither is cut.
  const float column_w = std::max({thumb_w, text_width("perspective_removal"), text_width("99.99 ms 9999>9999")});
  int& sel = ctx.view.pipeline_stage;
  if (sel >= 0 && f.views[static_cast<size_t>(sel)].empty()) sel = -1;
  auto thumb = [&](int stage, const std::string& title, const StageRecord* r) {
    ImGui::BeginGroup();
    if (image_button(ctx, "thumb:" + title, stage_view(f, stage, true), f.index, {thumb_w, thumb_h}, sel == stage)) {
      sel = stage;
    }
    if (stage >= 0) ImGui::PushStyleColor(ImGuiCol_Text, stage_colour(static_cast<Stage>(stage)));
    ImGui::TextUnformatted(title.c_str());
    if (stage >= 0) ImGui::PopStyleColor();
    if (r) ImGui::TextDisabled("%.2f ms %d>%d", r->ms, r->in, r->out);
    else ImGui::TextDisabled("%dx%d", f.image.cols, f.image.rows);
    ImGui::EndGroup();
    if (ImGui::IsItemHovered() && r) {
      ImGui::SetTooltip("%s: %.3f ms, %d in, %d out", title.c_str(), r->ms, r->in, r->out);
    }
    ImGui::Spacing();
  };
  if (!stage_only) {
    ImGui::BeginChild("thumbs", {column_w + ImGui::GetStyle().ScrollbarSize + 12.0f * ctx.scale, 0}, false);
    thumb(-1, "input", nullptr);
    for (const StageRecord& r : t.stages) thumb(static_cast<int>(r.stage), std::string(stage_name(r.stage)), &r);
    ImGui::EndChild();
    ImGui::SameLine();
  }
  ImGui::BeginGroup();

  const bool mosaic = sel >= 0 && stage_view_is_mosaic(static_cast<Stage>(sel));
  const std::string title = sel < 0 ? "input" : std::string(stage_name(static_cast<Stage>(sel)));
  const cv::Mat& big = stage_view(f, sel, false);
  ImGui::TextUnformatted(title.c_str());
  // What the picture shows on this frame where it could mislead (the decimation's factor, regions only).
  if (const std::string caption = sel < 0 ? "" : stage_view_caption(f.trace, static_cast<Stage>(sel)); !caption.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, stage_colour(static_cast<Stage>(sel)));
    ImGui::TextWrapped("%s", caption.c_str());
    ImGui::PopStyleColor();
  }
  const char* about = mosaic ? "(a tile per candidate that reached this stage, in ledger order)"
                             : "(zoom and pan shared with the live view)";
  if (!stage_only) {
    flow(text_width(about));
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("%s", about);
    ImGui::PopStyleColor();
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Wheel zooms, right-drag pans, right double-click fits.");
  }
  const char* hint = stage_only ? "" : "Hover the image for pixel values; click a thumbnail to show its stage here.";
  ImVec2 avail = ImGui::GetContentRegionAvail();
  // Room under the image for the pixel line or the hint, wrapped.
  avail.y -= std::max(ImGui::CalcTextSize(hint, nullptr, false, avail.x).y, ImGui::GetTextLineHeight()) +
             ImGui::GetStyle().ItemSpacing.y;
  const ImageMapping m =
      image_view(ctx, "stage_big", "stage:" + title, big, f.index, mosaic ? mosaic_view : ctx.view.image, avail);
  if (!mosaic && sel >= 0) ctx.view.stage_zoom = m.zoom;
  // A projector's pictures come without their text (Frame::view_style): it is drawn here in the window's type.
  ctx.view.stage_labels_drawn = 0;
  ctx.view.stage_label_px = 0;
  if (sel >= 0 && !big.empty() && !f.view_style.text) {
    const auto& labels = f.view_labels[static_cast<size_t>(sel)];
    ctx.view.stage_label_px = draw_stage_labels(ImGui::GetWindowDrawList(), m, labels);
    ctx.view.stage_labels_drawn = static_cast<int>(labels.size());
  }
  if (m.hovered && !big.empty()) {
    const int x = static_cast<int>(std::lround(m.mouse_px.x)), y = static_cast<int>(std::lround(m.mouse_px.y));
    if (x >= 0 && y >= 0 && x < big.cols && y < big.rows) {
      if (big.channels() == 1) {
        ImGui::Text("(%d, %d) value %d", x, y, big.at<uint8_t>(y, x));
      } else {
        const cv::Vec3b p = big.at<cv::Vec3b>(y, x);
        ImGui::Text("(%d, %d) RGB %d %d %d", x, y, p[2], p[1], p[0]);
      }
    }
  } else {
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("%s", hint);
    ImGui::PopStyleColor();
  }
  ImGui::EndGroup();
}

}  // namespace arwb::ui
