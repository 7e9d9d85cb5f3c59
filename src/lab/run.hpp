// Running a plan: for every cell its frames are rendered once through the camera and sensor model (sensor.hpp)
// and handed to every detector; a frame counts for a detector when it reports the marker's id with corners on
// the marker's (P_Rec = detected frames / frames in which the marker is visible x 100, the paper's measure).
// The same seed gives the same frames, and so the same table. frame_renderer.cpp renders the frames, run.cpp
// runs and marks them, results.cpp writes the results out.
#pragma once

#include "lab/plan.hpp"
#include "lab/lighting.hpp"
#include "lab/sensor.hpp"
#include "detect/trace.hpp"
#include "synth/marker_view.hpp"
#include "detect/params.hpp"
#include "base/result.hpp"

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <string>
#include <vector>

namespace arwb::lab {

// The detectors a lab compares: "arwb" (with `params`), "opencv" (OpenCV 4.6's aruco, default parameters),
// "opencv-aruco3" (its ArUco3 mode), "apriltag" (AprilTag 3, AprilTag families only).
inline const std::vector<std::string> kLabDetectors{"arwb", "opencv", "opencv-aruco3", "apriltag"};

struct CellResult;

struct LabOptions {
  std::vector<std::string> detectors{"arwb", "opencv", "opencv-aruco3"};
  unsigned seed = 1;
  // Frames of a cell are spread over this many threads; the table does not depend on it (times aside).
  int threads = 1;
  SynthCamera camera = default_lab_camera();
  std::string camera_name = "the default webcam (640x480, 60 degrees across)";
  SensorModel sensor;
  SceneLight light;          // shadows and glints by the paper's three conditions (lighting.hpp)
  DetectorParams params;
  // Resuming: cells an earlier run of the same plan and options finished, by index in plan.cells() (empty or a
  // null entry: run it). on_cell is called with each cell run here once it is finished, to save it.
  std::vector<std::shared_ptr<const CellResult>> finished;
  std::function<void(size_t, const CellResult&)> on_cell;
  // Set (by another thread) to stop between frames: run_lab then returns an error saying how far it got, and the
  // cells finished before have been given to on_cell.
  const std::atomic<bool>* stop = nullptr;
};

// What one frame of a cell was for a detector, one character per frame in frame order (DetectorTally::marks):
// frames with a marker, then the frames without one.
namespace mark {
constexpr char detected = 'D';      // the right id on the marker
constexpr char missed = 'M';        // not reported
constexpr char wrong_id = 'W';      // not the right id on the marker, but another id reported
constexpr char not_visible = '.';   // the marker could not be placed wholly in view: not a frame of the measure
constexpr char clean = 'c';         // a frame without a marker, nothing reported
constexpr char false_positive = 'F';   // a frame without a marker, something reported
}  // namespace mark

struct DetectorTally {
  int frames = 0;        // frames in which the marker was visible
  int detected = 0;      // ... and this detector reported it, right id, on the marker
  int wrong_id = 0;      // frames where it reported another id
  int empty_frames = 0;      // frames without a marker (cluttered, decoys included)
  int false_positives = 0;   // markers it reported on them
  double fp_per_frame() const { return empty_frames ? double(false_positives) / empty_frames : 0; }
  std::vector<double> ms;
  std::string marks;     // per frame of the cell (namespace mark), so a user can open the frames that failed
  double p_rec() const { return frames ? 100.0 * detected / frames : 0; }
  double median_ms() const;
};

struct CellResult {
  Cell cell;
  double side_px = 0;          // the marker's side at the image centre, facing the camera
  // blur_px: the cell's whole blur, in px: the defocus's sigma, half the hand's streak and the cell's added blur,
  // combined as independent blurs are (the root of the sum of squares).
  double exposure_ms = 0, gain = 1, snr_black_white = 0, blur_px = 0;
  // Per frame with a marker (frames 0 .. frames_per_cell-1), the marker's tilt (LabFrame::tilt_deg), -1 for a
  // frame whose marker could not be placed: recall against tilt bins frames by it.
  std::vector<float> tilts_deg;
  std::vector<DetectorTally> detectors;   // in LabOptions::detectors' order
  // The wall time its frames took in the run that ran it; -1 when not recorded (a cell saved by an older arwb).
  double seconds = -1;
};

struct LabResults {
  LabPlan plan;
  LabOptions options;
  std::vector<int> ids;
  std::vector<CellResult> cells;
  double seconds = 0;   // this run's wall time
  int resumed = 0;      // cells taken from an earlier run (LabOptions::finished)
  int merged_parts = 0;   // the parts (Shard) its cells were run in, when it joins them (arwb lab --merge)
};

// What a run took, in words: "12.5 s"; for a resumed run, this run's time and what all its cells took: "12.5 s
// here; all its cells took 40.1 s (2 of 4 from an earlier run)", or when a saved cell's time was not recorded (an
// older arwb's), "12.5 s here; 2 of 4 cells from an earlier run, time not recorded"; for a run joined from its
// parts, "merged from 3 parts; its cells took 40.1 s".
std::string lab_time_text(const LabResults& r);

// The markers a run shows: `plan.markers` distinct random ids of the plan's dictionary, drawn with the seed.
std::vector<int> lab_marker_ids(const LabPlan& plan, unsigned seed);

// One frame of a cell exactly as run_lab renders it: frames 0 .. frames_per_cell-1 show a marker, the cell's
// empty frames follow. The same plan, options, cell and frame give the same picture, whatever ran before it.
struct LabFrame {
  cv::Mat image;            // BGR, the camera's size
  bool empty = false;       // a frame without a marker (false positives are counted on it)
  bool visible = false;     // a marker frame whose marker could be placed wholly in view
  int id = -1;              // the marker shown
  Quad corners{};           // its corners in the image (OpenCV's order)
  double roll_deg = 0, tilt_x_deg = 0, tilt_y_deg = 0;
  LightEvents light;        // a shadow edge or a glint on the marker
  double tilt_deg = 0;      // the angle between the marker's normal and the camera's optical axis
  int occluded_side = -1;   // the side (0 top, 1 right, 2 bottom, 3 left of the upright marker) covered, if any
};
// Renders frames of any cell of one plan and options (a thread's own: it keeps the renderer's buffers).
class LabFrameRenderer {
 public:
  LabFrameRenderer(const LabPlan& plan, const LabOptions& options, std::vector<int> ids);
  LabFrame render(size_t cell_index, int frame) const;
  const std::vector<int>& ids() const { return ids_; }
  int frames_per_cell() const { return plan_.frames_per_cell + plan_.empty_frames_per_cell(); }
  cv::Size camera_size() const { return options_.camera.size; }

