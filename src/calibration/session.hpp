// A calibration session, as the Calibrate workspace runs one: frames come in one by one, the board is looked for in
// each, the selector keeps the frames that make good views (and says why it refused the others), and the views
// are solved again whenever they change. The solve runs on a thread of its own (it can take a second), and so can
// the board search (OpenCV's search for a chessboard takes a second or more on a frame without one): a live
// source offers every frame, and the frames that come while the search is busy are skipped, so the live view
// never waits for either. The newest finished solve is handed out with the rest of the state as one immutable
// snapshot. Knows nothing of the window: the workbench's worker feeds it and publishes the snapshot on its Frame.
#pragma once

#include "calibration/board.hpp"
#include "calibration/solve.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <future>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace arwb {


// What the Calibrate panels draw, as of one frame.
struct CalibrationSnapshot {
  BoardSpec board;
  bool capture = true;                    // frames are being judged and kept
  cv::Size image_size;                    // of the views (0x0 before the first frame)
  int frames = 0, boards = 0;             // frames judged, and those with the board in them
  int skipped = 0;                        // frames offered while the board search was busy with an earlier one
  // The frame this snapshot was made with: where the board was found (empty when it was not) and the verdict.
  BoardDetection detection;
  Verdict verdict;
  std::string frame_name;
  // That frame's picture (shared, not copied): the search runs behind the frames, and a view that draws the
  // corners on it draws them where they were found, not on a later frame where the board has moved.
  cv::Mat searched;
  std::vector<CalibrationView> views;     // kept, oldest first
  std::vector<ViewPose> poses;            // of each view
  // The coverage of the views kept, as the solve's report measures it (ROS's bars and the 8x6 grid of corners),
  // kept up to date with every view, so the bars fill up before there are enough views to solve.
  CoverageBars bars;
  cv::Mat1i grid;
  std::string advice;   // the coach's next step from the two (calibration/coach.hpp)
  std::map<std::string, int> tally;       // verdicts by kind ("kept", "no board", "moving", ...)
  int dropped = 0;                        // views the user dropped (kept, then taken out)
  struct Judged {
    std::string frame, reason;
    bool kept = false;
  };
  std::vector<Judged> recent;             // the last frames judged, newest first
  std::shared_ptr<const Solution> solution;   // the newest finished solve; null before the first
  int solved_revision = -1;               // the `revision` it was made from
  int revision = 0;                       // counts changes of `views`
  bool solving = false;                   // a solve is running (for the newest views or an older set)
  std::string solve_error;                // why the newest views could not be solved ("" when they were)
  bool current() const { return solution && solved_revision == revision && !solving; }
};

class CalibrationSession {
 public:
  explicit CalibrationSession(BoardSpec board = {}, SelectOptions select = {}, SolveOptions solve = {});
  ~CalibrationSession();   // waits for a solve in flight
  CalibrationSession(const CalibrationSession&) = delete;
  CalibrationSession& operator=(const CalibrationSession&) = delete;

  // Another board starts afresh (its views would not fit the old one's).
  void set_board(const BoardSpec& board);
  const BoardSpec& board() const { return board_; }
  void set_capture(bool on);
  // Frames that do not follow each other (a folder of stills): their stillness cannot be measured.
  void set_stills(bool stills);
  // Forgets the views, the tallies and the solution.
  void reset();
  // Drops the kept view named `name` and solves again; false when there is none of that name.
  bool drop_view(const std::string& name);

  // One new frame (8-bit BGR or grey), named for messages ("frame 120", "img_004.png"): the board is looked for
  // and, while capturing, the frame judged and perhaps kept. A frame of another size than the views starts
  // afresh (one calibration is of one camera at one size). A search begun by offer() is finished and judged
  // first, so that frames are judged in the order they came.
  void feed(const cv::Mat& frame, const std::string& name);
  // The same for a live source: the board is searched for on a thread of its own when it is idle (the frame is
  // skipped otherwise, and false returned); poll() judges the frame when the search is done.
  bool offer(const cv::Mat& frame, const std::string& name);
  // Takes a finished solve and starts the next one when the views changed; true when the state changed.
  bool poll();
  // The state now; the same pointer until something changes.
  std::shared_ptr<const CalibrationSnapshot> snapshot();
  // Waits until the current views are solved (or their solve failed), up to timeout_s; for tests and scripts.
  bool wait_solved(double timeout_s);

 private:
  void changed() { snap_.reset(); }
  void start_solve();
  void rebuild_selector();
  void update_coverage();
  void judge(const BoardDetection& d, const cv::Mat& frame, const std::string& name);

  BoardSpec board_;
  SelectOptions select_;
  SolveOptions solve_opt_;
  ViewSelector selector_;
  CalibrationSnapshot state_;   // everything but the cached pointer
  std::shared_ptr<const CalibrationSnapshot> snap_;
  std::future<Result<Solution>> running_;
  int running_revision_ = -1;
  std::future<BoardDetection> finding_;   // the board search in flight
  cv::Mat finding_image_;                 // the frame being searched (the search's own copy)
  std::string finding_name_;
  int finding_base_ = 0;
  int base_revision_ = 0;        // solves of views older than this (before a reset) are thrown away
};

}  // namespace arwb
