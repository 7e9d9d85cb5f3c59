// Lab: the paper's experiment (section 5) in the window. The plan (its axes as the plan file names them, the
// detectors, the seed, the camera), Run and Stop with the progress, the paper's table filling in cell by cell for
// the detector chosen, and a clicked cell's frames: a strip per detector of what became of each frame, the frame
// shown in the live view with its full trace, and "Why not detected?" on the marker a detector missed. Everything
// is drawn from Status::lab (the run's snapshot) and the frame; the window runs the plan and opens the cells.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include "detect/dictionary.hpp"
#include "lab/cell_source.hpp"
#include "lab/stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace arwb::ui {

namespace {

struct LabView : PanelState {
  int detector = 0;                      // whose P_Rec the grid shows (index into the run's detectors)
  std::array<char[256], 3> axes{};       // the plan's lists as typed
  bool axes_filled = false;
  std::array<std::string, 3> axis_error;
  char plan_file[1024] = "";
  char save_dir[1024] = "";
  std::string plan_shown;                // the plan the fields were filled from (a plan file read replaces it)
};

// Red through yellow to green with P_Rec, for the grid and the frame strip.
ImU32 rate_colour(double p_rec, float alpha = 1.0f) {
  const float t = static_cast<float>(std::clamp(p_rec / 100.0, 0.0, 1.0));
  const float r = t < 0.5f ? 0.85f : 0.85f - (t - 0.5f) * 2 * 0.55f;
  const float g = t < 0.5f ? 0.25f + t * 2 * 0.55f : 0.8f;
  return ImGui::ColorConvertFloat4ToU32({r, g, 0.25f, alpha});
}

ImU32 mark_colour(char m) {
  switch (m) {
    case lab::mark::detected: return IM_COL32(80, 190, 100, 255);
    case lab::mark::missed: return IM_COL32(215, 70, 60, 255);
    case lab::mark::wrong_id: return IM_COL32(230, 150, 40, 255);
    case lab::mark::clean: return IM_COL32(110, 110, 120, 255);
    case lab::mark::false_positive: return IM_COL32(200, 60, 200, 255);
    default: return IM_COL32(60, 60, 60, 255);
  }
}

const char* mark_words(char m) {
  switch (m) {
    case lab::mark::detected: return "detected";
    case lab::mark::missed: return "missed";
    case lab::mark::wrong_id: return "another id only";
    case lab::mark::clean: return "no marker, nothing reported";
    case lab::mark::false_positive: return "no marker, a false positive";
    default: return "not counted (marker not wholly in view)";
  }
}

void fill_axes(LabView& v, const lab::LabPlan& plan) {
  const auto& axes = lab::plan_axes();
  for (size_t i = 0; i < axes.size() && i < v.axes.size(); ++i) {
    std::snprintf(v.axes[i], sizeof v.axes[i], "%s", lab::axis_text(plan.*axes[i].values).c_str());
    v.axis_error[i].clear();
  }
  v.axes_filled = true;
}

void plan_section(Context& ctx, LabView& v, bool running) {
  LabSettings& ls = ctx.settings.lab;
  lab::LabPlan& plan = ls.plan;
  const std::string shown = plan.name + "|" + lab::axis_text(plan.sizes_mm) + "|" + lab::axis_text(plan.distances_m) +
                            "|" + lab::axis_text(plan.lux);
  if (!v.axes_filled || (v.plan_shown != shown && !ImGui::IsAnyItemActive())) fill_axes(v, plan);
  v.plan_shown = shown;
  ImGui::BeginDisabled(running);
  const float w = 170 * ctx.scale;
  static const char* kLabels[3] = {"marker sides (mm)", "distances (m)", "light (lux)"};
  const auto& axes = lab::plan_axes();
  for (size_t i = 0; i < axes.size() && i < 3; ++i) {
    fit_item_width(w * 1.4f, kLabels[i]);
    if (ImGui::InputText(kLabels[i], v.axes[i], sizeof v.axes[i])) {
      Result<std::vector<double>> r = lab::parse_axis(axes[i], v.axes[i]);
      if (r) {
        plan.*axes[i].values = *r;
        plan.name = "your plan";
        v.axis_error[i].clear();
      } else {
        v.axis_error[i] = r.error();
      }
    }
    if (!v.axis_error[i].empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.45f, 0.35f, 1));
      ImGui::TextWrapped("%s", v.axis_error[i].c_str());
      ImGui::PopStyleColor();
    }
  }
  fit_item_width(w, "frames per cell");
  if (ImGui::InputInt("frames per cell", &plan.frames_per_cell)) plan.name = "your plan";
  plan.frames_per_cell = std::clamp(plan.frames_per_cell, 1, 10000);
  fit_item_width(w, "markers");
  if (ImGui::InputInt("markers", &plan.markers)) plan.name = "your plan";
  if (const auto d = dictionary_by_name(plan.dictionary)) plan.markers = std::clamp(plan.markers, 1, d->size());
  float tilt = static_cast<float>(plan.max_tilt_deg);
  fit_item_width(w, "tilt up to");
  if (ImGui::SliderFloat("tilt up to", &tilt, 0, 80, "%.0f deg")) {
    plan.max_tilt_deg = tilt;
    plan.name = "your plan";
  }
  fit_item_width(w, "seed");
  ImGui::InputInt("seed", &ls.seed);
  ls.seed = std::max(0, ls.seed);
  fit_item_width(w, "dictionary");
  if (ImGui::BeginCombo("dictionary", plan.dictionary.c_str())) {
    for (const std::string& name : dictionary_names()) {
      if (ImGui::Selectable(name.c_str(), name == plan.dictionary)) {
        plan.dictionary = name;
        plan.name = "your plan";
      }
    }
    ImGui::EndCombo();
  }
  ImGui::TextUnformatted("detectors:");
  for (const std::string& name : lab::kLabDetectors) {
    flow(checkbox_width(name.c_str()));
    bool on = std::find(ls.detectors.begin(), ls.detectors.end(), name) != ls.detectors.end();
    if (ImGui::Checkbox(name.c_str(), &on)) {
      std::vector<std::string> next;
      for (const std::string& k : lab::kLabDetectors) {
        const bool was = std::find(ls.detectors.begin(), ls.detectors.end(), k) != ls.detectors.end();
        if (k == name ? on : was) next.push_back(k);
      }
      ls.detectors = next;
    }
    if (ImGui::IsItemHovered()) {
      ImGui::SetTooltip("%s", name == "arwb"            ? "arwb with the Parameters panel's values"
                              : name == "opencv"        ? "OpenCV 4.6's aruco, default parameters"
                              : name == "opencv-aruco3" ? "OpenCV's ArUco3 mode (useAruco3Detection)"
                                                        : "AprilTag 3 (AprilTag families only)");
    }
  }
  const bool calibrated = ctx.frame && ctx.frame->loaded_calibration;
  if (calibrated) {
    ImGui::Checkbox("through the loaded calibration", &ls.use_calibration);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", ctx.frame->loaded_calibration->source.c_str());
  } else {
    text_disabled_wrapped("Camera: the default webcam, 640x480 and 60 degrees across (docs/lab.md); --calib FILE "
                          "renders through yours.");
  }
  // A plan file, or back to the paper's.
  fit_item_width(w * 1.4f, "##plan_file");
  ImGui::InputTextWithHint("##plan_file", "a plan file (.yml)", v.plan_file, sizeof v.plan_file);
  flow(button_width("Read plan"));
  if (ImGui::Button("Read plan") && v.plan_file[0]) ctx.request(ReadLabPlan{v.plan_file});
  flow(button_width("The paper's plan"));
  if (ImGui::Button("The paper's plan")) {
    plan = lab::paper_plan();
    ls.seed = 1;
  }
  ImGui::EndDisabled();
  // The axes only a plan file sets (docs/lab.md), named so the fields above are not taken for the whole plan.
  std::string added;
  auto add = [&](bool has, const char* what, const std::vector<double>& values) {
    if (has) added += (added.empty() ? "" : "; ") + std::string(what) + " " + lab::axis_text(values);
  };
  add(!plan.sides_px.empty(), "sides (px, instead of the sizes)", plan.sides_px);
  add(plan.has_tilts(), "tilts (deg, instead of up to)", plan.tilts_deg);
  add(plan.has_blurs(), "added blur (px)", plan.blurs_px);
  add(plan.has_noises(), "added noise", plan.noises);
  add(plan.has_occlusions(), "occluded", plan.occlusions);
  if (!added.empty()) text_disabled_wrapped(("From the plan file: " + added).c_str());
  const int frames = int(plan.cell_count()) * (plan.frames_per_cell + plan.empty_frames_per_cell());
  const std::string curves = plan.curves_text().empty() ? "" : ", and " + plan.curves_text();
  char b[400];
  std::snprintf(b, sizeof b, "%s: %zu cells x %d frames (and %d without a marker)%s, %d frames in all",
                plan.name.c_str(), plan.grid_count(), plan.frames_per_cell, plan.empty_frames_per_cell(),
                curves.c_str(), frames);
  text_disabled_wrapped(b);
}

