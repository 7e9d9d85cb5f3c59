// Calibrate: the coach. The board looked for (and its settings), capture on or off, the live view undistorted,
// Reset and Save; what became of this frame and of the frames so far (kept, or refused and why); the four criteria
// of OpenCV's interactive-calibration app turning green; ROS's X, Y, size and skew coverage bars filling up; and
// the camera: fx, fy, cx, cy and the distortion with their uncertainty and, on the synthetic board, the truth and
// the difference. Everything is drawn from the frame's calibration snapshot, which the worker makes.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include "calibration/session.hpp"
#include "detect/dictionary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace arwb::ui {

namespace {

const ImU32 kGood = IM_COL32(90, 200, 110, 255);
const ImU32 kPoor = IM_COL32(230, 150, 60, 255);

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

// The board's settings as BoardSpec has them; a board that cannot exist is named and not used.
void board_settings(Context& ctx) {
  BoardSpec& b = ctx.settings.calibration.board;
  const float w = 150 * ctx.scale;
  int kind = b.kind == BoardKind::charuco ? 1 : 0;
  const int before = kind;
  ImGui::RadioButton("chessboard", &kind, 0);
  flow(checkbox_width("ChArUco"));
  ImGui::RadioButton("ChArUco", &kind, 1);
  if (kind != before) b = default_board(kind ? BoardKind::charuco : BoardKind::chessboard);
  const bool charuco = b.kind == BoardKind::charuco;
  fit_item_width(w, charuco ? "squares across" : "inner corners across");
  ImGui::InputInt(charuco ? "squares across" : "inner corners across", &b.cols);
  fit_item_width(w, charuco ? "squares down" : "inner corners down");
  ImGui::InputInt(charuco ? "squares down" : "inner corners down", &b.rows);
  b.cols = std::clamp(b.cols, 2, 40);
  b.rows = std::clamp(b.rows, 2, 40);
  fit_item_width(w, "square (mm)");
  ImGui::InputDouble("square (mm)", &b.square_mm, 1, 5, "%.2f");
  b.square_mm = std::clamp(b.square_mm, 1.0, 500.0);
  if (charuco) {
    fit_item_width(w, "marker (mm)");
    ImGui::InputDouble("marker (mm)", &b.marker_mm, 1, 5, "%.2f");
    b.marker_mm = std::clamp(b.marker_mm, 0.0, 500.0);
    fit_item_width(w, "dictionary");
    if (ImGui::BeginCombo("dictionary", b.dictionary.c_str(), ImGuiComboFlags_HeightLarge)) {
      for (const std::string& n : dictionary_names())
        if (n.rfind("DICT_", 0) == 0 && ImGui::Selectable(n.c_str(), n == b.dictionary)) b.dictionary = n;
      ImGui::EndCombo();
    }
    text_disabled_wrapped("Boards of OpenCV 4.6's layout; boards printed for the older layout are not read.");
  }
  if (const std::string p = b.problem(); !p.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kPoor);
    ImGui::TextWrapped("%s (the previous board stays in use)", p.c_str());
    ImGui::PopStyleColor();
  }
}

void toolbar(Context& ctx, const CalibrationSnapshot* s) {
  CalibrationSettings& c = ctx.settings.calibration;
  ImGui::Checkbox("Capture", &c.capture);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Judge every frame and keep those that make good views");
  flow(checkbox_width("Undistorted view"));
  ImGui::Checkbox("Undistorted view", &c.undistort);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("The live view undistorted with the newest solve (or the calibration loaded with --calib)");
  flow(button_width("Reset"));
  if (ImGui::Button("Reset")) ctx.request(ResetCalibration{});
  const bool can_save = s && s->solution;
  flow(button_width("Save..."));
  ImGui::BeginDisabled(!can_save);
  if (ImGui::Button("Save...")) ctx.request(SaveCalibrationAs{});
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip(can_save ? "Write the calibration (OpenCV FileStorage, .xml or .yml)" : "Nothing solved yet");
  flow(checkbox_width("+ paper's files"));
  ImGui::Checkbox("+ paper's files", &ctx.view.calibration_paper_files);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Also write cameraMatrix.xml and distCoeffs.xml beside the file saved");
  ImGui::TextWrapped("Board: %s", c.board.describe().c_str());
  flow(button_width("Board..."));
  if (ImGui::Button("Board...")) ImGui::OpenPopup("board");
  if (ImGui::BeginPopup("board")) {
    board_settings(ctx);
    ImGui::EndPopup();
  }
}

