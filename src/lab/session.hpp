// A lab run in the background, for the workbench's Lab workspace: the plan runs on a thread of its own while the
// window goes on, and each snapshot says how far it got, cell by cell, so the grid fills in as cells finish. A
// stopped or failed run keeps the cells it finished. The window owns the session and polls it once per UI frame.
#pragma once

#include "lab/run.hpp"

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace arwb::lab {

struct LabProgress {
  uint64_t revision = 0;        // counts changes (a frame done, a cell finished, the end)
  LabPlan plan;
  LabOptions options;           // without the run's callbacks
  std::vector<int> ids;         // the markers shown (lab_marker_ids)
  std::vector<Cell> cells;      // plan.cells(the camera's focal length)
  std::vector<std::shared_ptr<const CellResult>> results;   // by cell; null until that cell is finished
  int frames_done = 0, frames_total = 0;
  bool running = false;
  bool finished = false;        // every cell done
  std::string error;            // why it stopped early ("stopped after 4 of 27 cells (those are kept)")
  double seconds = 0;           // so far, or in all
  int cells_done() const;
  // The finished run as run_lab returns it (every cell present); null before that.
  std::shared_ptr<const LabResults> complete;
};

class LabSession {
 public:
  LabSession() = default;
  ~LabSession();
  LabSession(const LabSession&) = delete;
  LabSession& operator=(const LabSession&) = delete;

  // Starts a run (a running one is stopped first). An error (unknown detector or dictionary, an empty plan) is
  // returned at once and nothing runs.
  Status start(const LabPlan& plan, const LabOptions& options);
  // Asks the run to stop after the frame in hand; the snapshot says so once it has.
  void stop();
  bool running() const;
  std::shared_ptr<const LabProgress> snapshot() const;

 private:
  void publish(const std::function<void(LabProgress&)>& change);
  mutable std::mutex mutex_;
  std::shared_ptr<const LabProgress> progress_ = std::make_shared<LabProgress>();
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace arwb::lab
