#include "lab/session.hpp"

#include "lab/detectors.hpp"

#include <chrono>

namespace arwb::lab {

int LabProgress::cells_done() const {
  int n = 0;
  for (const auto& r : results) n += r != nullptr;
  return n;
}

LabSession::~LabSession() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void LabSession::publish(const std::function<void(LabProgress&)>& change) {
  std::lock_guard lock(mutex_);
  auto next = std::make_shared<LabProgress>(*progress_);
  change(*next);
  ++next->revision;
  progress_ = std::move(next);
}

Status LabSession::start(const LabPlan& plan, const LabOptions& options) {
  stop();
  if (thread_.joinable()) thread_.join();
  // The detectors are made here first, so a plan they cannot read is refused at once with run_lab's message.
  for (const std::string& name : options.detectors) {
    if (auto d = make_detector(name, plan.dictionary, options.params); !d) return fail(d.error());
  }
  if (options.detectors.empty()) return fail("choose at least one detector");
  if (plan.cell_count() == 0) return fail("the plan has no cells (every axis needs a value)");
  if (plan.frames_per_cell < 1) return fail("a plan needs at least one frame per cell");
  stop_ = false;
  LabOptions opts = options;
  opts.finished.clear();
  opts.on_cell = nullptr;
  opts.stop = nullptr;
  publish([&](LabProgress& p) {
    const uint64_t revision = p.revision;
    p = LabProgress{};
    p.revision = revision;
    p.plan = plan;
    p.options = opts;
    p.ids = lab_marker_ids(plan, opts.seed);
    p.cells = plan.cells(opts.camera.camera_matrix(0, 0));
    p.results.assign(p.cells.size(), nullptr);
    p.frames_total = int(p.cells.size()) * (plan.frames_per_cell + plan.empty_frames_per_cell());
    p.running = true;
  });
  opts.stop = &stop_;
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [t0] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  opts.on_cell = [this, elapsed](size_t i, const CellResult& c) {
    auto cell = std::make_shared<const CellResult>(c);
    publish([&](LabProgress& p) {
      if (i < p.results.size()) p.results[i] = cell;
      p.seconds = elapsed();
    });
  };
  thread_ = std::thread([this, plan, opts, elapsed] {
    int last_done = -1;
    Result<LabResults> r = run_lab(plan, opts, [&](int done, int) {
      if (done == last_done) return;
      last_done = done;
      publish([&](LabProgress& p) {
        p.frames_done = done;
        p.seconds = elapsed();
      });
    });
    publish([&](LabProgress& p) {
      p.running = false;
      p.seconds = elapsed();
      if (r) {
        p.finished = true;
        LabResults done = std::move(*r);
        done.options.on_cell = nullptr;
        done.options.stop = nullptr;
        p.complete = std::make_shared<const LabResults>(std::move(done));
      } else {
        p.error = r.error();
      }
    });
  });
  return {};
}

void LabSession::stop() { stop_ = true; }

bool LabSession::running() const {
  std::lock_guard lock(mutex_);
  return progress_->running;
}

std::shared_ptr<const LabProgress> LabSession::snapshot() const {
  std::lock_guard lock(mutex_);
  return progress_;
}

}  // namespace arwb::lab
