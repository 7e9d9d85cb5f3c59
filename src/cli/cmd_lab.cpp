// arwb lab: the paper's experiment (section 5) on frames rendered through a physical camera and sensor model,
// every detector on the same frames; the paper's table with 95 % intervals, as text, CSV and JSON.
#include "calibration/calibration_file.hpp"
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "lab/cells_file.hpp"
#include "lab/report.hpp"
#include "lab/run.hpp"
#include "lab/videos.hpp"
#include "base/decimals.hpp"
#include "base/files.hpp"
#include "base/text.hpp"

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
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

// The cells of run `key` saved in `path` into options.finished; the lines that cannot be a run's are named. Null
// with the problem printed when the file cannot be read.
std::optional<lab::CellsFile> take_saved_cells(const std::string& path, const std::string& key,
                                               lab::LabOptions& options, const char* then) {
  Result<lab::CellsFile> f = lab::read_cells_file(path, key, options.detectors.size(), options.finished);
  if (!f) {
    print_problem("arwb lab: %s\n", f.error().c_str());
    return std::nullopt;
  }
  for (const std::string& p : f->problems) std::fprintf(stderr, "arwb lab: %s; %s\n", p.c_str(), then);
  return std::move(*f);
}

// "cell 2 (65 mm, 1.0 m, 850 lx)".
std::string cell_words(size_t index, const lab::Cell& c) {
  return "cell " + std::to_string(index + 1) + " (" + fixed_text(c.size_mm, 0) + " mm, " + fixed_text(c.distance_m, 1) +
         " m, " + fixed_text(c.lux, 0) + " lx)";
}

// --merge: every cell of the plan from the parts' folders into options.finished; false with the problem printed.
bool take_parts(const std::vector<std::string>& dirs, const std::string& key, const lab::LabPlan& plan,
                lab::LabOptions& options) {
  options.finished.assign(plan.cell_count(), nullptr);
  for (const std::string& dir : dirs) {
    const std::string path = (std::filesystem::path(dir) / "cells.jsonl").string();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) {
      print_problem("arwb lab: --merge %s: no cells.jsonl there (the --out folder of a part run with --shard "
                    "holds one)\n", printable(dir).c_str());
      return false;
    }
    const std::optional<lab::CellsFile> f = take_saved_cells(path, key, options, "that cell is left out");
    if (!f) return false;
    if (f->taken == 0 && f->other_runs > 0) {
      print_problem("arwb lab: --merge %s: its cells are of another run (%s); give --merge the plan and options its "
                    "parts were run with\n", printable(path).c_str(), f->other_run.c_str());
      return false;
    }
  }
  const std::vector<lab::Cell> cells = plan.cells(options.camera.camera_matrix(0, 0));
  std::vector<size_t> missing;
  for (size_t i = 0; i < cells.size(); ++i)
    if (!options.finished[i]) missing.push_back(i);
  if (missing.empty()) return true;
  std::string names;
  for (size_t k = 0; k < missing.size() && k < 3; ++k)
    names += (k ? ", " : "") + cell_words(missing[k], cells[missing[k]]);
  if (missing.size() > 3) names += ", ...";
  print_problem("arwb lab: --merge: %zu of %zu cells are in none of the folders: %s; run the parts that hold them "
                "(--shard) and merge again\n", missing.size(), cells.size(), names.c_str());
  return false;
}

