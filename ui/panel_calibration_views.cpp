// Calibration views: what the solve made of each view and where the result can be trusted. The per-view
// reprojection errors as a bar chart in the order the views were kept (clicking a bar drops that view and the
// worker solves again), the coverage heatmap of the corners kept over the image (an 8x6 grid, filling up as views
// are kept), mrcal's cross-validation heatmap when the solve has one, and the last frames judged with the reason
// each was kept or refused.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include "calibration/session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace arwb::ui {

namespace {

// Green to yellow to red over 0..1.
ImU32 ramp(float t, float alpha = 1.0f) {
  t = std::clamp(t, 0.0f, 1.0f);
  const float r = t < 0.5f ? 2 * t : 1.0f, g = t < 0.5f ? 1.0f : 2 * (1 - t);
  return ImGui::ColorConvertFloat4ToU32({0.15f + 0.75f * r, 0.2f + 0.6f * g, 0.2f, alpha});
}

void error_bars(Context& ctx, const CalibrationSnapshot& s) {
  section_heading("Per-view reprojection error");
  if (!s.solution) {
    text_disabled_wrapped(s.solving ? "solving..." : s.solve_error.c_str());
    return;
  }
  const Solution& sol = *s.solution;
  const size_t n = sol.per_view_errors.size();
  double top = 0;
  for (double e : sol.per_view_errors) top = std::max(top, e);
  top = std::max(top * 1.1, 0.1);
  const float w = std::max(ImGui::GetContentRegionAvail().x, 40.0f);
  const float h = 110 * ctx.scale;
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("##bars", {w, h});
  const bool hovered = ImGui::IsItemHovered();
  const bool clicked = ImGui::IsItemClicked(ImGuiMouseButton_Left);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(p0, {p0.x + w, p0.y + h}, IM_COL32(30, 30, 36, 255));
  // The RMS as a line across.
  const float rms_y = p0.y + h - float(sol.rms / top) * h;
  dl->AddLine({p0.x, rms_y}, {p0.x + w, rms_y}, IM_COL32(200, 200, 200, 160), 1.0f);
  const float bw = w / float(std::max<size_t>(n, 1));
  const float mx = ImGui::GetIO().MousePos.x;
  int under = -1;
  for (size_t i = 0; i < n; ++i) {
    const float x0 = p0.x + bw * float(i), x1 = x0 + std::max(1.0f, bw - 2 * ctx.scale);
    const double e = sol.per_view_errors[i];
    const bool present = std::any_of(s.views.begin(), s.views.end(),
                                     [&](const CalibrationView& v) { return v.name == sol.view_names[i]; });
    const bool over = hovered && mx >= x0 && mx < x0 + bw;
    if (over) under = int(i);
    const ImU32 col = !present ? IM_COL32(90, 90, 90, 255) : ramp(float(e / std::max(1e-9, 3 * sol.rms)), over ? 1.0f : 0.85f);
    dl->AddRectFilled({x0, p0.y + h - float(e / top) * h}, {x1, p0.y + h}, col);
    if (over) dl->AddRect({x0, p0.y}, {x1, p0.y + h}, IM_COL32(255, 255, 255, 200));
  }
  if (under >= 0) {
    const std::string& name = sol.view_names[size_t(under)];
    ImGui::SetTooltip("%s: %.3f px\nclick to drop it and solve again", name.c_str(), sol.per_view_errors[size_t(under)]);
    if (clicked) ctx.request(DropCalibrationView{name});
  }
  char worst[200] = "";
  if (!sol.report.worst_first.empty())
    std::snprintf(worst, sizeof worst, ", the worst %s (%.3f px)", sol.report.worst_first.front().first.c_str(),
                  sol.report.worst_first.front().second);
  text_disabled_wrapped(("Views in the order kept" + std::string(worst) +
                         "; the line is the RMS. Click a bar to drop that view and solve again.").c_str());
}

// A grid of values over the image's rectangle, coloured by `colour(value)`, each cell's text in it.
template <class Mat, class Colour, class Label>
void heatmap(Context& ctx, const char* id, const Mat& grid, cv::Size image, Colour colour, Label label) {
  const float w = std::max(ImGui::GetContentRegionAvail().x, 40.0f);
  const float aspect = image.width > 0 ? float(image.height) / float(image.width) : 0.75f;
  const float width = std::min(w, 420 * ctx.scale);
  const float h = width * aspect;
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton(id, {width, h});
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float cw = width / float(grid.cols), ch = h / float(grid.rows);
  for (int r = 0; r < grid.rows; ++r) {
    for (int c = 0; c < grid.cols; ++c) {
      const ImVec2 a{p0.x + cw * float(c), p0.y + ch * float(r)}, b{a.x + cw - 1, a.y + ch - 1};
      dl->AddRectFilled(a, b, colour(grid(r, c)));
      const std::string t = label(grid(r, c));
      const ImVec2 ts = ImGui::CalcTextSize(t.c_str());
      if (ts.x < cw - 2 && ts.y < ch - 2)
        dl->AddText({a.x + (cw - ts.x) / 2, a.y + (ch - ts.y) / 2}, IM_COL32(240, 240, 240, 255), t.c_str());
    }
  }
  dl->AddRect(p0, {p0.x + width, p0.y + h}, IM_COL32(160, 160, 160, 255));
}

void coverage_map(Context& ctx, const CalibrationSnapshot& s) {
  section_heading("Where the corners fell");
  if (s.grid.empty() || s.image_size.area() == 0) return;
  int most = 1;
  for (int r = 0; r < s.grid.rows; ++r)
    for (int c = 0; c < s.grid.cols; ++c) most = std::max(most, s.grid(r, c));
  heatmap(ctx, "##coverage", s.grid, s.image_size,
          [&](int v) {
            return v == 0 ? IM_COL32(70, 30, 30, 255)
                          : ImGui::ColorConvertFloat4ToU32({0.1f, 0.25f + 0.55f * float(v) / float(most), 0.2f, 1.0f});
          },
          [](int v) { return std::to_string(v); });
  text_disabled_wrapped("Corners kept per cell of the image; dark red cells have none yet: show the board there.");
}

void cross_validation(Context& ctx, const CalibrationSnapshot& s) {
  section_heading("Cross-validation");
  if (!s.solution || s.solution->report.cross_validation.empty()) {
    text_disabled_wrapped("The views split in two halves, each solved alone: how far apart their projections fall over "
                          "the image shows where the result can be trusted. It needs more views.");
    return;
  }
  const QualityReport& r = s.solution->report;
  const float top = float(std::max(r.cross_validation_max_px, 1.0));
  heatmap(ctx, "##crossval", r.cross_validation, s.image_size, [&](float v) { return ramp(v / top); },
          [](float v) {
            char b[16];
            std::snprintf(b, sizeof b, "%.1f", double(v));
            return std::string(b);
          });
  ImGui::TextWrapped("The two halves differ by %.2f px at most, %.2f px at the median.", r.cross_validation_max_px,
                     r.cross_validation_median_px);
}

void recent(const CalibrationSnapshot& s) {
  section_heading("Frames");
  if (s.recent.empty()) text_disabled_wrapped(s.capture ? "No frame judged yet." : "Capture is off.");
  for (const CalibrationSnapshot::Judged& j : s.recent) {
    ImGui::PushStyleColor(ImGuiCol_Text, j.kept ? IM_COL32(90, 200, 110, 255) : IM_COL32(190, 190, 190, 255));
    ImGui::TextWrapped("%s: %s", j.frame.c_str(), j.reason.c_str());
    ImGui::PopStyleColor();
  }
}

}  // namespace

void draw_calibration_views(Context& ctx) {
  if (waiting_for_frame(ctx)) return;
  const CalibrationSnapshot* s = ctx.frame->calibration.get();
  if (!s) {
    text_disabled_wrapped("Starting the calibration session...");
    return;
  }
  error_bars(ctx, *s);
  coverage_map(ctx, *s);
  cross_validation(ctx, *s);
  recent(*s);
}

}  // namespace arwb::ui
