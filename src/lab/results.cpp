// A lab run's results written out (run.hpp): the paper's table as text and CSV; everything as JSON. The line a
// finished cell is saved as is cells_file.cpp's.
#include "lab/run.hpp"

#include "lab/stats.hpp"
#include "base/decimals.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace arwb::lab {

namespace {

const char* curve_name(const Cell& c) {
  return c.curve == kBlurCurve ? "blur" : c.curve == kNoiseCurve ? "noise" : "";
}

// A detector's blur and noise curves under its part of the table: the grid's cell at curve_at, then each curve
// cell, P_Rec with its interval. Nothing when the run has no curve cell.
std::string curves_text(const LabResults& r, size_t d) {
  const long base = r.plan.curve_base();
  if (base < 0 || size_t(base) >= r.cells.size() || r.cells.size() <= r.plan.grid_count()) return "";
  char b[200];
  const CellResult& at = r.cells[size_t(base)];
  std::snprintf(b, sizeof b, "blur and noise at %g mm, %g m, %g lx (%.0f px), on the same frames:\n", at.cell.size_mm,
                at.cell.distance_m, at.cell.lux, at.side_px);
  std::string s = b;
  auto row = [&](const char* what, double v, const DetectorTally& t) {
    const auto [lo, hi] = wilson_interval(t.detected, t.frames);
    std::snprintf(b, sizeof b, "  added %-5s %4g  %5.1f [%4.0f-%3.0f]\n", what, v, t.p_rec(), 100 * lo, 100 * hi);
    s += b;
  };
  for (int curve : {kBlurCurve, kNoiseCurve}) {
    const char* what = curve == kBlurCurve ? "blur" : "noise";
    row(what, 0, at.detectors[d]);
    for (size_t i = r.plan.grid_count(); i < r.cells.size(); ++i)
      if (r.cells[i].cell.curve == curve)
        row(what, curve == kBlurCurve ? r.cells[i].cell.blur_px : r.cells[i].cell.noise, r.cells[i].detectors[d]);
  }
  return s;
}

}  // namespace

std::string lab_table_text(const LabResults& r) {
  std::string s;
  char b[256];
  // The grid's cells; the curves' come after them.
  const size_t grid = std::min(r.cells.size(), r.plan.grid_count());
  // The added axes' values of each row (nothing for the paper's plan), each axis's values padded to one width so
  // the columns stay in line: "tilt 0  blur 1.5", "tilt 60 blur 1.5".
  const size_t per_row = std::max<size_t>(1, r.plan.lux.size());
  const struct {
    bool has;
    const char* name;
    double Cell::*value;
  } axes[] = {{r.plan.has_tilts(), "tilt", &Cell::tilt_deg},
              {r.plan.has_blurs(), "blur", &Cell::blur_px},
              {r.plan.has_noises(), "noise", &Cell::noise},
              {r.plan.has_occlusions(), "occluded", &Cell::occlusion}};
  std::vector<std::vector<std::string>> values;   // per row, per axis the plan has
  std::vector<size_t> widths(std::size(axes), 0);
  for (size_t i = 0; i < grid; i += per_row) {
    values.emplace_back();
    for (size_t a = 0; a < std::size(axes); ++a) {
      if (!axes[a].has) continue;
      std::snprintf(b, sizeof b, "%g", r.cells[i].cell.*axes[a].value);
      values.back().push_back(b);
      widths[a] = std::max(widths[a], values.back().back().size());
    }
  }
  std::vector<std::string> added;
  for (const std::vector<std::string>& row : values) {
    std::string text;
    for (size_t a = 0, v = 0; a < std::size(axes); ++a) {
      if (!axes[a].has) continue;
      text += std::string(" ") + axes[a].name + " " + row[v] + std::string(widths[a] - row[v].size(), ' ');
      ++v;
    }
    added.push_back(text);
  }
  const int label_width = 20 + int(added.empty() ? 0 : added[0].size());
  for (size_t d = 0; d < r.options.detectors.size(); ++d) {
    std::snprintf(b, sizeof b, "%s: P_Rec %% [95%% interval]\n%-*s", r.options.detectors[d].c_str(), label_width,
                  "size, distance");
    s += b;
    for (double l : r.plan.lux) {
      std::snprintf(b, sizeof b, "  %14.0f lx", l);
      s += b;
    }
    s += "\n";
    for (size_t i = 0; i < grid; i += r.plan.lux.size()) {
      const CellResult& c0 = r.cells[i];
      std::snprintf(b, sizeof b, "%3.0f mm %4.1f m %4.0f px", c0.cell.size_mm, c0.cell.distance_m, c0.side_px);
      s += b;
      s += added[i / per_row];
      for (size_t j = i; j < i + r.plan.lux.size() && j < grid; ++j) {
        const DetectorTally& t = r.cells[j].detectors[d];
        const auto [lo, hi] = wilson_interval(t.detected, t.frames);
        if (t.frames == 0)   // a cell no frame was taken in (videos of some conditions only)
          std::snprintf(b, sizeof b, "  %5s %11s", "-", "");
        else
          std::snprintf(b, sizeof b, "  %5.1f [%4.0f-%3.0f]", t.p_rec(), 100 * lo, 100 * hi);
        s += b;
      }
      s += "\n";
    }
    int empty = 0, fps = 0;   // the grid's (a curve's cell has its base's empty frames, blurred or noisier)
    for (size_t i = 0; i < grid; ++i) {
      empty += r.cells[i].detectors[d].empty_frames;
      fps += r.cells[i].detectors[d].false_positives;
    }
    if (empty > 0) {
      std::snprintf(b, sizeof b, "false positives: %d on %d frames without a marker (%.3f per frame)\n", fps, empty,
                    double(fps) / empty);
      s += b;
    }
    s += curves_text(r, d);
    s += "\n";
  }
  return s;
}

