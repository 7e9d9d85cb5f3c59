#include "calibration/session.hpp"

#include "calibration/coach.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

namespace arwb {

namespace {
constexpr size_t kRecent = 12;
}  // namespace

void CalibrationSession::update_coverage() {
  state_.grid = corner_grid(state_.views, state_.image_size);
  state_.bars = coverage_bars(state_.poses);
  state_.advice = coverage_advice(state_.bars, state_.grid, int(state_.views.size()));
}

CalibrationSession::CalibrationSession(BoardSpec board, SelectOptions select, SolveOptions solve)
    : board_(std::move(board)), select_(select), solve_opt_(solve), selector_(board_, select_) {
  state_.board = board_;
  update_coverage();
}

CalibrationSession::~CalibrationSession() {
  if (running_.valid()) running_.wait();
  if (finding_.valid()) finding_.wait();
}

void CalibrationSession::set_board(const BoardSpec& board) {
  if (board == board_) return;
  board_ = board;
  reset();
}

void CalibrationSession::set_capture(bool on) {
  if (state_.capture == on) return;
  state_.capture = on;
  changed();
}

void CalibrationSession::set_stills(bool stills) {
  if (select_.video == !stills) return;
  select_.video = !stills;
  rebuild_selector();
}

void CalibrationSession::reset() {
  const bool capture = state_.capture;
  const int revision = state_.revision + 1;
  state_ = CalibrationSnapshot{};
  state_.board = board_;
  state_.capture = capture;
  state_.revision = revision;
  base_revision_ = revision;
  state_.solving = running_.valid();
  selector_ = ViewSelector(board_, select_);
  update_coverage();
  changed();
}

// The selector remembers the poses it kept, to refuse a view like one of them; after a drop it must forget that
// one. It has no way to forget, so a new one is given the views left: each twice, as a still board (the first
// time it has no previous frame to measure motion against).
void CalibrationSession::rebuild_selector() {
  selector_ = ViewSelector(board_, select_);
  for (const CalibrationView& v : state_.views) {
    BoardDetection d;
    d.found = true;
    d.corners = v.corners;
    d.ids = v.ids;
    if (select_.video) selector_.consider(d, state_.image_size);
    selector_.consider(d, state_.image_size);
  }
}

bool CalibrationSession::drop_view(const std::string& name) {
  for (size_t i = 0; i < state_.views.size(); ++i) {
    if (state_.views[i].name != name) continue;
    state_.views.erase(state_.views.begin() + static_cast<std::ptrdiff_t>(i));
    state_.poses.erase(state_.poses.begin() + static_cast<std::ptrdiff_t>(i));
    ++state_.revision;
    ++state_.dropped;
    rebuild_selector();
    update_coverage();
    changed();
    poll();
    return true;
  }
  return false;
}

void CalibrationSession::feed(const cv::Mat& frame, const std::string& name) {
  if (frame.empty()) return;
  if (finding_.valid()) {
    finding_.wait();
    poll();
  }
  // The snapshot's picture is a copy: the caller's frame may be a source's buffer that it fills again.
  judge(detect_board(frame, board_), frame.clone(), name);
}

bool CalibrationSession::offer(const cv::Mat& frame, const std::string& name) {
  if (frame.empty()) return false;
  if (finding_.valid()) {
    ++state_.skipped;
    changed();
    return false;
  }
  finding_name_ = name;
  finding_base_ = base_revision_;
  finding_image_ = frame.clone();
  finding_ = std::async(std::launch::async, [image = finding_image_, board = board_] { return detect_board(image, board); });
  return true;
}

void CalibrationSession::judge(const BoardDetection& d, const cv::Mat& frame, const std::string& name) {
  const cv::Size size = frame.size();
  if (state_.image_size.area() > 0 && size != state_.image_size) reset();
  state_.image_size = size;
  state_.frame_name = name;
  state_.searched = frame;
  state_.detection = d;
  ++state_.frames;
  state_.boards += state_.detection.found;
  if (state_.capture) {
    state_.verdict = selector_.consider(state_.detection, size);
    ++state_.tally[state_.verdict.kind];
    if (state_.verdict.keep) {
      state_.views.push_back({name, state_.detection.corners, state_.detection.ids});
      state_.poses.push_back(view_pose(state_.detection.corners, state_.detection.ids, board_, size));
      ++state_.revision;
      update_coverage();
    }
    state_.recent.insert(state_.recent.begin(), {name, state_.verdict.reason, state_.verdict.keep});
    if (state_.recent.size() > kRecent) state_.recent.pop_back();
  } else {
    state_.verdict = {false, state_.detection.found ? "capture is off" : "no board", "off"};
  }
  changed();
  poll();
}

void CalibrationSession::start_solve() {
  running_revision_ = state_.revision;
  // Copies: the thread owns what it solves.
  running_ = std::async(std::launch::async, [views = state_.views, board = board_, size = state_.image_size,
                                             opt = solve_opt_] { return solve_calibration(views, board, size, opt); });
  state_.solving = true;
}

bool CalibrationSession::poll() {
  bool any = false;
  if (finding_.valid() && finding_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    const BoardDetection d = finding_.get();
    // A search begun before a reset or another board is of no use now.
    if (finding_base_ == base_revision_) judge(d, finding_image_, finding_name_);
    finding_image_ = cv::Mat();
    any = true;
  }
  if (running_.valid() && running_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    Result<Solution> r = running_.get();
    state_.solving = false;
    if (running_revision_ >= base_revision_) {
      if (r) {
        state_.solution = std::make_shared<const Solution>(std::move(*r));
        state_.solved_revision = running_revision_;
        if (running_revision_ == state_.revision) state_.solve_error.clear();
      } else if (running_revision_ == state_.revision) {
        state_.solve_error = r.error();
      }
    }
    any = true;
  }
  const int wanted = state_.revision;
  const bool tried = state_.solved_revision == wanted || (!state_.solve_error.empty() && running_revision_ == wanted);
  if (!running_.valid() && !tried && state_.image_size.area() > 0) {
    if (static_cast<int>(state_.views.size()) < solve_opt_.min_views) {
      // Not worth a thread: the solve would refuse at once; say what is missing instead.
      const size_t n = state_.views.size();
      const std::string why = std::to_string(n) + (n == 1 ? " view" : " views") + "; at least " +
                              std::to_string(solve_opt_.min_views) + " are needed to solve";
      if (state_.solve_error != why || state_.solution) {
        state_.solve_error = why;
        state_.solution.reset();
        state_.solved_revision = -1;
        any = true;
      }
      running_revision_ = wanted;
    } else {
      start_solve();
      any = true;
    }
  }
  if (any) changed();
  return any;
}

std::shared_ptr<const CalibrationSnapshot> CalibrationSession::snapshot() {
  if (!snap_) snap_ = std::make_shared<const CalibrationSnapshot>(state_);
  return snap_;
}

bool CalibrationSession::wait_solved(double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  for (;;) {
    poll();
    // Nothing judged since a reset leaves nothing to solve.
    const bool settled = !running_.valid() && !finding_.valid() && (state_.solved_revision == state_.revision ||
                                                                    state_.image_size.area() == 0 ||
                                               (!state_.solve_error.empty() && running_revision_ == state_.revision));
    if (settled) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace arwb