void run_section(Context& ctx, const lab::LabProgress* p) {
  const bool running = p && p->running;
  if (!running) {
    const bool ok = !ctx.settings.lab.detectors.empty();
    ImGui::BeginDisabled(!ok);
    if (ImGui::Button("Run")) ctx.request(StartLab{});
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Renders every cell's frames and gives them to every detector.");
  } else if (ImGui::Button("Stop")) {
    ctx.request(StopLab{});
  }
  if (!p || p->frames_total == 0) {
    if (!running) {
      ImGui::SameLine();
      ImGui::TextDisabled("No run yet: set up the plan and press Run.");
    }
  } else {
    ImGui::SameLine();
    char b[200];
    const double f = double(p->frames_done) / p->frames_total;
    if (running) {
      const double left = f > 0.02 ? p->seconds * (1 - f) / f : -1;
      std::snprintf(b, sizeof b, "cell %d of %zu, %.0f s%s", std::min(p->cells_done() + 1, int(p->cells.size())),
                    p->cells.size(), p->seconds, left >= 0 ? (", about " + std::to_string(int(left + 0.5)) + " s left").c_str() : "");
    } else {
      std::snprintf(b, sizeof b, "%d of %zu cells in %.1f s", p->cells_done(), p->cells.size(), p->seconds);
    }
    ImGui::ProgressBar(static_cast<float>(f), {-1, 0}, b);
  }
  if (!ctx.status.lab_message.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text,
                          ctx.status.lab_message_error ? ImVec4(1, 0.45f, 0.35f, 1) : ImVec4(0.7f, 0.85f, 0.7f, 1));
    ImGui::TextWrapped("%s", ctx.status.lab_message.c_str());
    ImGui::PopStyleColor();
  }
}

