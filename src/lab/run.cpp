// Running a plan (run.hpp): each cell's frames spread over the workers' threads, each frame given to every
// detector and marked by frame_mark, the marks counted into the cell's tallies in frame order.
#include "lab/run.hpp"

#include "lab/detectors.hpp"
#include "base/decimals.hpp"
#include "detect/dictionary.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <thread>

namespace arwb::lab {
namespace {

using Clock = std::chrono::steady_clock;

double quad_error(const Quad& a, const Quad& b) {
  double e = 0;
  for (size_t i = 0; i < 4; ++i) e += cv::norm(a[i] - b[i]);
  return e / 4;
}

// One frame's outcome for every detector, kept by frame so that tallies do not depend on which thread ran it.
struct FrameOutcome {
  bool visible = false;
  float tilt_deg = -1;           // the marker's (a frame with one, placed)
  bool empty = false;            // a frame without a marker: `found` counts false positives
  std::vector<char> marks;       // per detector (namespace mark)
  std::vector<char> other_id;    // per detector: another id reported (the wrong-id rate counts it even beside
                                 // the right one)
  std::vector<int> found;
  std::vector<double> ms;
};

// A thread's own renderer and detectors (AprilTag's detector and the renderer's buffers are not shared).
struct Worker {
  LabFrameRenderer renderer;
  std::vector<DetectFn> detectors;
};

FrameOutcome run_frame(Worker& w, size_t ci, double side_px, int k) {
  const LabFrame frame = w.renderer.render(ci, k);
  FrameOutcome fo;
  fo.visible = frame.visible;
  fo.empty = frame.empty;
  if (frame.visible && !frame.empty) fo.tilt_deg = float(frame.tilt_deg);
  if (!frame.visible) {   // the marker could not be placed wholly in view: not a frame of the experiment
    fo.marks.assign(w.detectors.size(), mark::not_visible);
    return fo;
  }
  for (const DetectFn& detect : w.detectors) {
    const auto s0 = Clock::now();
    const std::vector<Marker> found = detect(frame.image);
    fo.ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - s0).count());
    bool other = false;
    fo.found.push_back(int(found.size()));
    fo.marks.push_back(frame_mark(frame, found, side_px, &other));
    fo.other_id.push_back(other);
  }
  return fo;
}

// One worker per thread, each with its own renderer and detectors; an error for a detector that cannot be made.
Result<std::vector<std::unique_ptr<Worker>>> make_workers(const LabPlan& plan, const LabOptions& options,
                                                          int threads) {
  std::vector<std::unique_ptr<Worker>> workers;
  for (int i = 0; i < threads; ++i) {
    auto w = std::make_unique<Worker>(Worker{LabFrameRenderer(plan, options, lab_marker_ids(plan, options.seed)), {}});
    for (const std::string& name : options.detectors) {
      auto d = make_detector(name, plan.dictionary, options.params);
      if (!d) return fail(d.error());
      w->detectors.push_back(std::move(*d));
    }
    workers.push_back(std::move(w));
  }
  return workers;
}

// What a cell is before any frame: the marker's side in pixels, the sensor's exposure and gain, the ink's
// signal-to-noise ratio and the whole blur; empty tallies, one per detector.
CellResult cell_before_frames(const Cell& cell, const LabOptions& options, double f) {
  CellResult cr;
  cr.cell = cell;
  cr.side_px = marker_side_px(cell.size_mm, cell.distance_m, f);
  const Exposure ex = auto_exposure(options.sensor, cell.lux);
  cr.exposure_ms = ex.exposure_s * 1000;
  cr.gain = ex.gain;
  cr.snr_black_white = snr(options.sensor, cell.lux, 0.12);
  cr.blur_px = std::hypot(defocus_sigma_px(options.sensor, cell.distance_m, f),
                          shake_length_px(options.sensor, ex.exposure_s, f) / 2);
  if (cell.blur_px > 0) cr.blur_px = std::hypot(cr.blur_px, cell.blur_px);
  cr.detectors.resize(options.detectors.size());
  return cr;
}