// --shard K/N: the part's cells run (or resumed) and saved; no table, which the merge of all parts makes.
int run_part(CommandLine& cl, const lab::LabPlan& plan, const lab::LabOptions& options, const lab::Shard& shard,
             const std::string& cells_path, const std::string& plan_words) {
  const bool bar = ::isatty(2);
  Result<lab::PartRun> r = lab::run_lab_part(plan, options, shard, [&](int done, int total) {
    if (bar) std::fprintf(stderr, "\rarwb lab: part %d of %d: %d of %d frames%s", shard.index, shard.count, done,
                          total, done == total ? "\n" : "");
  });
  if (!r) return cl.usage_error(r.error());
  std::printf("Part %d of %d of %s: %d of %zu cells", shard.index, shard.count, plan_words.c_str(), r->cells,
              plan.cell_count());
  if (r->resumed > 0) std::printf(" (%d from an earlier run)", r->resumed);
  std::printf(" in %s s, saved in %s\nWhen every part is done: arwb lab --merge FOLDER... with the same plan and "
              "options\n", fixed_text(r->seconds, 1).c_str(), cells_path.c_str());
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
  std::string detectors_opt = "arwb,opencv,opencv-aruco3", out, calib_file, params_file, plan_opt = "paper", videos,
              shard_opt;
  std::vector<std::string> merge;
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
  cl.app.add_option("--frames-per-cell", frames, "frames rendered for each cell (default: the plan's, 400 in the "
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
  auto* shard_flag = cl.app.add_option("--shard", shard_opt, "runs only the K-th of N parts of the plan's cells "
                                       "(every N-th cell) and saves them in --out's cells.jsonl, for a run spread "
                                       "over processes or machines; --merge joins the parts (docs/lab.md)")
                         ->type_name("K/N");
  auto* merge_flag = cl.app.add_option("--merge", merge, "joins the cells of the parts run with --shard (their --out "
                                       "folders) into the run's table, plots and report, as one run gives them; "
                                       "with the plan and options the parts were run with")
                         ->type_name("FOLDER...")
                         ->excludes(shard_flag);
  cl.app.add_flag("--json", json, "print results.json instead of the table")->excludes(shard_flag);
  cl.app.get_option("--videos")->excludes(shard_flag)->excludes(merge_flag);
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

  lab::Shard shard;
  if (!shard_opt.empty()) {
    Result<lab::Shard> sh = lab::parse_shard(shard_opt);
    if (!sh) return cl.usage_error("--shard " + sh.error());
    if (out.empty()) return cl.usage_error("--shard needs --out: a part's cells are saved there for --merge");
    shard = *sh;
  }
  const std::string plan_words = plan_opt == "paper" ? "the paper's plan" : "plan " + plan.name;
  // Resuming: the cells an earlier run with the same plan and options saved; the others are run and saved as
  // they finish, one line each, so an interruption loses at most the cell it was in. A merge takes them all from
  // the parts' folders instead.
  const std::string key = lab::lab_run_key(plan, options);
  const std::string cells_path = out.empty() ? "" : (std::filesystem::path(out) / "cells.jsonl").string();
  if (!merge.empty() && !take_parts(merge, key, plan, options)) return 1;
  std::FILE* saved = nullptr;
  std::error_code ec;
  if (!out.empty()) std::filesystem::create_directories(out, ec);
  if (!out.empty() && merge.empty()) {
    if (restart) std::filesystem::remove(cells_path, ec);
    options.finished.resize(plan.cell_count());
    const std::optional<lab::CellsFile> f = take_saved_cells(cells_path, key, options, "the cell is run again");
    if (!f) return 1;
    if (f->taken > 0)
      std::fprintf(stderr, "arwb lab: resuming: %d of %zu cells from %s (--restart runs them again)\n", f->taken,
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
  if (!shard_opt.empty()) {
    const int status = run_part(cl, plan, options, shard, cells_path, plan_words);
    if (saved) std::fclose(saved);
    return status;
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
  if (!merge.empty()) {
    r->merged_parts = int(merge.size());
    std::string error;
    // The merged folder holds every cell, as a single run's does: it resumes, and merges again.
    if (!out.empty() && !write_file_atomically(cells_path, lab::cells_file_text(key, r->cells), &error)) {
      print_problem("arwb lab: %s\n", error.c_str());
      return 1;
    }
  }
  if (!out.empty() && !write_outputs(*r, out)) return 1;
  if (json) {
    std::fputs(lab::lab_results_json(*r).c_str(), stdout);
    return 0;
  }
  std::string title = plan_words;
  title[0] = char(std::toupper(static_cast<unsigned char>(title[0])));
  const std::string curves = plan.curves_text().empty() ? "" : ", and " + plan.curves_text();
  std::printf("%s: %zu cells x %d frames (and %d without a marker)%s, markers %s, camera %s, seed %d\n\n",
              title.c_str(), plan.grid_count(), plan.frames_per_cell, plan.empty_frames_per_cell(), curves.c_str(),
              plan.dictionary.c_str(), r->options.camera_name.c_str(), seed);
  std::fputs(lab::lab_table_text(*r).c_str(), stdout);
  if (out.empty())
    std::printf("%s\n", lab::lab_time_text(*r).c_str());
  else
    std::printf("%s; wrote table.txt, table.csv, results.json, report.pdf and %zu PNG plots to %s\n",
                lab::lab_time_text(*r).c_str(), lab::lab_report_png_names(*r).size(), out.c_str());
  return 0;
}

}  // namespace arwb
