// Timings: where the time of a frame goes. The latest frame's stages as a table (ms, items in and out, share of
// the frame), the detection and capture times, the UI and detection rates against the fps cap, and the recent
// history: the total as a line and the stages stacked, one colour per stage, so a stage that grows shows as a
// band that widens. The peers' times when they ran.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace arwb::ui {

namespace {

void stage_table(Context& ctx, const FrameTrace& t) {
  if (t.stages.empty()) {
    ImGui::TextWrapped("The trace is at level '%s': per-stage times are recorded from the summary level up.",
                       std::string(trace_level_name(t.level)).c_str());
    return;
  }
  double sum = 0;
  for (const StageRecord& r : t.stages) sum += r.ms;
  const ImGuiTableFlags tf = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_SizingFixedFit;
  if (!ImGui::BeginTable("stages", 5, tf)) return;
  ImGui::TableSetupColumn("stage");
  ImGui::TableSetupColumn("ms");
  ImGui::TableSetupColumn("in");
  ImGui::TableSetupColumn("out");
  ImGui::TableSetupColumn("share", ImGuiTableColumnFlags_WidthStretch);
  ImGui::TableHeadersRow();
  for (const StageRecord& r : t.stages) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    const std::string name(stage_name(r.stage));
    ImGui::PushStyleColor(ImGuiCol_Text, stage_colour(r.stage));
    ImGui::TextUnformatted(name.c_str());
    ImGui::PopStyleColor();
    ImGui::TableNextColumn();
    ImGui::Text("%7.3f", r.ms);
    ImGui::TableNextColumn();
    ImGui::Text("%d", r.in);
    ImGui::TableNextColumn();
    ImGui::Text("%d", r.out);
    ImGui::TableNextColumn();
    const float share = sum > 0 ? static_cast<float>(r.ms / sum) : 0.0f;
    char overlay[16];
    std::snprintf(overlay, sizeof overlay, "%.0f%%", static_cast<double>(share) * 100.0);
    ImGui::PushStyleColor(ImGuiCol_PlotHistogram, stage_colour(r.stage, 0.8f));
    ImGui::ProgressBar(share, {-FLT_MIN, ImGui::GetTextLineHeight()}, overlay);
    ImGui::PopStyleColor();
  }
  ImGui::TableNextRow();
  ImGui::TableNextColumn();
  ImGui::TextUnformatted("sum of stages");
  ImGui::TableNextColumn();
  ImGui::Text("%7.3f", sum);
  ImGui::EndTable();
  (void)ctx;
}

void rates(Context& ctx) {
  const double cap = ctx.settings.acquisition.fps_cap;
  ImGui::Text("UI %.1f fps", ctx.status.ui_fps);
  flow(text_width("detection 000.0 fps of a 000 fps cap"));
  if (cap > 0) ImGui::Text("detection %.1f fps of a %.0f fps cap", ctx.status.detect_fps, cap);
  else ImGui::Text("detection %.1f fps (no cap)", ctx.status.detect_fps);
  if (cap > 0) {
    const float frac = static_cast<float>(std::clamp(ctx.status.detect_fps / cap, 0.0, 1.0));
    ImGui::ProgressBar(frac, {-FLT_MIN, 4.0f * ctx.scale}, "");
    if (ctx.frame && !ctx.settings.frozen && ctx.status.detect_fps < 0.9 * cap) {
      const double per_frame = ctx.frame->capture_ms + ctx.frame->detect_ms;
      double peers = 0;
      for (const PeerDetections& p : ctx.frame->peers) peers += p.ms;
      if (per_frame + peers > 1000.0 / cap) {
        ImGui::PushTextWrapPos(0.0f);
        ImGui::TextDisabled("Below the cap: capture + detection%s take %.1f ms a frame, the cap allows %.1f ms.",
                            peers > 0 ? " + peers" : "", per_frame + peers, 1000.0 / cap);
        ImGui::PopTextWrapPos();
      } else {
        ImGui::PushTextWrapPos(0.0f);
        ImGui::TextDisabled("Below the cap: the source gives frames more slowly than the cap (or is paused).");
        ImGui::PopTextWrapPos();
      }
    }
  }
}

