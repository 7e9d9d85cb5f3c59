// arwb lab: the paper's experiment (section 5) on frames rendered through a physical camera and sensor model,
// every detector on the same frames; the paper's table with 95 % intervals, as text, CSV and JSON.
#include "calibration/calibration_file.hpp"
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "lab/report.hpp"
#include "lab/run.hpp"
#include "lab/videos.hpp"
#include "base/files.hpp"
#include "base/text.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace arwb {

namespace {

// The three tables, the plots and the report into `out`; false with the problem printed.
bool write_outputs(const lab::LabResults& r, const std::string& out) {
  if (const Status s = lab::write_lab_outputs(r, out); !s) {
    print_problem("arwb lab: %s\n", s.error().c_str());
    return false;
  }
  return true;
}

// arwb lab --videos DIR: the paper's measure on real clips.
int run_on_videos(CommandLine& cl, const std::string& dir, const lab::LabOptions& options, const std::string& out,
                  bool json) {
  Result<std::vector<lab::VideoRow>> rows = lab::read_video_list(dir);
  if (!rows) return cl.usage_error("--videos " + dir + ": " + rows.error());
  std::vector<std::string> warnings;
  const bool bar = ::isatty(2);
  Result<lab::LabResults> r = lab::run_videos(dir, *rows, options, &warnings, [&](int done, int total) {
    if (bar) std::fprintf(stderr, "\rarwb lab: clip %d of %d%s", done, total, done == total ? "\n" : "");
  });
  if (!r) return cl.usage_error("--videos " + dir + ": " + r.error());
  for (const std::string& w : warnings) print_problem("arwb lab: %s\n", w.c_str());
  if (!out.empty() && !write_outputs(*r, out)) return 1;
  if (json) {
    std::fputs(lab::lab_results_json(*r).c_str(), stdout);
    return 0;
  }
  int frames = 0;
  for (const lab::CellResult& c : r->cells) frames += c.detectors.empty() ? 0 : c.detectors[0].frames;
  std::printf("Videos in %s: %zu clips, %d frames with the marker in view, %zu cells\n\n", dir.c_str(), rows->size(),
              frames, r->cells.size());
  std::fputs(lab::lab_table_text(*r).c_str(), stdout);
  std::printf("%.1f s%s%s\n", r->seconds, out.empty() ? "" : "; wrote the tables, plots and report.pdf to ",
              out.c_str());
  return 0;
}

}  // namespace