// The paper's table for one detector: a row per size and distance, a column per light level; a finished cell
// shows P_Rec on its colour, and a click opens its frames.
void grid(Context& ctx, LabView& v, const lab::LabProgress& p) {
  const auto& dets = p.options.detectors;
  if (dets.empty()) return;
  v.detector = std::clamp(v.detector, 0, int(dets.size()) - 1);
  for (size_t d = 0; d < dets.size(); ++d) {
    if (d) flow(checkbox_width(dets[d].c_str()));
    ImGui::RadioButton(dets[d].c_str(), &v.detector, int(d));
  }
  const size_t L = p.plan.lux.size();
  if (L == 0) return;
  const int cols = int(L) + 1;
  const ImGuiTableFlags flags = ImGuiTableFlags_Borders | ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_ScrollX |
                                ImGuiTableFlags_ScrollY;
  const float row_h = ImGui::GetFrameHeightWithSpacing();
  // The grid's cells (the curves' cells after them are in the report and table.txt).
  const size_t grid = std::min(p.cells.size(), p.plan.grid_count());
  const float height = std::min(row_h * float(grid / L + 1) + 6, 14 * row_h);
  if (!ImGui::BeginTable("lab_grid", cols, flags, {0, height})) return;
  ImGui::TableSetupScrollFreeze(1, 1);
  ImGui::TableSetupColumn("size, distance");
  char b[160];
  for (double l : p.plan.lux) {
    std::snprintf(b, sizeof b, "%g lx", l);
    ImGui::TableSetupColumn(b);
  }
  ImGui::TableHeadersRow();
  const float cell_w = ImGui::CalcTextSize("100% [100-100]").x;
  for (size_t i = 0; i < grid; i += L) {
    ImGui::TableNextRow();
    ImGui::TableSetColumnIndex(0);
    const lab::Cell& c0 = p.cells[i];
    const lab::CellResult* r0 = p.results[i].get();
    if (c0.side_px > 0) std::snprintf(b, sizeof b, "%g px at %g m", c0.side_px, c0.distance_m);   // sides_px
    else if (r0) std::snprintf(b, sizeof b, "%g mm at %g m (%.0f px)", c0.size_mm, c0.distance_m, r0->side_px);
    else std::snprintf(b, sizeof b, "%g mm at %g m", c0.size_mm, c0.distance_m);
    // Rows are every combination but light: the added axes the plan has name theirs ("tilt 60 blur 1.5").
    const std::string added = lab::added_axes_text(p.plan, c0);
    ImGui::TextUnformatted(added.empty() ? b : (std::string(b) + ", " + added).c_str());
    for (size_t j = i; j < i + L && j < grid; ++j) {
      ImGui::TableSetColumnIndex(int(j - i) + 1);
      const lab::CellResult* r = p.results[j].get();
      ImGui::PushID(int(j));
      const bool open = ctx.status.lab_cell == int(j) && ctx.frame && ctx.frame->source.kind == SourceKind::lab;
      if (!r || size_t(v.detector) >= r->detectors.size()) {
        const bool now = p.running && int(j) == p.cells_done();
        ImGui::TextDisabled("%s", now ? "running..." : "...");
      } else {
        const lab::DetectorTally& t = r->detectors[size_t(v.detector)];
        if (t.frames == 0) {
          std::snprintf(b, sizeof b, "-");
        } else {
          const auto [lo, hi] = lab::wilson_interval(t.detected, t.frames);
          std::snprintf(b, sizeof b, "%.0f%% [%.0f-%.0f]", t.p_rec(), 100 * lo, 100 * hi);
        }
        if (t.frames) ImGui::TableSetBgColor(ImGuiTableBgTarget_CellBg, rate_colour(t.p_rec(), 0.55f));
        if (ImGui::Selectable(b, open, 0, {cell_w, 0})) ctx.request(OpenLabCell{int(j)});
        if (ImGui::IsItemHovered()) {
          ImGui::SetTooltip("%s, %s: %d of %d frames (P_Rec %.1f%%)\nanother id on %d frames; %d false positives on "
                            "%d frames without a marker\nmedian %.2f ms a frame\nexposure %.1f ms, gain %.2f, "
                            "black-on-white SNR %.1f, blur %.1f px\nClick: its frames in the live view.",
                            lab::cell_name(r->cell).c_str(), dets[size_t(v.detector)].c_str(), t.detected, t.frames,
                            t.p_rec(), t.wrong_id, t.false_positives, t.empty_frames, t.median_ms(), r->exposure_ms,
                            r->gain, r->snr_black_white, r->blur_px);
        }
      }
      ImGui::PopID();
    }
  }
  ImGui::EndTable();
  if (const std::string curves = p.plan.curves_text(); !curves.empty())
    text_disabled_wrapped(("And " + curves + ": in table.txt and the report.").c_str());
}