// The stages stacked over the history, one band per stage, with the detection total as a white line on top.
void stacked_history(Context& ctx, const std::deque<std::array<float, kStageCount + 1>>& h) {
  const float height = 130.0f * ctx.scale;
  const float width = std::max(ImGui::GetContentRegionAvail().x, 50.0f);
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("stacked", {width, height});
  const bool hovered = ImGui::IsItemHovered();
  const ImVec2 p1{p0.x + width, p0.y + height};
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(p0, p1, ImGui::GetColorU32(ImGuiCol_FrameBg));
  const size_t n = h.size();
  if (n < 2) {
    dl->AddText({p0.x + 6, p0.y + 6}, ImGui::GetColorU32(ImGuiCol_TextDisabled), "Collecting frames...");
    return;
  }
  float top = 0.001f;
  for (const auto& row : h) {
    float s = 0;
    for (int k = 0; k < kStageCount; ++k) s += row[static_cast<size_t>(k)];
    top = std::max({top, s, row[kStageCount]});
  }
  top *= 1.1f;
  const float dx = width / static_cast<float>(n - 1);
  auto y_of = [&](float ms) { return p1.y - std::min(ms / top, 1.0f) * height; };
  dl->PushClipRect(p0, p1, true);
  std::array<float, kStageCount> cum_prev{}, cum_next{};
  for (size_t i = 0; i + 1 < n; ++i) {
    float a = 0, b = 0;
    for (int k = 0; k < kStageCount; ++k) {
      a += h[i][static_cast<size_t>(k)];
      b += h[i + 1][static_cast<size_t>(k)];
      cum_prev[static_cast<size_t>(k)] = a;
      cum_next[static_cast<size_t>(k)] = b;
    }
    const float x0 = p0.x + dx * static_cast<float>(i), x1 = x0 + dx;
    float lo0 = 0, lo1 = 0;
    for (int k = 0; k < kStageCount; ++k) {
      const float hi0 = cum_prev[static_cast<size_t>(k)], hi1 = cum_next[static_cast<size_t>(k)];
      if (hi0 > lo0 || hi1 > lo1) {
        dl->AddQuadFilled({x0, y_of(lo0)}, {x0, y_of(hi0)}, {x1, y_of(hi1)}, {x1, y_of(lo1)},
                          stage_colour(static_cast<Stage>(k), 0.85f));
      }
      lo0 = hi0;
      lo1 = hi1;
    }
    dl->AddLine({x0, y_of(h[i][kStageCount])}, {x1, y_of(h[i + 1][kStageCount])}, IM_COL32(255, 255, 255, 150),
                1.0f * ctx.scale);
  }
  char label[48];
  std::snprintf(label, sizeof label, "%.2f ms", static_cast<double>(top));
  dl->AddText({p0.x + 4, p0.y + 2}, IM_COL32(255, 255, 255, 200), label);
  if (hovered) {
    const float mx = ImGui::GetIO().MousePos.x;
    const size_t i = std::min(n - 1, static_cast<size_t>(std::max(0.0f, (mx - p0.x) / dx + 0.5f)));
    const float x = p0.x + dx * static_cast<float>(i);
    dl->AddLine({x, p0.y}, {x, p1.y}, IM_COL32(255, 255, 255, 120));
    ImGui::BeginTooltip();
    ImGui::Text("%zu frames ago: detection %.3f ms", n - 1 - i, static_cast<double>(h[i][kStageCount]));
    for (int k = kStageCount - 1; k >= 0; --k) {  // top band first, as drawn
      const float ms = h[i][static_cast<size_t>(k)];
      if (ms <= 0) continue;
      const std::string name(stage_name(static_cast<Stage>(k)));
      ImGui::PushStyleColor(ImGuiCol_Text, stage_colour(static_cast<Stage>(k)));
      ImGui::Text("%-20s %7.3f ms", name.c_str(), static_cast<double>(ms));
      ImGui::PopStyleColor();
    }
    ImGui::EndTooltip();
  }
  dl->PopClipRect();

  // Legend: the stages that took time in the history, wrapped to the panel's width.
  std::array<bool, kStageCount> used{};
  for (const auto& row : h)
    for (int k = 0; k < kStageCount; ++k)
      if (row[static_cast<size_t>(k)] > 0) used[static_cast<size_t>(k)] = true;
  const float sq = ImGui::GetTextLineHeight() * 0.8f;
  const float right = ImGui::GetCursorScreenPos().x + ImGui::GetContentRegionAvail().x;
  bool first = true;
  for (int k = 0; k < kStageCount; ++k) {
    if (!used[static_cast<size_t>(k)]) continue;
    const Stage s = static_cast<Stage>(k);
    const std::string name(stage_name(s));
    const float w = sq + ImGui::GetStyle().ItemInnerSpacing.x + ImGui::CalcTextSize(name.c_str()).x;
    // On the line when it fits (checked before SameLine: a NewLine after it would count the item as reaching there).
    if (!first && ImGui::GetItemRectMax().x + 14.0f * ctx.scale + w <= right) ImGui::SameLine(0, 14.0f * ctx.scale);
    first = false;
    const ImVec2 at = ImGui::GetCursorScreenPos();
    const float pad = (ImGui::GetTextLineHeight() - sq) * 0.5f;
    dl->AddRectFilled({at.x, at.y + pad}, {at.x + sq, at.y + pad + sq}, stage_colour(s));
    ImGui::Dummy({sq, ImGui::GetTextLineHeight()});
    ImGui::SameLine(0, ImGui::GetStyle().ItemInnerSpacing.x);
    ImGui::TextUnformatted(name.c_str());
  }
  const float total_w = sq + ImGui::GetStyle().ItemInnerSpacing.x + ImGui::CalcTextSize("detection total").x;
  if (ImGui::GetItemRectMax().x + 14.0f * ctx.scale + total_w <= right) ImGui::SameLine(0, 14.0f * ctx.scale);
  const ImVec2 at = ImGui::GetCursorScreenPos();
  const float mid = at.y + ImGui::GetTextLineHeight() * 0.5f;
  dl->AddLine({at.x, mid}, {at.x + sq, mid}, IM_COL32(255, 255, 255, 200), 1.5f * ctx.scale);
  ImGui::Dummy({sq, ImGui::GetTextLineHeight()});
  ImGui::SameLine(0, ImGui::GetStyle().ItemInnerSpacing.x);
  ImGui::TextUnformatted("detection total");
}