std::string lab_table_csv(const LabResults& r) {
  std::string s =
      "detector,size_mm,distance_m,lux,side_px,frames,detected,p_rec,ci_low,ci_high,wrong_id_rate,empty_frames,"
      "false_positives,tilt_deg,added_blur_px,added_noise,occlusion,curve,median_ms\n";
  char b[400];
  for (size_t d = 0; d < r.options.detectors.size(); ++d)
    for (const CellResult& c : r.cells) {
      const DetectorTally& t = c.detectors[d];
      const auto [lo, hi] = wilson_interval(t.detected, t.frames);
      // tilt_deg is empty for a random tilt (up to the plan's max_tilt_deg).
      char tilt[32] = "";
      if (c.cell.tilt_deg >= 0) std::snprintf(tilt, sizeof tilt, "%g", c.cell.tilt_deg);
      std::snprintf(b, sizeof b, "%s,%g,%g,%g,%.1f,%d,%d,%.2f,%.2f,%.2f,%.4f,%d,%d,%s,%g,%g,%g,%s,%.3f\n",
                    r.options.detectors[d].c_str(), c.cell.size_mm, c.cell.distance_m, c.cell.lux, c.side_px, t.frames,
                    t.detected, t.p_rec(), 100 * lo, 100 * hi, t.frames ? double(t.wrong_id) / t.frames : 0.0,
                    t.empty_frames, t.false_positives, tilt, c.cell.blur_px, c.cell.noise, c.cell.occlusion,
                    curve_name(c.cell), t.median_ms());
      s += b;
    }
  return s;
}