// The opened cell: a strip per detector, a square per frame (click: that frame), the frame's verdicts, and the
// way from a missed frame to why.
void cell_section(Context& ctx, LabView& v, const lab::LabProgress& p) {
  const int ci = ctx.status.lab_cell;
  const Frame* f = ctx.frame;
  if (ci < 0 || size_t(ci) >= p.results.size() || !p.results[size_t(ci)] || !f || f->source.kind != SourceKind::lab) {
    text_disabled_wrapped("Click a finished cell to see its frames in the live view, with their traces.");
    return;
  }
  const lab::CellResult& r = *p.results[size_t(ci)];
  ImGui::Separator();
  ImGui::TextWrapped("%s: frame %d of %d", lab::cell_name(r.cell).c_str(), f->source.position + 1, f->source.count);
  const auto& dets = p.options.detectors;
  const float sq = std::max(6.0f, std::min(14 * ctx.scale, (ImGui::GetContentRegionAvail().x - 120 * ctx.scale) /
                                                              float(std::max(1, f->source.count))));
  const float label_w = 110 * ctx.scale;
  for (size_t d = 0; d < dets.size() && d < r.detectors.size(); ++d) {
    const std::string& marks = r.detectors[d].marks;
    ImGui::TextUnformatted(dets[d].c_str());
    ImGui::SameLine(label_w);
    ImDrawList* dl = ImGui::GetWindowDrawList();
    for (size_t k = 0; k < marks.size(); ++k) {
      if (k) ImGui::SameLine(0, 1);
      ImGui::PushID(int(d * 100000 + k));
      const ImVec2 at = ImGui::GetCursorScreenPos();
      if (ImGui::InvisibleButton("f", {sq, sq})) ctx.request(Seek{int(k)});
      dl->AddRectFilled(at, {at.x + sq, at.y + sq}, mark_colour(marks[k]));
      if (int(k) == f->source.position) dl->AddRect(at, {at.x + sq, at.y + sq}, IM_COL32(255, 255, 255, 255), 0, 0, 2);
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("frame %zu: %s", k + 1, mark_words(marks[k]));
      ImGui::PopID();
    }
  }
  // This frame's verdicts, and stepping to the next frame the chosen detector missed.
  const size_t k = size_t(std::max(0, f->source.position));
  std::string verdicts;
  for (size_t d = 0; d < dets.size() && d < r.detectors.size(); ++d) {
    if (k < r.detectors[d].marks.size())
      verdicts += (verdicts.empty() ? "" : "; ") + dets[d] + " " + mark_words(r.detectors[d].marks[k]);
  }
  text_disabled_wrapped(f->source.item.c_str());
  ImGui::TextWrapped("%s", verdicts.c_str());
  const size_t det = size_t(std::clamp(v.detector, 0, int(r.detectors.size()) - 1));
  const std::string& marks = r.detectors[det].marks;
  auto missed_from = [&](int from, int dir) {
    for (int i = from + dir; i >= 0 && i < int(marks.size()); i += dir)
      if (marks[size_t(i)] == lab::mark::missed || marks[size_t(i)] == lab::mark::wrong_id) return i;
    return -1;
  };
  const int prev = missed_from(int(k), -1), next = missed_from(int(k), +1);
  ImGui::BeginDisabled(prev < 0);
  if (ImGui::Button("< missed")) ctx.request(Seek{prev});
  ImGui::EndDisabled();
  flow(button_width("missed >"));
  ImGui::BeginDisabled(next < 0);
  if (ImGui::Button("missed >")) ctx.request(Seek{next});
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("The next frame %s missed.", dets[det].c_str());
  // "Why not detected?" on the marker, from its exact corners: the region the Why panel explains.
  if (!f->truth.empty()) {
    flow(button_width("Why not detected?"));
    if (ImGui::Button("Why not detected?")) why_on_marker(ctx.view, f->truth[0].corners);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("The Why panel on the marker's exact place: every candidate there and the stage and\n"
                        "parameter that dropped it.");
  }
  if (!(p.options.params == f->params) && std::find(dets.begin(), dets.end(), "arwb") != dets.end()) {
    text_disabled_wrapped("The parameters changed since the run: the live view's arwb may not agree with its strip.");
  }
}

