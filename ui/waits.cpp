// What a script waits for (--actions next, calib_wait, lab_wait, export_wait, play_wait): the window waits, not drawn
// meanwhile, until the worker or a thread has got there, whatever the machine's speed, and says so when it did not
// within the time given. A step of the same frame before it was carried out already.
#include "ui/app.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

namespace arwb {

// The source's next frame, shown: two steps a few frames apart had reached the worker as one. A video or folder
// steps to the frame after the one shown (the worker's next_frame), other sources give their next frame, and a
// still image none.
void App::next_frame_shown() {
  forward_settings();   // a freeze of this same frame reaches the worker first
  const uint64_t ticket = engine->next_frame();
  const auto end = Clock::now() + std::chrono::seconds(2);
  while (engine->served() < ticket && engine->running() && Clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  if (engine->served() < ticket) warn("--actions next: the worker did not take the frame within 2 s");
  if (auto f = engine->latest()) frame = f;
}

// Until `views` views are kept and the views are solved (120 s at most). The worker goes on meanwhile.
void App::wait_for_calibration(int views) {
  const size_t want = static_cast<size_t>(std::max(0, views));
  const auto end = Clock::now() + std::chrono::seconds(120);
  // The settings changed this frame (a workspace switched to, capture turned off) reach the worker first.
  forward_settings();
  // Two frames newer than now: the worker may be finishing a frame begun before this frame's requests reached it.
  std::shared_ptr<const Frame> f = engine->latest();
  for (int i = 0; i < 2 && Clock::now() < end; ++i) f = engine->wait_newer(f ? f->index : 0, 60);
  while (Clock::now() < end) {
    const CalibrationSnapshot* c = f ? f->calibration.get() : nullptr;
    const bool settled = c && !c->solving && (c->solved_revision == c->revision || !c->solve_error.empty());
    if (c && c->views.size() >= want && settled && c->capture == settings.calibration.capture) {
      frame = f;
      return;
    }
    f = engine->wait_newer(f ? f->index : 0, 0.5);
  }
  warn("--actions calib_wait=" + std::to_string(views) + ": the calibration did not get there within 120 s");
}

// Until the run has finished `cells` cells (-1: until it ends; 600 s at most).
void App::wait_for_lab(int cells) {
  const auto end = Clock::now() + std::chrono::seconds(600);
  while (Clock::now() < end) {
    const auto run = lab_session.snapshot();
    if (!run->running || (cells >= 0 && run->cells_done() >= cells)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  poll_lab();
  if (lab_session.running() && cells < 0) warn("--actions lab_wait: the run did not end within 600 s");
}

// Until the check, export or server start running has finished.
void App::wait_export(double timeout_s) {
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  const ExportDialog& d = export_dialog;
  const auto busy = [&d] { return d.checking.valid() || d.writing.valid() || d.serve_starting.valid(); };
  while (Clock::now() < end && busy()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    poll_export();
  }
  if (busy())
    warn("--actions export_wait: the export did not finish within " + std::to_string(int(timeout_s)) + " s");
}

// Until the worker has taken the source last opened (it takes only the newest of those asked for meanwhile).
void App::wait_source(double timeout_s) {
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (Clock::now() < end && engine->source().text() != asked_source)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (engine->source().text() != asked_source)
    warn("--actions source_wait: the source " + asked_source + " was not taken within " +
         std::to_string(int(timeout_s)) + " s");
}

// Until every player started has ended.
void App::wait_players(double timeout_s) {
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  auto running = [this] {
    std::lock_guard lock(players->mutex);
    return players->running;
  };
  while (Clock::now() < end && running() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  poll_export();
  if (running() > 0) warn("--actions play_wait: a player still runs after " + std::to_string(int(timeout_s)) + " s");
}

}  // namespace arwb