void history(Context& ctx) {
  const auto& h = ctx.status.history;
  if (h.empty()) {
    ImGui::TextDisabled("No history yet.");
    return;
  }
  std::vector<float> total(h.size());
  float mx = 0, sum = 0;
  for (size_t i = 0; i < h.size(); ++i) {
    total[i] = h[i][kStageCount];
    mx = std::max(mx, total[i]);
    sum += total[i];
  }
  const float mean = sum / static_cast<float>(total.size());
  char overlay[96];
  std::snprintf(overlay, sizeof overlay, "detection: last %.2f  mean %.2f  max %.2f ms", static_cast<double>(total.back()),
                static_cast<double>(mean), static_cast<double>(mx));
  ImGui::Text("Last %zu frames", h.size());
  ImGui::PlotLines("##total", total.data(), static_cast<int>(total.size()), 0, overlay, 0.0f, mx * 1.15f + 0.001f,
                   {ImGui::GetContentRegionAvail().x, 60.0f * ctx.scale});
  ImGui::TextDisabled("Stages stacked (hover for a frame's split):");
  stacked_history(ctx, h);
}

void peers(Context& ctx) {
  if (!ctx.frame || ctx.frame->peers.empty()) return;
  ImGui::Separator();
  ImGui::TextUnformatted("Peers on this frame (run after arwb, on the same image)");
  for (const PeerDetections& p : ctx.frame->peers) {
    const ImU32 col = p.name == "opencv_aruco" ? IM_COL32(255, 120, 255, 255) : IM_COL32(80, 200, 255, 255);
    ImGui::PushStyleColor(ImGuiCol_Text, col);
    ImGui::Bullet();
    ImGui::TextUnformatted(p.name.c_str());
    ImGui::PopStyleColor();
    ImGui::SameLine();
    if (!p.error.empty()) {
      ImGui::PushTextWrapPos(0.0f);
      ImGui::TextDisabled("did not run: %s", p.error.c_str());
      ImGui::PopTextWrapPos();
    } else ImGui::Text("%.2f ms, %zu markers (%s)", p.ms, p.markers.size(), p.dict.c_str());
  }
}

}  // namespace

void draw_timings(Context& ctx) {
  rates(ctx);
  if (waiting_for_frame(ctx)) return;
  const Frame& f = *ctx.frame;
  ImGui::Text("Frame %llu: detection %.2f ms", static_cast<unsigned long long>(f.index), f.detect_ms);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("Detector::detect as the worker timed it, trace included (the trace's own total: %.2f ms).",
                      f.trace.total_ms);
  }
  flow(text_width("capture 000.00 ms"));
  ImGui::Text("capture %.2f ms", f.capture_ms);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Reading the source; acquisition's resize is the acquisition stage.");
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
  ImGui::TextWrapped("working image %dx%d, trace level %s", f.trace.work_width, f.trace.work_height,
                     std::string(trace_level_name(f.trace.level)).c_str());
  ImGui::PopStyleColor();
  stage_table(ctx, f.trace);
  ImGui::Spacing();
  history(ctx);
  peers(ctx);
}

}  // namespace arwb::ui
