// The Lab workspace's requests: a plan run in the background (lab::LabSession), a finished cell opened in the live
// view as a source (lab::LabCellSource: its frames exactly as the run judged them), plan files read into the
// panel's plan, and the report saved off the UI thread.
#include "ui/app.hpp"

#include "lab/cell_source.hpp"
#include "lab/report.hpp"

#include <chrono>
#include <filesystem>
#include <cstdlib>
#include <memory>

namespace arwb {

namespace {

std::string plural(int n, const char* one, const char* many) { return std::to_string(n) + " " + (n == 1 ? one : many); }

}  // namespace

void App::lab_request(const ui::Request& r) {
  auto say = [this](const std::string& message, bool is_error) {
    status.lab_message = message;
    status.lab_message_error = is_error;
    if (is_error) error("lab: " + message);
    else info("lab: " + message);
  };
  switch (r.kind) {
    case ui::RequestKind::lab_start: {
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
      if (const Status s = lab_session.start(ls.plan, o); !s) {
        say(s.error(), true);
        break;
      }
      status.lab = lab_session.snapshot();
      const auto& p = *status.lab;
      say("running " + ls.plan.name + ": " + plural(int(p.cells.size()), "cell", "cells") + ", " +
              plural(p.frames_total, "frame", "frames") + ", through " + o.camera_name,
          false);
      break;
    }
    case ui::RequestKind::lab_stop:
      if (lab_session.running()) lab_session.stop();
      break;
    case ui::RequestKind::lab_open_cell: {
      const std::shared_ptr<const lab::LabProgress> p = lab_session.snapshot();
      if (!p || r.value < 0 || size_t(r.value) >= p->cells.size()) {
        say("no cell " + std::to_string(r.value) + " in the run (" + plural(p ? int(p->cells.size()) : 0, "cell", "cells") +
                ")",
            true);
        break;
      }
      const int start = r.text.empty() ? 0 : std::atoi(r.text.c_str());
      // The detector reads the plan's dictionary, as the run's arwb did.
      if (settings.dictionaries != std::vector<std::string>{p->plan.dictionary}) {
        settings.dictionaries = {p->plan.dictionary};
        change_name = "the lab plan's dictionary " + p->plan.dictionary;
      }
      settings.playback.playing = false;
      const std::string name = "lab: " + lab::cell_name(p->cells[size_t(r.value)]);
      engine->open_made_source(
          std::make_unique<lab::LabCellSource>(p->plan, p->options, p->ids, size_t(r.value), start),
          SourceSpec{SourceKind::lab, 0, name, {}});
      status.lab_cell = r.value;
      view.show(ui::Panel::live_view);
      break;
    }
    case ui::RequestKind::lab_read_plan: {
      Result<lab::LabPlan> plan = lab::read_plan(r.text);
      if (!plan) {
        say(plan.error(), true);   // the panel's plan stays as it was
        break;
      }
      settings.lab.plan = std::move(*plan);
      say("plan " + settings.lab.plan.name + " read from " + r.text, false);
      break;
    }
    case ui::RequestKind::lab_save: {
      const std::shared_ptr<const lab::LabProgress> p = lab_session.snapshot();
      if (!p || !p->complete) {
        say("nothing to save: no run has finished every cell", true);
        break;
      }
      if (lab_save_future.valid()) break;   // one save at a time
      lab_save_dir = r.text;
      status.lab_saving = true;
      lab_save_future = std::async(std::launch::async, [results = p->complete, dir = r.text] {
        return lab::write_lab_outputs(*results, dir);
      });
      break;
    }
    case ui::RequestKind::lab_save_clip: {
      const SourceSpec src = engine->source();
      if (src.kind != SourceKind::video) {
        say("marking a clip needs a video as the source", true);
        break;
      }
      const std::string dir = settings.lab.videos_dir.empty()
                                  ? std::filesystem::path(src.path).parent_path().string()
                                  : settings.lab.videos_dir;
      lab::VideoRow row = settings.lab.clip;
      if (row.first_frame < 0 || row.last_frame < 0) row.first_frame = 0, row.last_frame = -1;   // the whole clip
      const std::string list = (std::filesystem::path(dir.empty() ? "." : dir) / "videos.csv").string();
      if (const Status s = lab::save_video_row(dir.empty() ? "." : dir, src.path, row); !s) {
        say(s.error(), true);
        break;
      }
      say(list + ": " + std::filesystem::path(src.path).filename().string() + ", marker " + std::to_string(row.id) +
              (row.last_frame >= 0 ? ", frames " + std::to_string(row.first_frame) + " to " + std::to_string(row.last_frame)
                                   : ", the whole clip"),
          false);
      break;
    }
    default: break;
  }
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
