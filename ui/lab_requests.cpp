// The Lab workspace's requests: a plan run in the background (lab::LabSession), a finished cell opened in the live
// view as a source (lab::LabCellSource: its frames exactly as the run judged them), plan files read into the
// panel's plan, and the report saved off the UI thread.
#include "ui/app.hpp"

#include "lab/cell_source.hpp"
#include "lab/report.hpp"
#include "ui/widgets.hpp"

#include <chrono>
#include <filesystem>
#include <cstdlib>
#include <memory>

namespace arwb {

namespace {

std::string plural(int n, const char* one, const char* many) { return std::to_string(n) + " " + (n == 1 ? one : many); }

}  // namespace

void App::lab_say(const std::string& message, bool is_error) {
  status.lab_message = message;
  status.lab_message_error = is_error;
  if (is_error) error("lab: " + message);
  else info("lab: " + message);
}

void App::start_lab() {
  const ui::LabSettings& ls = settings.lab;
  lab::LabOptions o;
  o.detectors = ls.detectors;
  o.seed = unsigned(ls.seed);
  o.params = settings.params;
  o.threads = 1;   // the window and the worker have the machine's other core
  if (ls.use_calibration && frame && frame->loaded_calibration) {
    // The calibration as made for the working image's size: the frames are rendered at that size, so the
    // acquisition step leaves them as the run saw them when a cell is opened.
    const Calibration& c = *frame->loaded_calibration;
    o.camera.size = frame->image.size();
    o.camera.camera_matrix = c.camera_matrix;
    o.camera.distortion = c.distortion;
    o.camera_name = c.source;
  }
  if (const Status s = lab_session.start(ls.plan, o); !s) return lab_say(s.error(), true);
  status.lab = lab_session.snapshot();
  const auto& p = *status.lab;
  lab_say("running " + ls.plan.name + ": " + plural(int(p.cells.size()), "cell", "cells") + ", " +
              plural(p.frames_total, "frame", "frames") + ", through " + o.camera_name,
          false);
}

void App::open_lab_cell(int cell, int start) {
  const std::shared_ptr<const lab::LabProgress> p = lab_session.snapshot();
  if (!p || cell < 0 || size_t(cell) >= p->cells.size()) {
    return lab_say("no cell " + std::to_string(cell) + " in the run (" +
                       plural(p ? int(p->cells.size()) : 0, "cell", "cells") + ")",
                   true);
  }
  // The detector reads the plan's dictionary, as the run's arwb did.
  if (settings.dictionaries != std::vector<std::string>{p->plan.dictionary}) {
    settings.dictionaries = {p->plan.dictionary};
    change_name = "the lab plan's dictionary " + p->plan.dictionary;
  }
  settings.playback.playing = false;
  const std::string name = "lab: " + lab::cell_name(p->cells[size_t(cell)]);
  engine->open_made_source(std::make_unique<lab::LabCellSource>(p->plan, p->options, p->ids, size_t(cell), start),
                           SourceSpec{SourceKind::lab, 0, name, {}});
  status.lab_cell = cell;
  view.show(ui::Panel::live_view);
}

void App::read_lab_plan(const std::string& path) {
  Result<lab::LabPlan> plan = lab::read_plan(path);
  if (!plan) return lab_say(plan.error(), true);   // the panel's plan stays as it was
  settings.lab.plan = std::move(*plan);
  lab_say("plan " + settings.lab.plan.name + " read from " + path, false);
}

void App::save_lab_report(const std::string& dir) {
  const std::shared_ptr<const lab::LabProgress> p = lab_session.snapshot();
  if (!p || !p->complete) return lab_say("nothing to save: no run has finished every cell", true);
  if (lab_save_future.valid()) return;   // one save at a time
  lab_save_dir = dir;
  status.lab_saving = true;
  lab_save_future = std::async(std::launch::async, [results = p->complete, dir] {
    return lab::write_lab_outputs(*results, dir);
  });
}

// The clip's row (as typed first, when given) for the video playing, into videos.csv.
void App::save_clip(const std::optional<ui::ClipRow>& typed) {
  lab::VideoRow& clip = settings.lab.clip;
  if (typed) {
    clip.id = typed->id;
    clip.size_mm = typed->size_mm;
    clip.distance_m = typed->distance_m;
    clip.lux = typed->lux;
    clip.dictionary = settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : settings.dictionaries[0];
    settings.lab.videos_dir = typed->dir;
  }
  const SourceSpec src = engine->source();
  if (src.kind != SourceKind::video) return lab_say("marking a clip needs a video as the source", true);
  const std::string dir = settings.lab.videos_dir.empty() ? std::filesystem::path(src.path).parent_path().string()
                                                          : settings.lab.videos_dir;
  lab::VideoRow row = clip;
  if (row.first_frame < 0 || row.last_frame < 0) row.first_frame = 0, row.last_frame = -1;   // the whole clip
  const std::string list = (std::filesystem::path(dir.empty() ? "." : dir) / "videos.csv").string();
  if (const Status s = lab::save_video_row(dir.empty() ? "." : dir, src.path, row); !s) return lab_say(s.error(), true);
  lab_say(list + ": " + std::filesystem::path(src.path).filename().string() + ", marker " + std::to_string(row.id) +
              (row.last_frame >= 0 ? ", frames " + std::to_string(row.first_frame) + " to " + std::to_string(row.last_frame)
                                   : ", the whole clip"),
          false);
}

// The Lab panel's span buttons on the video frame shown.
void App::mark_clip_span(ui::SpanEnd end) {
  lab::VideoRow& row = settings.lab.clip;
  const int at = frame ? frame->source.position : 0;
  if (end == ui::SpanEnd::start) row.first_frame = at;
  else if (end == ui::SpanEnd::end) row.last_frame = at;
  else row.first_frame = row.last_frame = -1;
}

// What the Lab panel's "Why not detected?" does on the frame shown: the region on the marker's truth.
void App::why_lab_marker() {
  if (!frame || frame->truth.empty()) return warn("--actions lab_why: the frame shown has no marker's truth");
  ui::why_on_marker(view, frame->truth[0].corners);
}

void App::poll_lab() {
  const std::shared_ptr<const lab::LabProgress> before = status.lab;
  status.lab = lab_session.snapshot();
  const lab::LabProgress* p = status.lab.get();
  // A run that ended since the last UI frame: say how.
  if (before && before->running && p && !p->running && p->revision != before->revision) {
    status.lab_message_error = !p->finished;
    status.lab_message = p->finished ? "finished: " + plural(int(p->cells.size()), "cell", "cells") + " in " +
                                           std::to_string(int(p->seconds + 0.5)) + " s; click a cell to see its frames"
                                     : p->error;
    info("lab: " + status.lab_message);
  }
  if (lab_save_future.valid() && lab_save_future.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    status.lab_saving = false;
    const Status s = lab_save_future.get();
    status.lab_message_error = !s;
    status.lab_message = s ? "saved the tables, plots and report.pdf to " + lab_save_dir : s.error();
    if (s) note_status("lab: " + status.lab_message);
    else error("lab: " + status.lab_message);
  }
}

}  // namespace arwb