void save_section(Context& ctx, LabView& v, const lab::LabProgress& p) {
  if (!p.complete) return;
  ImGui::Separator();
  if (!v.save_dir[0]) std::snprintf(v.save_dir, sizeof v.save_dir, "%s/lab/%s", ctx.status.config_dir.c_str(),
                                    p.plan.name.c_str());
  fit_item_width(260 * ctx.scale, "##save_dir");
  ImGui::InputText("##save_dir", v.save_dir, sizeof v.save_dir);
  flow(button_width("Save report"));
  ImGui::BeginDisabled(ctx.status.lab_saving);
  if (ImGui::Button("Save report")) ctx.request(SaveLabReport{v.save_dir});
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("table.txt, table.csv, results.json, the PNG plots and report.pdf, as arwb lab --out writes.");
}

}  // namespace

void draw_lab(Context& ctx) {
  LabView& v = panel_state<LabView>(ctx.view, Panel::lab);
  const lab::LabProgress* p = ctx.status.lab.get();
  const bool running = p && p->running;
  if (ImGui::CollapsingHeader("Plan", running ? 0 : ImGuiTreeNodeFlags_DefaultOpen)) plan_section(ctx, v, running);
  run_section(ctx, p);
  if (p && !p->cells.empty()) {
    grid(ctx, v, *p);
    cell_section(ctx, v, *p);
    save_section(ctx, v, *p);
  }
  draw_lab_clips(ctx);   // after the run's results, which a finished run is opened for
}

}  // namespace arwb::ui