// Frames 0 .. frames.size()-1 of cell ci, each taken by the next free thread (one per worker); `report` after each.
// A library's exception on one frame (OpenCV, a detector) must not end the process from a worker thread: the
// first one stops the cell's other threads and is returned, naming the cell and frame ("" when none).
std::string run_frames(std::vector<std::unique_ptr<Worker>>& workers, size_t ci, double side_px,
                       const std::function<bool()>& stopped, const std::function<void()>& report,
                       std::vector<FrameOutcome>& frames) {
  const int n = int(frames.size());
  std::atomic<int> next{0};
  std::mutex failure_mutex;
  std::string failure;
  std::atomic<bool> failed{false};
  auto work = [&](Worker& w) {
    for (int k = next++; k < n && !stopped() && !failed; k = next++) {
      try {
        frames[size_t(k)] = run_frame(w, ci, side_px, k);
      } catch (const std::exception& e) {
        std::lock_guard lock(failure_mutex);
        if (failure.empty())
          failure = "cell " + std::to_string(ci + 1) + ", frame " + std::to_string(k + 1) + ": " + e.what();
        failed = true;
      }
      report();
    }
  };
  std::vector<std::thread> pool;
  for (size_t i = 1; i < workers.size(); ++i) pool.emplace_back(work, std::ref(*workers[i]));
  work(*workers[0]);
  for (std::thread& t : pool) t.join();
  return failure;
}

// The frames' outcomes counted into the cell's tallies, in frame order.
void tally(const std::vector<FrameOutcome>& frames, CellResult& cr) {
  for (const FrameOutcome& fo : frames) {
    for (size_t d = 0; d < cr.detectors.size(); ++d) cr.detectors[d].marks += fo.marks[d];
    if (!fo.empty) cr.tilts_deg.push_back(fo.tilt_deg);
    if (fo.empty) {
      for (size_t d = 0; d < cr.detectors.size(); ++d) {
        ++cr.detectors[d].empty_frames;
        cr.detectors[d].false_positives += fo.found[d];
      }
      continue;
    }
    if (!fo.visible) continue;
    for (size_t d = 0; d < cr.detectors.size(); ++d) {
      DetectorTally& t = cr.detectors[d];
      ++t.frames;
      t.detected += fo.marks[d] == mark::detected;
      t.wrong_id += fo.other_id[d];
      t.ms.push_back(fo.ms[d]);
    }
  }
}

}  // namespace

