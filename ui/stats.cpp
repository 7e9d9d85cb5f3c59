// [SECTION] Index
//   Per frame   each finished frame's stage times and poses, for the Timings and Pose panels and for --stats
//   --stats     one JSON line of figures at exit: timings, the scene, poses, labels, the Lab, export, the
//               Calibrate workspace, the layout
#include "ui/stats.hpp"

#include "ui/app.hpp"
#include "ui/gl_window.hpp"
#include "base/decimals.hpp"
#include "pose/marker_pose.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

namespace arwb {

// [SECTION] Per frame
void App::record_stats() {
  if (!frame || frame->index == totals.last_frame_index) return;
  totals.last_frame_index = frame->index;
  ++totals.detected_seen;
  std::array<float, kStageCount + 1> row{};
  for (const StageRecord& s : frame->trace.stages) {
    const auto i = static_cast<size_t>(s.stage);
    row[i] = static_cast<float>(s.ms);
    totals.stage_ms_sum[i] += s.ms;
    ++totals.stage_ms_n[i];
  }
  row[kStageCount] = static_cast<float>(frame->detect_ms);
  totals.detect_ms_sum += frame->detect_ms;
  for (const PeerDetections& p : frame->peers) {
    if (!p.error.empty()) continue;
    totals.peer_ms[p.name].first += p.ms;
    ++totals.peer_ms[p.name].second;
  }
  status.history.push_back(row);
  while (status.history.size() > 300) status.history.pop_front();
  // Each track's pose over the last frames (the Pose panel's plots); tracks gone are forgotten.
  std::map<uint64_t, std::deque<ui::PoseSample>> poses;
  for (const TrackedMarker& t : frame->tracks) {
    if (!t.pose) continue;
    auto& h = poses[t.track_id];
    if (auto it = status.pose_history.find(t.track_id); it != status.pose_history.end()) h = std::move(it->second);
    const PoseAngles a = pose_angles(t.pose->pose);
    h.push_back({static_cast<float>(frame->time_s), static_cast<float>(a.distance),
                 static_cast<float>(t.pose->ambiguity), static_cast<float>(t.pose->pose.error_px),
                 static_cast<float>(t.pose->alternative.error_px), static_cast<float>(a.tilt_deg)});
    while (h.size() > 300) h.pop_front();
  }
  status.pose_history = std::move(poses);
}

// [SECTION] --stats
namespace {

using Json = nlohmann::ordered_json;

// Each track's pose on the last frame.
Json poses(const App& app) {
  Json poses = Json::array();
  if (app.frame)
    for (const TrackedMarker& t : app.frame->tracks)
      if (t.pose)
        poses.push_back({{"id", t.id},
                         {"instance", t.instance},
                         {"distance", round_decimals(pose_angles(t.pose->pose).distance, 4)},
                         {"tvec", {round_decimals(t.pose->pose.tvec[0], 4), round_decimals(t.pose->pose.tvec[1], 4),
                                   round_decimals(t.pose->pose.tvec[2], 4)}},
                         {"error_px", round_decimals(t.pose->pose.error_px, 3)},
                         {"alternative_error_px", round_decimals(t.pose->alternative.error_px, 3)},
                         {"ambiguity", round_decimals(t.pose->ambiguity, 3)},
                         {"chosen_by_previous", t.pose->chosen_by_previous}});
  return poses;
}

// The Lab workspace: the run's progress, each detector's P_Rec per cell (null: not finished), the cell shown.
Json lab_stats(const App& app) {
  Json lab = {{"running", false}, {"cells", 0}, {"cells_done", 0}};
  if (const lab::LabProgress* p = app.status.lab.get()) {
    lab = {{"running", p->running},        {"finished", p->finished},       {"error", p->error},
           {"plan", p->plan.name},          {"cells", p->cells.size()},      {"cells_done", p->cells_done()},
           {"frames_done", p->frames_done}, {"frames_total", p->frames_total}, {"detectors", p->options.detectors},
           {"camera", p->options.camera_name}};
    Json rates = Json::object();
    for (size_t d = 0; d < p->options.detectors.size(); ++d) {
      Json cells = Json::array();
      for (const auto& r : p->results)
        cells.push_back(r ? Json(round_decimals(r->detectors[d].p_rec(), 2)) : Json());
      rates[p->options.detectors[d]] = cells;
    }
    lab["p_rec"] = rates;
    if (app.status.lab_cell >= 0 && size_t(app.status.lab_cell) < p->results.size() && p->results[size_t(app.status.lab_cell)]) {
      Json marks = Json::object();
      for (size_t d = 0; d < p->options.detectors.size(); ++d)
        marks[p->options.detectors[d]] = p->results[size_t(app.status.lab_cell)]->detectors[d].marks;
      lab["cell_marks"] = marks;
    }
  }
  lab["cell_open"] = app.frame && app.frame->source.kind == SourceKind::lab ? app.status.lab_cell : -1;
  lab["frame"] = app.frame && app.frame->source.kind == SourceKind::lab ? app.frame->source.position : -1;
  lab["message"] = app.status.lab_message;
  lab["plan_set"] = app.settings.lab.plan.name;   // the panel's plan (what Run would run)
  const ClipSummary& c = app.status.lab_clip;   // Record: the clip being recorded, or the last one
  lab["clip"] = {{"recording", app.status.lab_recording}, {"path", c.path}, {"frames", c.frames},
                 {"dropped", c.dropped}, {"error", c.error}};
  return lab;
}

// File > Export... and File > Play bundle...: the last check, the last export.
Json export_stats(const ExportDialog& d) {
  Json rows = Json::array();
  if (d.plan)
    for (const bundle::SelfTestRow& r : d.plan->manifest.self_test)
      rows.push_back({{"id", r.id}, {"line", r.mapping_line}, {"media", r.media}, {"detected", r.detected},
                      {"fired", r.fired}, {"why", r.detail}});
  Json e = {{"checked", d.plan != nullptr},
            {"self_test_passed", d.plan && d.plan->manifest.self_test_passed},
            {"self_test", rows},
            {"error", d.error},
            {"warnings", Json::array()},
            {"written", d.written},
            {"serving", d.server ? d.server->url() : ""},
            {"served_requests", d.server ? d.server->requests() : 0},
            {"serve_error", d.serve_error}};
  if (d.plan)
    for (const std::string& w : d.plan->warnings) e["warnings"].push_back(export_window_wording(w));
  return e;
}

// The players File > Play bundle... started.
Json players_stats(Players& players) {
  std::lock_guard lock(players.mutex);
  return {{"started", players.started},
          {"ended", players.ended},
          {"refused", players.refused},
          {"running", players.running},
          {"exit_codes", players.exit_codes}};
}

// The Calibrate workspace's session as the last frame had it: views kept, refusals by reason, the newest solve
// and its checklist; the calibration loaded with --calib; what the live view was undistorted with.
Json calibration_stats(const App& app) {
  Json c = {{"active", app.frame && app.frame->calibration != nullptr}};
  if (const CalibrationSnapshot* k = app.frame ? app.frame->calibration.get() : nullptr) {
    c["board"] = k->board.describe();
    c["capture"] = k->capture;
    c["frames"] = k->frames;
    c["boards"] = k->boards;
    c["skipped"] = k->skipped;
    c["views"] = k->views.size();
    c["kept"] = k->tally.count("kept") ? k->tally.at("kept") : 0;
    c["dropped"] = k->dropped;
    Json refused = Json::object();
    for (const auto& [kind, n] : k->tally)
      if (kind != "kept") refused[kind] = n;
    c["refused"] = refused;
    c["verdict"] = k->verdict.reason;
    // The board as the live view draws it: on the frame the search judged (board_drawn), which is the newest frame
    // or one before it (board_behind).
    c["board_drawn"] = !k->searched.empty() && k->detection.found;
    c["board_behind"] = k->frame_name != app.frame->calibration_name;
    c["solving"] = k->solving;
    c["solve_error"] = k->solve_error;
    c["coverage"] = {{"x", round_decimals(k->bars.x, 3)}, {"y", round_decimals(k->bars.y, 3)},
                     {"size", round_decimals(k->bars.size, 3)}, {"skew", round_decimals(k->bars.skew, 3)}};
    if (const Solution* sol = k->solution.get()) {
      const cv::Matx33d& K = sol->calibration.camera_matrix;
      c["solved_views"] = sol->view_names.size();
      c["current"] = k->current();
      c["rms"] = round_decimals(sol->rms, 4);
      c["fx"] = round_decimals(K(0, 0), 3);
      c["fy"] = round_decimals(K(1, 1), 3);
      c["cx"] = round_decimals(K(0, 2), 3);
      c["cy"] = round_decimals(K(1, 2), 3);
      c["size"] = std::to_string(sol->calibration.image_size.width) + "x" + std::to_string(sol->calibration.image_size.height);
      c["distortion"] = sol->calibration.distortion;
      Json checks = Json::array();
      for (const Check& ch : sol->report.checklist) checks.push_back({{"name", ch.name}, {"ok", ch.ok}});
      c["checklist"] = checks;
      c["cross_validation_max_px"] = round_decimals(sol->report.cross_validation_max_px, 3);
    }
  }
  if (app.frame && app.frame->calibration_truth) {
    const cv::Matx33d& T = app.frame->calibration_truth->camera_matrix;
    c["truth"] = {{"fx", round_decimals(T(0, 0), 3)}, {"fy", round_decimals(T(1, 1), 3)},
                  {"cx", round_decimals(T(0, 2), 3)}, {"cy", round_decimals(T(1, 2), 3)}};
  }
  c["loaded"] = app.frame && app.frame->loaded_calibration ? app.frame->loaded_calibration->source : "";
  c["undistorted_by"] = app.frame ? app.frame->undistorted_by : "";
  return c;
}

// The layout as drawn in the last frame: regions, overlaps, anything cut off (ui/workspace.hpp LayoutAudit).
Json layout_stats(App& app) {
  Json regions = Json::array();
  Json clipped = Json::array();
  for (const ui::LayoutAudit::Region& r : app.audit.regions) {
    Json panels = Json::array();
    for (ui::Panel p : r.tabs) panels.push_back(ui::panel_key(p));
    regions.push_back({{"panels", panels},
                       {"front", r.front == ui::Panel::count ? "" : ui::panel_key(r.front)},
                       {"rect", {std::lround(r.pos.x), std::lround(r.pos.y), std::lround(r.size.x), std::lround(r.size.y)}}});
    for (ui::Panel p : r.tabs)
      for (const std::string& what : app.audit.clipped[static_cast<size_t>(p)])
        clipped.push_back({{"panel", ui::panel_key(p)}, {"what", what}});
  }
  return {{"workspace", app.workspaces.now().name},
          {"presentation", app.view.presentation},
          {"scale", round_decimals(app.scale, 3)},
          {"font_px", round_decimals(ImGui::GetFontSize(), 1)},
          {"regions", regions},
          {"overlaps", app.audit.overlaps},
          {"clipped", clipped},
          {"off_screen", app.audit.off_screen}};
}

// The Why panel's report on the last frame: its headline and the dictionary it advises adding.
Json why_stats(const App& app) {
  const RegionReport& rep = app.view.region_report;
  Json why = {{"summary", rep.summary},
              {"candidate", rep.candidates.empty() ? -1 : rep.candidates.front().index},
              {"dictionaries", app.settings.dictionaries}};
  if (!rep.other_dictionaries.empty()) {
    why["other_dictionary"] = rep.other_dictionaries.front().dict;
    why["other_id"] = rep.other_dictionaries.front().id;
  }
  return why;
}

}  // namespace

std::string stats_json(App& app, double elapsed, uint64_t detected) {
  const StatsTotals& t = app.totals;
  auto per = [](double sum, int n) { return sum / std::max(1, n); };
  Json s = {{"ui_fps", round_decimals(elapsed > 0 ? t.ui_frames / elapsed : 0, 1)},
            {"detect_fps", round_decimals(elapsed > 0 ? static_cast<double>(detected) / elapsed : 0, 1)},
            {"frames", t.ui_frames},
            {"detected", detected},
            {"stages", Json::object()}};
  for (int i = 0; i < kStageCount; ++i)
    if (const int n = t.stage_ms_n[static_cast<size_t>(i)])
      s["stages"][std::string(stage_name(static_cast<Stage>(i)))] =
          round_decimals(t.stage_ms_sum[static_cast<size_t>(i)] / n, 3);
  // Detection against the peers on the same frames (when they ran): the same run, the same machine load.
  s["detect_ms"] = round_decimals(per(t.detect_ms_sum, t.detected_seen), 3);
  s["peers_ms"] = Json::object();
  for (const auto& [name, v] : t.peer_ms) s["peers_ms"][name] = round_decimals(per(v.first, v.second), 3);
  s["fps_cap"] = round_decimals(app.settings.acquisition.fps_cap, 1);
  s["overlays"] = app.frame ? app.frame->overlays.size() : 0;
  s["composite_ms"] = round_decimals(per(t.composite_ms, t.composites), 2);
  s["scene"] = app.frame ? app.frame->scene.file : "";
  s["scene_ok"] = app.frame && app.frame->scene.ok;
  // Per mapping of the scene: ok, or error / disabled / skipped with the reason and the line it points at.
  s["scene_mappings"] = Json::array();
  if (app.frame)
    for (const MappingRow& r : app.frame->scene.mappings)
      s["scene_mappings"].push_back({{"ids", r.ids},
                                     {"health", mapping_health_name(r.health)},
                                     {"reason", r.reason},
                                     {"line", r.health == MappingHealth::ok ? r.line : r.reason_line}});
  {
    app.log.sync(app.log_copy, app.log_seen);
    int errors = 0;
    for (const LogEntry& e : app.log_copy) errors += e.level == LogLevel::error;
    s["log_errors"] = errors;   // what the Log panel's "error (N)" counts
  }
  s["ui_ms"] = {{"panels", round_decimals(per(t.ui_ms[0], t.ui_frames), 2)},
                {"render", round_decimals(per(t.ui_ms[1], t.ui_frames), 2)},
                {"swap", round_decimals(per(t.ui_ms[2], t.ui_frames), 2)},
                {"uploads", round_decimals(per(app.textures.uploads().ms, t.ui_frames), 2)},
                {"draw_calls", std::llround(per(t.draw_calls, t.ui_frames))},
                {"vertices", std::llround(per(t.vertices, t.ui_frames))}};
  // Where a software renderer's time goes: every pixel covered is shaded and blended, so the covered area over
  // the window's (1: each pixel drawn once) and the texture uploads' count and size per frame.
  s["ui_fill"] = {{"overdraw", round_decimals(t.window_px > 0 ? t.covered_px / t.window_px : 0, 2)},
                  {"uploads_per_frame", round_decimals(per(double(app.textures.uploads().count), t.ui_frames), 2)},
                  {"upload_mb_per_frame", round_decimals(per(app.textures.uploads().bytes / 1e6, t.ui_frames), 2)}};
  s["markers"] = app.frame ? app.frame->trace.markers.size() : 0;
  // Each track's pose on the last frame, the camera it came from, and how many the live view drew in 3D.
  s["poses"] = poses(app);
  s["pose_camera"] = app.frame ? (app.frame->pose_camera.assumed ? "assumed" : app.frame->pose_camera.source) : "";
  s["pose_marker_side"] = app.frame ? app.frame->pose_marker_side : 1.0;
  s["pose_drawn"] = app.view.pose_drawn;
  const ui::LabelReport& lr = app.view.labels;
  s["labels"] = {{"drawn", lr.drawn},         {"hidden", lr.hidden},         {"leaders", lr.leaders},
                 {"shortened", lr.shortened}, {"overlaps", lr.overlaps},     {"on_corners", lr.on_corners},
                 {"boxes", lr.boxes}};
  s["source"] = app.engine->source().text();
  s["frame_label"] = app.frame ? frame_label(*app.frame) : "";   // the live view's
  s["source_position"] = app.frame ? app.frame->source.position : -1;   // the Source panel slider's
  s["working_size"] = app.frame ? std::to_string(app.frame->image.cols) + "x" + std::to_string(app.frame->image.rows) : "";
  s["synthetic_board"] = app.settings.synthetic.board;   // what the synthetic source shows: "" markers, or a board
  s["problems"] = app.log.problems();
  if (app.view.has_region) s["why"] = why_stats(app);
  s["lab"] = lab_stats(app);
  s["export"] = export_stats(app.export_dialog);
  s["players"] = players_stats(*app.players);
  s["frozen"] = app.settings.frozen;
  s["fullscreen"] = ui::is_fullscreen(app.glfw_window);
  s["tour_active"] = app.view.tour_active;
  s["tour_overflow_px"] = std::lround(app.view.tour_overflow_px);
  if (app.frame) {
    const StageViewStyle& vs = app.frame->view_style;
    s["stage_views"] = {{"line", vs.line},
                        {"text_drawn_in", vs.text},
                        {"zoom", app.view.stage_zoom},
                        {"labels_drawn", app.view.stage_labels_drawn},
                        {"label_px", app.view.stage_label_px}};
  }
  const size_t step = size_t(std::max(0, app.view.tour_step));
  s["tour_step"] = step < app.tour.size() ? app.tour[step].key : "";   // the step's name
  s["modal"] = app.dialogs.modal;
  s["script_unsaved"] = app.view.script_unsaved;
  s["undo"] = app.history.undo_name();
  s["redo"] = app.history.redo_name();
  s["note"] = app.note;
  s["params"] = Json::object();
  for (const ParamInfo& info : param_table()) s["params"][info.name] = get_param(app.settings.params, info);
  s["dictionaries"] = app.settings.dictionaries;
  s["calibration"] = calibration_stats(app);
  s["layout"] = layout_stats(app);
  return json_text(s);
}

}  // namespace arwb
