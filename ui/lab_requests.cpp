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

// The conditions as typed in the Lab panel (--actions lab_clip, lab_record), the marker of the first dictionary.
void type_clip_row(lab::VideoRow& clip, const ui::ClipRow& typed, const std::vector<std::string>& dictionaries) {
  clip.id = typed.id;
  clip.size_mm = typed.size_mm;
  clip.distance_m = typed.distance_m;
  clip.lux = typed.lux;
  clip.dictionary = dictionaries.empty() ? "ARUCO_ORIGINAL" : dictionaries[0];
}

// clips/m17_65mm_1m_850lx_1.mkv: the marker and conditions in the name, then the first number not taken in `dir`.
std::string clip_name(const std::string& dir, const lab::VideoRow& row) {
  char stem[160];
  std::snprintf(stem, sizeof stem, "clips/m%d_%gmm_%gm_%glx_", row.id, row.size_mm, row.distance_m, row.lux);
  std::error_code ec;
  for (int k = 1;; ++k) {
    const std::string name = stem + std::to_string(k) + ".mkv";
    if (!std::filesystem::exists(std::filesystem::path(dir) / name, ec)) return name;
  }
}

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
    type_clip_row(clip, *typed, settings.dictionaries);
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

// Record: the source's frames from now into a clip of DIR/clips (lossless), with the conditions as typed; the row
// goes into DIR/videos.csv when it stops. The conditions are checked first, so that no clip is filmed for nothing.
void App::record_clip(const std::optional<ui::ClipRow>& typed) {
  lab::VideoRow& clip = settings.lab.clip;
  if (typed) {
    type_clip_row(clip, *typed, settings.dictionaries);
    if (!typed->dir.empty()) settings.lab.record_dir = typed->dir;
  }
  if (status.lab_recording) return lab_say("a clip is being recorded: Stop it first", true);
  const SourceSpec src = engine->source();
  if (src.kind == SourceKind::lab)
    return lab_say("recording needs a camera or a video as the source, not a lab cell", true);
  if (!frame || frame->source.size.area() == 0) return lab_say("recording needs a frame from the source first", true);
  lab::VideoRow row = clip;
  row.first_frame = 0;
  row.last_frame = -1;
  if (const Status s = lab::check_video_row(row); !s) return lab_say("the clip's conditions: " + s.error(), true);
  const std::string dir = ui::record_folder(settings.lab, status.config_dir);
  const std::string path = (std::filesystem::path(dir) / clip_name(dir, row)).string();
  auto rec = std::make_shared<ClipRecorder>();
  if (const Status s = rec->start(path, frame->source.size, frame->source.native_fps); !s)
    return lab_say(s.error(), true);
  recorder = std::move(rec);
  engine->set_recorder(recorder);
  recording_row = row;
  recording_dir = dir;
  status.lab_recording = true;
  status.lab_clip = recorder->progress();
  lab::Cell cell;
  cell.size_mm = row.size_mm;
  cell.distance_m = row.distance_m;
  cell.lux = row.lux;
  lab_say("recording " + path + " from " + src.text() + ": marker " + std::to_string(row.id) + ", " +
              lab::cell_name(cell),
          false);
}

// Stop: the clip is closed and listed in videos.csv as one whole-clip row. A clip that got no frame is removed.
void App::stop_clip() {
  if (!status.lab_recording || !recorder) return lab_say("no clip is being recorded", true);
  engine->set_recorder(nullptr);
  status.lab_clip = recorder->stop();
  status.lab_recording = false;
  const ClipSummary& c = status.lab_clip;
  std::error_code ec;
  if (c.frames == 0) {
    std::filesystem::remove(c.path, ec);
    return lab_say("no frame came from the source while recording (is it frozen or at its end?): no clip kept" +
                       (c.error.empty() ? "" : "; " + c.error),
                   true);
  }
  const std::string list = (std::filesystem::path(recording_dir) / "videos.csv").string();
  if (const Status s = lab::save_video_row(recording_dir, c.path, recording_row); !s)
    return lab_say(s.error() + " (the clip is kept: " + c.path + ")", true);
  char b[160];
  std::snprintf(b, sizeof b, ", %lld frames in %.1f s", (long long)c.frames, c.seconds);
  std::string said = list + ": " + std::filesystem::path(c.path).filename().string() + b;
  if (c.dropped > 0) said += "; " + plural(int(c.dropped), "frame", "frames") + " dropped (the disk was too slow)";
  if (!c.error.empty()) said += "; " + c.error;
  lab_say(said, c.dropped > 0 || !c.error.empty());
}

// The marker to film, at the size typed: one page with the printer's check bar, beside the clips.
void App::print_clip_marker() {
  const lab::VideoRow& c = settings.lab.clip;
  char name[96];
  std::snprintf(name, sizeof name, "marker_%d_%gmm.pdf", c.id, c.size_mm);
  const std::string dir = ui::record_folder(settings.lab, status.config_dir);
  write_marker_sheet({(std::filesystem::path(dir) / name).string(), c.dictionary, std::to_string(c.id), c.size_mm});
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
  if (status.lab_recording && recorder) {
    status.lab_clip = recorder->progress();
    if (!recorder->recording()) stop_clip();   // it ended on its own: the source's frames changed size
  }
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