int cmd_lab(int argc, char** argv) {
  CommandLine cl("arwb lab",
                 "Runs the paper's recognition experiment (Avola et al. 2016, section 5): 25 random ARUCO_ORIGINAL "
                 "markers printed at 65, 39 and 26 mm, seen at 2, 1 and 0.5 m under 1000, 850 and 500 lux, turned "
                 "in plane and tilted, each frame rendered through a camera (the calibration given, or a default "
                 "webcam of 60 degrees across at 640x480) and a sensor with auto-exposure, shot and read noise, "
                 "defocus and hand-held motion blur (docs/lab.md). Every detector gets the same frames. Prints "
                 "P_Rec = detected frames / frames with the marker in view x 100 per cell, with its 95 % Wilson "
                 "interval.",
                 "The same seed gives the same frames and the same table.");
  std::string detectors_opt = "arwb,opencv,opencv-aruco3", out, calib_file, params_file, plan_opt = "paper", videos;
  int frames = 0, seed = 1, threads = 1;
  bool json = false, restart = false;
  cl.app.add_option("--detectors", detectors_opt, "a comma list of arwb, opencv, opencv-aruco3, apriltag")
      ->type_name("LIST");
  cl.app.add_option("--plan", plan_opt, "the paper's plan, or a plan file (docs/lab.md: sizes_mm, distances_m, lux, "
                                        "max_tilt_deg, frames_per_cell, markers, dictionary, empty_share, and the "
                                        "added axes sides_px, tilts_deg, blurs_px, noises, occlusions)")
      ->type_name("paper|FILE.yml");
  cl.app.add_option("--videos", videos, "real clips instead of rendered frames: DIR/videos.csv lists each clip with "
                                        "its marker and conditions (docs/lab.md); the same table from them")
      ->type_name("DIR");
  cl.app.add_option("--frames-per-cell", frames, "frames rendered for each cell (default: the plan's, 40 in the "
                                                 "paper's)")
      ->type_name("N")
      ->check(whole_number(1, 100000));
  cl.app.add_option("--seed", seed, "the markers, poses and noise")->type_name("S")->check(whole_number(0, 2147483647));
  cl.app.add_option("--calib", calib_file, "the camera to render through (a calibration file); default: a webcam of "
                                           "60 degrees across at 640x480")
      ->type_name("FILE");
  cl.app.add_option("--params", params_file, "a YAML preset of arwb's parameters")->type_name("FILE.yml");
  cl.app.add_option("--threads", threads, "frames rendered and detected at once; the table is the same for any "
                                          "number (times are not)")
      ->type_name("N")
      ->check(whole_number(1, 64));
  cl.app.add_option("--out", out, "a folder for table.txt, table.csv, results.json, report.pdf and PNG plots; each "
                                  "finished cell is saved in cells.jsonl there, and a run interrupted is resumed "
                                  "from it")
      ->type_name("DIR")
      ->check(out_kinds({}, true));
  cl.app.add_flag("--restart", restart, "with --out: forget the cells saved by an earlier run");
  cl.app.add_flag("--json", json, "print results.json instead of the table");
  if (const auto status = cl.parse(argc, argv)) return *status;

  lab::LabPlan plan = lab::paper_plan();
  if (plan_opt != "paper") {
    Result<lab::LabPlan> p = lab::read_plan(plan_opt);
    if (!p) return cl.usage_error("--plan " + p.error());
    plan = std::move(*p);
  }
  if (frames > 0) plan.frames_per_cell = frames;
  lab::LabOptions options;
  options.seed = unsigned(seed);
  options.detectors.clear();
  std::stringstream list(detectors_opt);
  for (std::string d; std::getline(list, d, ',');)
    if (!d.empty()) options.detectors.push_back(d);
  if (options.detectors.empty()) return cl.usage_error("--detectors: name at least one detector");
  if (!calib_file.empty()) {
    Result<Calibration> c = read_calibration(calib_file);
    if (!c) return cl.usage_error("--calib " + c.error());
    if (c->image_size.width <= 0 || c->image_size.height <= 0)
      return cl.usage_error("--calib " + calib_file + ": the file gives no image size (image_width, image_height)");
    options.camera.size = c->image_size;
    options.camera.camera_matrix = c->camera_matrix;
    options.camera.distortion = c->distortion;
    options.camera_name = calib_file;
  }
  if (!load_params_option(params_file, "arwb lab", options.params)) return 2;
  options.threads = threads;
  if (!videos.empty()) return run_on_videos(cl, videos, options, out, json);

  // Resuming: the cells an earlier run with the same plan and options saved; the others are run and saved as
  // they finish, one line each, so an interruption loses at most the cell it was in.
  std::FILE* saved = nullptr;
  const std::string key = lab::lab_run_key(plan, options);
  if (!out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(out, ec);
    const std::string cells_path = (std::filesystem::path(out) / "cells.jsonl").string();
    if (restart) std::filesystem::remove(cells_path, ec);
    options.finished.resize(plan.cell_count());
    int resumed = 0;
    if (std::filesystem::symlink_status(cells_path, ec).type() != std::filesystem::file_type::not_found) {
      // Through the file check: a FIFO or a device in its place is refused at once instead of blocking or reading
      // without end, and the results could not be appended to it either.
      const Result<std::string> text =
          read_file_bytes(cells_path, FileLimit{"a lab's cells file", std::uintmax_t(256) << 20});
      if (!text) {
        print_problem("arwb lab: %s\n", printable(text.error()).c_str());
        return 1;
      }
      size_t start = 0;
      for (int n = 1; start < text->size(); ++n) {
        size_t end = text->find('\n', start);
        if (end == std::string::npos) break;   // a last line without its newline: cut short by an interruption
        std::string problem;
        if (auto c = lab::cell_from_line(key, text->substr(start, end - start), options.detectors.size(), &problem);
            c && c->first < options.finished.size() && !options.finished[c->first]) {
          options.finished[c->first] = std::make_shared<const lab::CellResult>(std::move(c->second));
          ++resumed;
        } else if (!problem.empty()) {
          std::fprintf(stderr, "arwb lab: %s:%d: %s; the cell is run again\n", printable(cells_path).c_str(), n,
                       problem.c_str());
        }
        start = end + 1;
      }
    }
    if (resumed > 0)
      std::fprintf(stderr, "arwb lab: resuming: %d of %zu cells from %s (--restart runs them again)\n", resumed,
                   plan.cell_count(), cells_path.c_str());
    saved = std::fopen(cells_path.c_str(), "a");
    if (!saved) {
      print_problem("arwb lab: %s: cannot write (%s)\n", cells_path.c_str(), std::strerror(errno));
      return 1;
    }
    options.on_cell = [&](size_t index, const lab::CellResult& c) {
      const std::string line = lab::cell_to_line(key, index, c);
      std::fwrite(line.data(), 1, line.size(), saved);
      std::fflush(saved);
    };
  }

  const bool bar = ::isatty(2);
  int last_shown = -1;
  Result<lab::LabResults> r = lab::run_lab(plan, options, [&](int done, int total) {
    if (!bar) return;
    const int percent = total ? 100 * done / total : 100;
    if (percent == last_shown) return;
    last_shown = percent;
    std::fprintf(stderr, "\rarwb lab: %3d%% (%d of %d frames)", percent, done, total);
    if (done == total) std::fputc('\n', stderr);
  });
  if (saved) std::fclose(saved);
  if (!r) return cl.usage_error(r.error());
  if (!out.empty() && !write_outputs(*r, out)) return 1;
  if (json) {
    std::fputs(lab::lab_results_json(*r).c_str(), stdout);
    return 0;
  }
  std::printf("%s: %zu cells x %d frames (and %d without a marker), markers %s, camera %s, seed %d\n\n",
              plan_opt == "paper" ? "The paper's plan" : ("Plan " + plan.name).c_str(), plan.cell_count(),
              plan.frames_per_cell, plan.empty_frames_per_cell(), plan.dictionary.c_str(),
              r->options.camera_name.c_str(), seed);
  std::fputs(lab::lab_table_text(*r).c_str(), stdout);
  if (out.empty())
    std::printf("%s\n", lab::lab_time_text(*r).c_str());
  else
    std::printf("%s; wrote table.txt, table.csv, results.json, report.pdf and %zu PNG plots to %s\n",
                lab::lab_time_text(*r).c_str(), lab::lab_report_png_names(*r).size(), out.c_str());
  return 0;
}

}  // namespace arwb