std::string lab_results_json(const LabResults& r) {
  using Json = nlohmann::ordered_json;
  const SensorModel& m = r.options.sensor;
  Json j;
  j["plan"] = {{"name", r.plan.name},
               {"dictionary", r.plan.dictionary},
               {"markers", r.plan.markers},
               {"sizes_mm", r.plan.sizes_mm},
               {"distances_m", r.plan.distances_m},
               {"lux", r.plan.lux},
               {"max_tilt_deg", r.plan.max_tilt_deg},
               {"sides_px", r.plan.sides_px},
               {"tilts_deg", r.plan.tilts_deg},
               {"blurs_px", r.plan.blurs_px},
               {"noises", r.plan.noises},
               {"occlusions", r.plan.occlusions},
               {"curve_at", r.plan.curve_base() >= 0 ? Json(r.plan.curve_at) : Json(nullptr)},
               {"curve_blurs_px", r.plan.curve_blurs_px},
               {"curve_noises", r.plan.curve_noises},
               {"frames_per_cell", r.plan.frames_per_cell},
               {"empty_frames_per_cell", r.plan.empty_frames_per_cell()}};
  j["seed"] = r.options.seed;
  j["ids"] = r.ids;
  j["camera"] = {{"name", r.options.camera_name},
                 {"width", r.options.camera.size.width},
                 {"height", r.options.camera.size.height},
                 {"fx", r.options.camera.camera_matrix(0, 0)},
                 {"distortion", r.options.camera.distortion}};
  j["sensor"] = {{"sensitivity_e_per_lux_s", m.sensitivity}, {"full_well_e", m.full_well},
                 {"read_noise_e", m.read_noise},          {"target_level", m.target_level},
                 {"max_exposure_s", m.max_exposure_s},    {"max_gain", m.max_gain},
                 {"focal_length_mm", m.focal_length_mm},  {"f_number", m.f_number},
                 {"focus_m", m.focus_m},                  {"shake_deg_s", m.shake_deg_s}};
  const SceneLight& l = r.options.light;
  j["light"] = {{"direct_outdoor", l.direct_outdoor},   {"direct_indoor", l.direct_indoor},
                {"direct_evening", l.direct_evening},   {"body_width_m", l.body_width_m},
                // null: from the geometry (shadow_edge_chance), which depends on the cell
                {"shadow_chance", l.shadow_chance >= 0 ? Json(l.shadow_chance) : Json(nullptr)},
                {"sun_diameter_rad", l.sun_diameter_rad}, {"glare_chance", glint_chance(l)},
                {"glare_lobe_deg", l.glare_lobe_deg},   {"glare_peak", l.glare_peak}};
  j["detectors"] = r.options.detectors;
  // Each detector's "marks": a character per frame of the cell (frames with a marker, then those without): D
  // detected, M missed, W another id only, . not counted (the marker not wholly in view), c nothing reported on a
  // frame without a marker, F a false positive there.
  Json cells = Json::array();
  for (const CellResult& c : r.cells) {
    Json per = Json::object();
    for (size_t d = 0; d < r.options.detectors.size(); ++d) {
      const DetectorTally& t = c.detectors[d];
      const auto [lo, hi] = wilson_interval(t.detected, t.frames);
      per[r.options.detectors[d]] = {{"frames", t.frames},
                                     {"detected", t.detected},
                                     {"p_rec", round_decimals(t.p_rec(), 2)},
                                     {"ci95", {round_decimals(100 * lo, 2), round_decimals(100 * hi, 2)}},
                                     {"wrong_id", t.wrong_id},
                                     {"empty_frames", t.empty_frames},
                                     {"false_positives", t.false_positives},
                                     {"median_ms", round_decimals(t.median_ms(), 3)},
                                     {"marks", t.marks}};
    }
    Json tilts = Json::array();
    for (float t : c.tilts_deg) tilts.push_back(round_decimals(t, 1));
    cells.push_back({{"size_mm", round_decimals(c.cell.size_mm, 3)},
                     {"distance_m", c.cell.distance_m},
                     {"lux", c.cell.lux},
                     {"side_px", round_decimals(c.side_px, 1)},
                     // The added axes: tilt_deg null for a random tilt; blur_px below is the cell's whole blur.
                     {"tilt_deg", c.cell.tilt_deg >= 0 ? Json(c.cell.tilt_deg) : Json(nullptr)},
                     {"added_blur_px", c.cell.blur_px},
                     {"added_noise", c.cell.noise},
                     {"occlusion", c.cell.occlusion},
                     // "blur" or "noise": a point of that curve (the grid's cell at curve_at, one factor changed)
                     {"curve", c.cell.curve ? Json(curve_name(c.cell)) : Json(nullptr)},
                     {"exposure_ms", round_decimals(c.exposure_ms, 2)},
                     {"gain", round_decimals(c.gain, 2)},
                     {"snr_ink", round_decimals(c.snr_black_white, 1)},
                     {"blur_px", round_decimals(c.blur_px, 2)},
                     // Each frame with a marker's tilt (the angle of its normal from the optical axis), -1 where
                     // the marker could not be placed.
                     {"tilts_deg", tilts},
                     {"results", per}});
  }
  j["cells"] = cells;
  j["seconds"] = round_decimals(r.seconds, 1);
  return json_text(j, 2) + "\n";
}

}  // namespace arwb::lab
