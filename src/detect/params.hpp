// The detector's parameters: one table (name, default, range, unit, help) that the YAML presets, the GUI
// sliders and the Lua API all read. A parameter's name is the same everywhere; its unit is in its name where
// it has one (_px, _rate of the image or perimeter, _cells).
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace arwb {

// Acquisition's resize is not here: it is the source's acquisition setting (capture/source.hpp), one for the
// workbench, the CLI and the detector.
struct DetectorParams {
  // search_regions (video: detect/video_search.hpp)
  int full_search_interval = 0;      // filled from the table's defaults by the constructor
  double region_margin_rate = 0;
  double region_min_side_px = 0;
  // decimation
  int decimation_factor = 0;
  // adaptive_threshold
  int threshold_window_px = 0;
  double threshold_offset = 0;
  // coarse_search
  int coarse_factor = 0;
  double coarse_min_perimeter_px = 0;
  // size_filter
  double min_perimeter_px = 0;
  double max_perimeter_rate = 0;
  // quad_fit
  double polygon_epsilon_rate = 0;
  double min_side_rate = 0;
  int min_border_distance_px = 0;
  int cut_thin_lines = 0;
  double split_thin_lines_px = 0;
  // nested_filter
  double min_marker_distance_rate = 0;
  // corner_refinement
  int corner_refinement = 0;         // 0 off, 1 on
  int subpix_window_px = 0;
  int subpix_max_iterations = 0;
  double subpix_epsilon_px = 0;
  double unrefined_miss_rate = 0;   // 1: refine every quad, no read as found first
  // perspective_removal
  int warp_cell_px = 0;
  double warp_max_step_px = 0;    // 0: every view warp_cell_px a cell
  double warp_margin_rate = 0;
  // otsu
  double otsu_min_stddev = 0;
  // bit_grid
  int local_thresholds = 0;
  // border_check
  double border_max_error_rate = 0;
  double quiet_zone_max_dark_rate = 0;
  // identification
  double error_correction_rate = 0;
  double bar_min_aspect_rate = 0;
  // fine_search
  double fine_max_side_px = 0;
  double fine_threshold_offset = 0;
  // tracking (after detection: the tracker's One Euro filter on each track's corners, track/tracker.hpp)
  int tracking_smoothing = 0;        // 0 off, 1 on
  double tracking_min_cutoff_hz = 0;
  double tracking_beta = 0;
  double tracking_d_cutoff_hz = 0;
  double tracking_hold_s = 0;

  DetectorParams();  // every field at its table default
  bool operator==(const DetectorParams&) const = default;
};

struct ParamInfo {
  const char* name;
  const char* stage;   // the pipeline stage it belongs to (same names as the trace, or kTrackingStage)
  const char* unit;    // "px", "rate", "" ...
  double default_value;
  double min_value;
  double max_value;
  bool integer;
  const char* help;    // one line: what raising it trades
  int DetectorParams::*int_field;
  double DetectorParams::*double_field;
};

// The stage after detection whose parameters are in the table too: the tracker's (track/tracker.hpp). It is
// not a detector stage (no trace record, no stage picture), so the detector's search (diagnose) leaves it alone.
inline constexpr const char* kTrackingStage = "tracking";
// A detector stage's name (detect/trace.hpp's stage_name) or kTrackingStage: the names a table row may use.
bool param_stage_known(std::string_view stage);
// The row is one of the detector's (it changes what is detected), not the tracker's.
bool is_detector_param(const ParamInfo& info);

// The table, in pipeline order.
std::span<const ParamInfo> param_table();
const ParamInfo* find_param(const std::string& name);

double get_param(const DetectorParams& p, const ParamInfo& info);
// The decimals a value of this parameter is shown and written with: 0 for an integer, else from how wide its
// range is (a range of 1 or less: 3; 10: 2; 200: 1; wider: 0). Sliders, messages and presets all use it.
int param_decimals(const ParamInfo& info);
// Sets a value; false and a message naming the parameter, value and range when out of range or not an integer.
bool set_param(DetectorParams& p, const ParamInfo& info, double value, std::string* error = nullptr);

// YAML presets (OpenCV FileStorage YAML): a map of name: value. Loading checks every key against the table:
// unknown names and out-of-range values are errors naming the file and the key; nothing is changed then.
// Presets written before the resize became acquisition's still load: their resize_width and resize_height are
// not applied, and `notes` says so and where the resize is set now.
bool load_params_yaml(const std::string& path, DetectorParams& out, std::vector<std::string>* errors,
                      std::vector<std::string>* notes = nullptr);
// Writes every parameter, rounded to param_decimals (0.03, not 0.029999999999999999), atomically.
bool save_params_yaml(const std::string& path, const DetectorParams& p, std::string* error = nullptr);

}  // namespace arwb