double DetectorTally::median_ms() const {
  if (ms.empty()) return 0;
  std::vector<double> v = ms;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

char frame_mark(const LabFrame& frame, const std::vector<Marker>& found, double side_px, bool* other_id) {
  bool right = false, wrong = false;
  if (other_id) *other_id = false;
  if (frame.empty) return found.empty() ? mark::clean : mark::false_positive;
  if (!frame.visible) return mark::not_visible;
  for (const Marker& m : found) {
    if (m.id == frame.id && quad_error(m.corners, frame.corners) < std::max(3.0, 0.2 * side_px)) right = true;
    else if (m.id != frame.id) wrong = true;
  }
  if (other_id) *other_id = wrong;
  return right ? mark::detected : wrong ? mark::wrong_id : mark::missed;
}

namespace {

// The cells `take` selects, in order: each one finished by an earlier run (LabOptions::finished) taken as it was,
// the others run; `keep(index, cell, resumed)` gets each. The marker ids shown, or an error.
Result<std::vector<int>> run_cells(const LabPlan& plan, const LabOptions& options,
                                   const std::function<bool(size_t)>& take,
                                   const std::function<void(size_t, CellResult&&, bool)>& keep,
                                   const std::function<void(int, int)>& progress) {
  const auto dict = dictionary_by_name(plan.dictionary);
  if (!dict) return fail("the plan's dictionary '" + plan.dictionary + "' is unknown");
  if (plan.frames_per_cell < 1) return fail("a plan needs at least one frame per cell");
  Result<std::vector<std::unique_ptr<Worker>>> workers =
      make_workers(plan, options, std::clamp(options.threads, 1, 64));
  if (!workers) return fail(workers.error());
  const double f = options.camera.camera_matrix(0, 0);
  const std::vector<Cell> cells = plan.cells(f);
  const int per_cell = plan.frames_per_cell + plan.empty_frames_per_cell();
  int taken = 0;
  for (size_t ci = 0; ci < cells.size(); ++ci) taken += take(ci);
  const int total = taken * per_cell;
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  auto report = [&] {
    const int d = ++done;
    if (!progress) return;
    std::lock_guard lock(progress_mutex);
    progress(d, total);
  };
  auto stopped = [&] { return options.stop && options.stop->load(); };
  int before = 0;   // the selected cells before this one, finished
  for (size_t ci = 0; ci < cells.size(); ++ci) {
    if (!take(ci)) continue;
    ++before;
    if (ci < options.finished.size() && options.finished[ci]) {
      CellResult saved(*options.finished[ci]);
      saved.cell.curve = cells[ci].curve;   // not in the saved line: which curve a cell is, the plan says
      keep(ci, std::move(saved), true);
      for (int k = 0; k < per_cell; ++k) report();
      continue;
    }
    const auto cell_t0 = Clock::now();
    CellResult cr = cell_before_frames(cells[ci], options, f);
    std::vector<FrameOutcome> frames(static_cast<size_t>(per_cell));
    if (const std::string failure = run_frames(*workers, ci, cr.side_px, stopped, report, frames); !failure.empty())
      return fail(failure);
    if (stopped()) {
      return fail("stopped after " + std::to_string(before - 1) + " of " + std::to_string(taken) +
                  " cells (those are kept)");
    }
    tally(frames, cr);
    cr.seconds = std::chrono::duration<double>(Clock::now() - cell_t0).count();
    if (options.on_cell) options.on_cell(ci, cr);
    keep(ci, std::move(cr), false);
  }
  return (*workers)[0]->renderer.ids();
}

}  // namespace

Result<LabResults> run_lab(const LabPlan& plan, const LabOptions& options,
                           const std::function<void(int, int)>& progress) {
  const auto t0 = Clock::now();
  LabResults out;
  out.plan = plan;
  out.options = options;
  Result<std::vector<int>> ids = run_cells(
      plan, options, [](size_t) { return true; },
      [&](size_t, CellResult&& c, bool resumed) {
        out.cells.push_back(std::move(c));
        out.resumed += resumed;
      },
      progress);
  if (!ids) return fail(ids.error());
  out.ids = std::move(*ids);
  out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

size_t Shard::cells(size_t plan_cells) const {
  if (count <= 1) return plan_cells;
  return plan_cells / size_t(count) + (size_t(index) <= plan_cells % size_t(count) ? 1 : 0);
}

Result<Shard> parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  const auto whole = [](const std::string& s, int& v) {
    if (s.empty() || s.size() > 6 || s.find_first_not_of("0123456789") != std::string::npos) return false;
    v = std::stoi(s);
    return true;
  };
  Shard s;
  if (slash == std::string::npos || !whole(text.substr(0, slash), s.index) || !whole(text.substr(slash + 1), s.count))
    return fail("'" + text + "' is not K/N, the K-th of N parts (for example 2/4)");
  if (s.count < 1 || s.count > 100000) return fail("'" + text + "': N is from 1 to 100000 parts");
  if (s.index < 1 || s.index > s.count)
    return fail("'" + text + "': K is from 1 to N (" + std::to_string(s.count) + ")");
  return s;
}

Result<PartRun> run_lab_part(const LabPlan& plan, const LabOptions& options, const Shard& shard,
                             const std::function<void(int, int)>& progress) {
  const auto t0 = Clock::now();
  PartRun out;
  Result<std::vector<int>> ids = run_cells(
      plan, options, [&](size_t ci) { return shard.has(ci); },
      [&](size_t, CellResult&&, bool resumed) {
        ++out.cells;
        out.resumed += resumed;
      },
      progress);
  if (!ids) return fail(ids.error());
  out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

std::string lab_time_text(const LabResults& r) {
  const auto seconds = [](double s) { return fixed_text(s, 1) + " s"; };
  double cells = 0;
  bool recorded = true;
  for (const CellResult& c : r.cells) {
    recorded = recorded && c.seconds >= 0;
    cells += c.seconds;
  }
  if (r.merged_parts > 0)
    return "merged from " + std::to_string(r.merged_parts) + " parts; " +
           (recorded ? "its cells took " + seconds(cells) : "its cells' time not recorded");
  if (r.resumed == 0) return seconds(r.seconds);
  const std::string earlier = std::to_string(r.resumed) + " of " + std::to_string(r.cells.size());
  if (!recorded) return seconds(r.seconds) + " here; " + earlier + " cells from an earlier run, time not recorded";
  return seconds(r.seconds) + " here; all its cells took " + seconds(cells) + " (" + earlier + " from an earlier run)";
}

}  // namespace arwb::lab