void frames_so_far(const CalibrationSnapshot& s, SourceKind source) {
  if (!s.frame_name.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, s.verdict.keep ? kGood : (s.detection.found ? kPoor : IM_COL32(170, 170, 170, 255)));
    ImGui::TextWrapped("%s: %s", s.frame_name.c_str(), s.verdict.reason.c_str());
    ImGui::PopStyleColor();
  }
  ImGui::TextWrapped("%d frames judged, board in %d, %zu views kept", s.frames, s.boards, s.views.size());
  // Frames that went by lose nothing where they repeat a still (a folder's photographs, an image): said only for
  // a board that moves. Only a person holding one can hold it still; the synthetic board moves as its source says.
  const bool still = source == SourceKind::folder || source == SourceKind::image;
  if (s.skipped > 0 && !still) {
    const char* why = source == SourceKind::synthetic ? "" : " (hold the board still: a view needs two frames alike)";
    text_disabled_wrapped((std::to_string(s.skipped) + " frames went by while the board was being searched for" +
                           why).c_str());
  }
  std::string refused;
  for (const auto& [kind, n] : s.tally)
    if (kind != "kept") refused += (refused.empty() ? "" : ", ") + kind + " " + std::to_string(n);
  if (!refused.empty()) text_disabled_wrapped(("refused: " + refused).c_str());
}

void checklist(const CalibrationSnapshot& s) {
  section_heading("Checklist");
  if (!s.solution) {
    for (const char* name : {"enough views", "RMS reprojection error", "95 % intervals under 5 %", "square pixels",
                             "image coverage"}) {
      chip("no", kPoor, false);
      ImGui::SameLine();
      ImGui::TextDisabled("%s", name);
    }
    text_disabled_wrapped(s.solving ? "solving..." : s.solve_error.c_str());
    return;
  }
  for (const Check& c : s.solution->report.checklist) {
    chip(c.ok ? "ok##c" : "no##c", c.ok ? kGood : kPoor, c.ok);
    ImGui::SameLine();
    ImGui::TextWrapped("%s: %s", c.name.c_str(), c.detail.c_str());
  }
  if (!s.current()) {
    const std::string what = s.solving ? "solving the newest views..."
                                       : (s.solve_error.empty() ? "" : "the newest views: " + s.solve_error);
    if (!what.empty()) text_disabled_wrapped(("For " + std::to_string(s.solution->view_names.size()) + " views; " + what).c_str());
  }
}

void coverage(const CalibrationSnapshot& s) {
  section_heading("Coverage");
  const float label = ImGui::CalcTextSize("skew").x + ImGui::GetStyle().ItemSpacing.x;
  const std::pair<const char*, double> bars[] = {{"X", s.bars.x}, {"Y", s.bars.y}, {"size", s.bars.size}, {"skew", s.bars.skew}};
  for (const auto& [name, v] : bars) {
    ImGui::TextUnformatted(name);
    ImGui::SameLine(label + ImGui::GetStyle().WindowPadding.x);
    ImGui::PushStyleColor(ImGuiCol_PlotHistogram, v >= 0.5 ? kGood : kPoor);
    const std::string overlay = fmt("%.0f %%", 100 * v);
    ImGui::ProgressBar(float(v), {-FLT_MIN, ImGui::GetTextLineHeight() * 1.1f}, overlay.c_str());
    ImGui::PopStyleColor();
  }
  ImGui::TextWrapped("%s", s.advice.c_str());
}