 private:
  LabPlan plan_;
  LabOptions options_;
  std::vector<int> ids_;
  std::vector<Cell> cells_;
  mutable MarkerRenderer renderer_;
};

// Whether a detector's markers count for the frame (the right id with its corners on the marker's), and whether
// another id was reported: the one rule run_lab and the workbench's Lab workspace use.
// `other_id`: set when another id was reported (beside the right one or instead of it).
char frame_mark(const LabFrame& frame, const std::vector<Marker>& found, double side_px, bool* other_id = nullptr);

// Runs the plan; `progress(done, total)` after each frame. An error for an unknown detector or dictionary, or a
// detector that cannot read the plan's dictionary ("apriltag reads the AprilTag families, not ARUCO_ORIGINAL").
Result<LabResults> run_lab(const LabPlan& plan, const LabOptions& options,
                           const std::function<void(int, int)>& progress = {});

// One of `count` disjoint parts of a plan's cells, to spread a run over processes or machines (arwb lab --shard
// K/N): cell i (from 0, in plan.cells()' order) is part (i mod count) + 1's. Dealt in turn rather than in blocks,
// every part gets cells of every size and distance, so the parts take about the same time.
struct Shard {
  int index = 1, count = 1;   // 1 <= index <= count
  bool has(size_t cell) const { return count <= 1 || int(cell % size_t(count)) + 1 == index; }
  size_t cells(size_t plan_cells) const;   // how many of a plan's cells are this part's
};
// Parses "K/N" (1 <= K <= N <= 100000); an error in words otherwise.
Result<Shard> parse_shard(const std::string& text);

struct PartRun {
  int cells = 0;     // the part's cells
  int resumed = 0;   // ... of them taken from an earlier run (LabOptions::finished)
  double seconds = 0;
};
// Runs the part's cells only, each finished one given to options.on_cell (its tallies are a single run's for
// that cell: frames depend on the cell and frame only); the run's table is made by joining the parts' cells.
Result<PartRun> run_lab_part(const LabPlan& plan, const LabOptions& options, const Shard& shard,
                             const std::function<void(int, int)>& progress = {});

// The paper's table as text: per detector, a row per size and distance (and the added axes' values the plan
// has: "26 mm  1.0 m   14 px tilt 60 blur 1.5"), a column per light level, each cell "P_Rec% [low-high]", then its
// false positives on the frames without a marker.
std::string lab_table_text(const LabResults& r);
// One row per cell and detector: detector,size_mm,distance_m,lux,side_px,frames,detected,p_rec,ci_low,ci_high,
// wrong_id_rate,empty_frames,false_positives, the added axes (tilt_deg, empty for a random tilt up to the plan's
// max_tilt_deg; added_blur_px, added_noise, occlusion), and median_ms last (the one column that varies run to run).
std::string lab_table_csv(const LabResults& r);
// Everything above, with the plan, the camera, the sensor model and each cell's exposure, as JSON text.
std::string lab_results_json(const LabResults& r);

}  // namespace arwb::lab
