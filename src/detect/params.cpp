#include "detect/params.hpp"

#include "base/decimals.hpp"
#include "base/files.hpp"
#include "detect/trace.hpp"
#include "detect/yaml_file.hpp"

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdio>
#include <utility>

namespace arwb {
namespace {

using P = DetectorParams;

#define ARWB_INT(field, stage, unit, def, lo, hi, help) {#field, stage, unit, def, lo, hi, true, help, &P::field, nullptr}
#define ARWB_DBL(field, stage, unit, def, lo, hi, help) {#field, stage, unit, def, lo, hi, false, help, nullptr, &P::field}

const ParamInfo kTable[] = {
    ARWB_INT(full_search_interval, "search_regions", "frames", 5, 1, 100,
             "In video, the whole frame is searched at least once in this many frames; between, only around the "
             "markers of the previous frame, at their scale. Higher is faster and finds a marker that comes into "
             "view later (at most this many frames); 1 searches the whole of every frame."),
    ARWB_DBL(region_margin_rate, "search_regions", "rate", 1, 0.2, 4,
             "How far around a known marker its search region reaches, in the marker's sides. Higher follows "
             "faster motion between frames, costs time."),
    ARWB_DBL(region_min_side_px, "search_regions", "px", 32, 8, 400,
             "In video, the regions are searched at the decimation that keeps the smallest known marker at least "
             "this many pixels a side (at most 4). Lower is faster and reads a blurred or tilted marker less "
             "surely."),
    ARWB_INT(decimation_factor, "decimation", "", 0, 0, 4,
             "The search (adaptive_threshold to quad_fit) runs on the grey image shrunk this many times; candidates "
             "are still read and their corners placed on the full image. 0 chooses by the frame: 2 when its shorter "
             "side is 720 px or more, else 1. 2 halves the search's time and, its threshold window covering twice "
             "the pixels, finds more large markers at low contrast and in dim light; fine_search searches the small "
             "shapes it could not read again at full resolution. 1 searches every pixel."),
    ARWB_INT(threshold_window_px, "adaptive_threshold", "px", 17, 3, 201,
             "Side of the square whose mean each pixel is compared with (odd), in the decimated image's pixels; "
             "from 9 up the mean is taken over 2x2 block means. Larger keeps thick borders whole, "
             "smaller separates touching dark regions."),
    ARWB_DBL(threshold_offset, "adaptive_threshold", "grey", 7, 0, 100,
             "How much darker than its neighbourhood mean a pixel must be to count as black. Higher ignores faint "
             "texture and noise, lower finds low-contrast markers."),
    ARWB_INT(coarse_factor, "coarse_search", "", 4, 0, 6,
             "The whole frame is searched a second time on the first search's image shrunk this many times (the "
             "grey image's at decimation 1, 8 times the grey image's on a half-size search), for large markers: "
             "there the threshold's window spans a whole border and sensor noise averages out, so dim, noisy and "
             "grey-on-grey markers under a shadow edge are found. 0 or 1 turns it off."),
    ARWB_DBL(coarse_min_perimeter_px, "coarse_search", "px", 120, 48, 100000,
             "Contours of the coarse search shorter than this (in the frame's pixels) are not traced: it looks for "
             "large markers, the first search finds the small ones."),
    ARWB_DBL(min_perimeter_px, "size_filter", "px", 32, 4, 100000,
             "Contours shorter than this are dropped before fitting. Lower finds smaller markers, costs time."),
    ARWB_DBL(max_perimeter_rate, "size_filter", "rate", 4, 0.1, 8,
             "Contours longer than this times the frame's larger side are dropped."),
    ARWB_DBL(polygon_epsilon_rate, "quad_fit", "rate", 0.03, 0.005, 0.2,
             "Polygon approximation tolerance as a fraction of the contour's perimeter. Higher accepts rounder "
             "or blurrier quads, and more clutter."),
    ARWB_DBL(min_side_rate, "quad_fit", "rate", 0.1, 0, 0.25,
             "Shortest quad side allowed, as a fraction of its perimeter. 0.1 still admits a square tilted 75 "
             "degrees away; lower admits slivers such as thin outlined frames, which read as ARUCO_ORIGINAL 1023."),
    ARWB_INT(min_border_distance_px, "quad_fit", "px", 3, 0, 100,
             "Quads with a corner closer than this to the image edge are dropped (they are usually cut off)."),
    ARWB_INT(cut_thin_lines, "quad_fit", "", 1, 0, 1,
             "1: a shape that is a quad joined to thin lines (a line that crosses a marker's quiet zone into its "
             "border joins the two, and whatever else the line touches, in one shape) gives the quad, its sides "
             "fitted without the lines. 0: off."),
    ARWB_DBL(split_thin_lines_px, "quad_fit", "px", 5, 0, 40,
             "A shape whose polygon is no quad, and whose outline is long for its area, is split where the outline "
             "runs along both sides of a line at most this wide (beyond what the search's decimation thins away), "
             "and each part is fitted again: a marker that lines join to other shapes stands alone. 0: off."),
    ARWB_DBL(min_marker_distance_rate, "nested_filter", "rate", 0.05, 0, 1,
             "Two quads whose corners are closer than this fraction of the smaller perimeter are one candidate; "
             "the outer one is kept."),
    ARWB_INT(corner_refinement, "corner_refinement", "", 1, 0, 1,
             "1 refines the four corners to subpixel accuracy on the grey image; 0 keeps the polygon's corners."),
    ARWB_INT(subpix_window_px, "corner_refinement", "px", 5, 1, 20,
             "How far each edge profile reaches either side of a side: at most this + 1 px and 0.6 of a cell."),
    ARWB_INT(subpix_max_iterations, "corner_refinement", "", 1, 1, 50,
             "Passes of the edge fit. More re-profile across the sides the last pass found: on the bench set 2 "
             "passes gain 3% in corner precision (0.067 to 0.065 px) for about 5% more time."),
    ARWB_DBL(subpix_epsilon_px, "corner_refinement", "px", 0.05, 0.001, 1,
             "Refinement stops when no corner moved more than this in a pass."),
    ARWB_DBL(unrefined_miss_rate, "corner_refinement", "rate", 0.15, 0, 1,
             "Each quad is first read as found, its corners unrefined (no quiet zone check); it is refined and "
             "read again only if that read passes otsu and border_check and its nearest id is at most this share "
             "of the code's bits more than the correction budget away (0.15: 3 bits of ARUCO_ORIGINAL's 25, 5 of "
             "APRILTAG_36h11's 36). Lower is faster and may miss a blurred or tilted marker whose corners were "
             "found far off; 1 refines and reads every quad. No effect when corner_refinement is 0."),
    ARWB_INT(warp_cell_px, "perspective_removal", "px", 4, 1, 32,
             "Pixels per cell in the frontal view. More samples each cell better, costs time."),
    ARWB_DBL(warp_max_step_px, "perspective_removal", "px", 3, 0, 64,
             "The frontal view's samples lie at most this many image pixels apart: a quad whose cells are larger "
             "than warp_cell_px x this is viewed at 2, 3 or 4 times warp_cell_px a cell (its cell centres the same), "
             "so a thin line across a large cell is a minority of its samples. 0: always warp_cell_px."),
    ARWB_DBL(warp_margin_rate, "perspective_removal", "rate", 0.13, 0, 0.45,
             "Part of each cell's side ignored at its edges when sampling, so blur from neighbours does not count."),
    ARWB_DBL(otsu_min_stddev, "otsu", "grey", 5, 0, 128,
             "A frontal view whose grey levels vary less than this is uniform (all black or white), not a marker."),
    ARWB_INT(local_thresholds, "bit_grid", "", 1, 0, 1,
             "1: a quad that one threshold cannot read (its border or id fails) is read again with a threshold per "
             "cell, spread in from the mid levels between each border cell and the quiet zone beside it, for a "
             "shadow edge or a steep gradient across a marker; a large one (viewed at more than warp_cell_px) whose "
             "id still fails, against the level half way between planes through its black and its white cells. "
             "0: off."),
    ARWB_DBL(border_max_error_rate, "border_check", "rate", 0.35, 0, 1,
             "Share of border cells allowed to be white. Higher tolerates occlusion and glare, and more clutter."),
    ARWB_DBL(quiet_zone_max_dark_rate, "border_check", "rate", 0.6, 0, 1,
             "Share of a side's quiet zone (half a cell outside the border) allowed to be dark. 1 turns it off."),
    ARWB_DBL(error_correction_rate, "identification", "rate", 0.6, 0, 1,
             "Share of the dictionary's correction budget used: bits that may be wrong = rate x max correction."),
    ARWB_DBL(bar_min_aspect_rate, "identification", "rate", 2, 0, 10,
             "A quad at least this many times as long as it is wide whose inside reads as stripes along its length "
             "(one row or column repeated) is a bar or an outlined rectangle, not a marker: their insides read so "
             "(ARUCO_ORIGINAL 0 and 1023). Lower drops more of them, and markers with such ids seen at a steeper "
             "angle; 0 turns it off."),
    ARWB_DBL(fine_max_side_px, "fine_search", "px", 80, 0, 400,
             "A decimated search's shapes up to this size (the longer side of their box) that it could not close "
             "into a quad or read, and its quad-shaped holes up to this size that are inside no marker it read, are "
             "searched again at full resolution, where a small marker's border and cells are sharp. Higher rescues "
             "larger blurred markers, costs time; 0 turns it off. It runs only when the search is decimated."),
    ARWB_DBL(fine_threshold_offset, "fine_search", "grey", 3, 0, 100,
             "threshold_offset for fine_search's regions. Each holds a shape the first search could not close or "
             "read, so it may look harder there than the whole frame can afford: lower than threshold_offset "
             "keeps a small marker's border whole where sensor noise in dim light or a faint print broke it; "
             "higher than it, fewer specks."),
    ARWB_INT(tracking_smoothing, kTrackingStage, "", 1, 0, 1,
             "1 smooths each tracked marker's corners over time (One Euro filter); 0 shows them as detected."),
    ARWB_DBL(tracking_min_cutoff_hz, kTrackingStage, "Hz", 1, 0.05, 30,
             "Cutoff of a still marker's corners. Lower holds a still marker steadier, and it lags more when it "
             "starts to move."),
    ARWB_DBL(tracking_beta, kTrackingStage, "s/px", 1, 0, 10,
             "How fast the cutoff rises with a corner's speed. Higher follows a moving marker more closely, and "
             "lets more jitter through while it moves."),
    ARWB_DBL(tracking_d_cutoff_hz, kTrackingStage, "Hz", 1, 0.05, 30,
             "Cutoff of the corner speed that the cutoff follows. Higher reacts sooner to a start, and to noise."),
    ARWB_DBL(tracking_hold_s, kTrackingStage, "s", 0.25, 0, 5,
             "How long a marker unseen stays, its media on its last corners, before it leaves (a scene's on_leave "
             "runs). It also stays while missed on no more than two frames in a row, so a slow source's missed "
             "frame does not make it leave and enter again. Higher rides out longer gaps; media then linger longer "
             "after a marker is taken away."),
};

#undef ARWB_INT
#undef ARWB_DBL

}  // namespace

DetectorParams::DetectorParams() {
  for (const auto& info : kTable) set_param(*this, info, info.default_value);
}

std::span<const ParamInfo> param_table() { return kTable; }

bool param_stage_known(std::string_view stage) {
  Stage s;
  return stage == kTrackingStage || stage_from_name(stage, &s);
}

bool is_detector_param(const ParamInfo& info) { return std::string_view(info.stage) != kTrackingStage; }

const ParamInfo* find_param(const std::string& name) {
  for (const auto& info : kTable)
    if (name == info.name) return &info;
  return nullptr;
}

double get_param(const DetectorParams& p, const ParamInfo& info) {
  return info.integer ? static_cast<double>(p.*(info.int_field)) : p.*(info.double_field);
}

bool set_param(DetectorParams& p, const ParamInfo& info, double value, std::string* error) {
  if (!std::isfinite(value) || value < info.min_value || value > info.max_value) {
    if (error)
      *error = std::string(info.name) + " = " + general_text(value) + " is outside " + general_text(info.min_value) + ".." +
               general_text(info.max_value);
    return false;
  }
  if (info.integer) {
    if (value != std::floor(value)) {
      if (error) *error = std::string(info.name) + " = " + general_text(value) + " must be a whole number";
      return false;
    }
    p.*(info.int_field) = static_cast<int>(value);
  } else {
    p.*(info.double_field) = value;
  }
  return true;
}

// A parameter file is a few dozen lines; a larger file is not one.
constexpr FileLimit kPresetFile{"a preset", 1u << 20};

bool load_params_yaml(const std::string& path, DetectorParams& out, std::vector<std::string>* errors,
                      std::vector<std::string>* notes) {
  auto report = [&](const std::string& msg) {
    if (errors) errors->push_back(path + ": " + msg);
  };
  auto note = [&](const std::string& msg) {
    if (notes) notes->push_back(path + ": " + msg);
  };
  DetectorParams next = out;
  bool ok = true;
  try {
    cv::FileStorage fs;
    if (Status opened = open_yaml_file(path, kPresetFile, &fs); !opened) {
      if (errors) errors->push_back(opened.error());
      return false;
    }
    const cv::FileNode root = fs.root();
    if (!root.isMap()) {
      report("expected a map of parameter: value");
      return false;
    }
    for (const auto& node : root) {
      const std::string key = node.name();
      const ParamInfo* info = find_param(key);
      if (!info && (key == "resize_width" || key == "resize_height")) {
        // Once a second resize inside the detector; now the one resize is acquisition's. 0 (every shipped preset)
        // meant "no second resize", which is what happens; anything else is named so that nothing changes unseen.
        const double v = (node.isInt() || node.isReal()) ? node.real() : -1;
        if (v == 0)
          note(key + ": 0 is no longer needed: the detector does not resize again; the one resize is "
                     "acquisition's (arwb --resize WxH, arwb render --size WxH, the Source panel)");
        else
          note(key + " = " + (v < 0 ? std::string("?") : general_text(v)) +
               " is not applied: the detector no longer resizes; set acquisition's resize instead "
               "(arwb --resize WxH, arwb render --size WxH, the Source panel)");
        continue;
      }
      if (!info) {
        report("unknown parameter '" + key + "'");
        ok = false;
        continue;
      }
      if (!node.isInt() && !node.isReal()) {
        report(key + " is not a number");
        ok = false;
        continue;
      }
      std::string err;
      if (!set_param(next, *info, node.real(), &err)) {
        report(err);
        ok = false;
      }
    }
  } catch (const std::exception&) {
    // cv::Exception from reading a node of the wrong type (its text names OpenCV's own source), std::length_error
    // and the like from OpenCV's parser (found by fuzzing): ours names the file.
    report("malformed YAML");
    return false;
  }
  if (ok) out = next;
  return ok;
}

int param_decimals(const ParamInfo& info) {
  if (info.integer) return 0;
  const double span = info.max_value - info.min_value;
  if (span <= 1.0) return 3;
  if (span <= 10.0) return 2;
  if (span <= 200.0) return 1;
  return 0;
}

bool save_params_yaml(const std::string& path, const DetectorParams& p, std::string* error) {
  // Written as text, not through cv::FileStorage, which prints doubles with 17 digits: a preset is read by people.
  std::string text = "%YAML:1.0\n---\n";
  for (const auto& info : kTable) {
    text += info.name;
    text += ": ";
    if (info.integer) text += std::to_string(p.*(info.int_field));
    else text += decimals_text(p.*(info.double_field), param_decimals(info));   // as the slider shows it
    text += "\n";
  }
  std::string err;
  if (write_file_atomically(path, text, &err)) return true;
  if (error) *error = path + ": cannot write (" + err + ")";
  return false;
}

}  // namespace arwb