// fx fy cx cy and the distortion: the value, one standard deviation, and the truth and the difference when known.
void camera(const CalibrationSnapshot* s, const Frame& f) {
  const Solution* sol = s && s->solution ? s->solution.get() : nullptr;
  const Calibration* c = sol ? &sol->calibration : f.loaded_calibration.get();
  section_heading("Camera");
  if (!c) {
    text_disabled_wrapped("No calibration yet: keep at least 6 views (move the board to many places, tilted), or "
                          "start with --calib FILE.");
    return;
  }
  if (!sol) ImGui::TextWrapped("From %s (made for %dx%d)", c->source.c_str(), c->image_size.width, c->image_size.height);
  const Calibration* truth = f.calibration_truth ? &*f.calibration_truth : nullptr;
  const int cols = truth ? 5 : 3;
  const ImGuiTableFlags tf = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_SizingStretchProp;
  if (!ImGui::BeginTable("camera", cols, tf)) return;
  ImGui::TableSetupColumn("");
  ImGui::TableSetupColumn("value");
  ImGui::TableSetupColumn("± (1 sd)");
  if (truth) {
    ImGui::TableSetupColumn("truth");
    ImGui::TableSetupColumn("diff");
  }
  ImGui::TableHeadersRow();
  auto row = [&](const char* name, double v, double sd, bool has_sd, bool fixed, double t, bool pixels) {
    const char* f4 = pixels ? "%.2f" : "%.4f";
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(name);
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(fmt(f4, v).c_str());
    ImGui::TableNextColumn();
    if (fixed) ImGui::TextDisabled("fixed");   // not estimated: no interval, rather than one of 0
    else if (has_sd) ImGui::TextUnformatted(fmt(f4, sd).c_str());
    if (truth) {
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(fmt(f4, t).c_str());
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(fmt(pixels ? "%+.2f" : "%+.4f", v - t).c_str());
    }
  };
  const cv::Matx33d& K = c->camera_matrix;
  const double kv[4] = {K(0, 0), K(1, 1), K(0, 2), K(1, 2)};
  const char* kn[4] = {"fx", "fy", "cx", "cy"};
  for (int i = 0; i < 4; ++i) {
    const bool has = sol && sol->std_intrinsics.size() > size_t(i);
    const double t = truth ? (i == 0 ? truth->camera_matrix(0, 0) : i == 1 ? truth->camera_matrix(1, 1)
                             : i == 2 ? truth->camera_matrix(0, 2) : truth->camera_matrix(1, 2)) : 0;
    row(kn[i], kv[i], has ? sol->std_intrinsics[size_t(i)] : 0, has, sol && i >= 2 && sol->fixed_principal_point, t,
        true);
  }
  const char* dn[5] = {"k1", "k2", "p1", "p2", "k3"};
  for (size_t i = 0; i < c->distortion.size() && i < 5; ++i) {
    const bool has = sol && sol->std_distortion.size() > i;
    const double t = truth && truth->distortion.size() > i ? truth->distortion[i] : 0;
    row(dn[i], c->distortion[i], has ? sol->std_distortion[i] : 0, has, sol && i == 4 && sol->fixed_k3, t, false);
  }
  ImGui::EndTable();
  if (sol) {
    ImGui::TextWrapped("RMS reprojection error %.3f px over %zu views (OpenCV's defaults on all of them: %.3f px)",
                       sol->rms, sol->view_names.size(), sol->opencv_defaults_rms);
    for (const std::string& n : sol->notes) text_disabled_wrapped(("note: " + n).c_str());
    ImGui::TextWrapped("For %dx%d frames (the source's own size, before the resize; fitted to the working size "
                       "where it is used).", c->image_size.width, c->image_size.height);
  }
  if (truth) text_disabled_wrapped("The truth: the synthetic source's camera, which the board is seen through.");
}

}  // namespace

void draw_calibrate(Context& ctx) {
  const CalibrationSnapshot* s = ctx.frame ? ctx.frame->calibration.get() : nullptr;
  toolbar(ctx, s);
  if (waiting_for_frame(ctx)) return;
  if (!s) {
    text_disabled_wrapped("Starting the calibration session...");
    return;
  }
  ImGui::Separator();
  frames_so_far(*s, ctx.frame->source.kind);
  checklist(*s);
  coverage(*s);
  camera(s, *ctx.frame);
}

}  // namespace arwb::ui
