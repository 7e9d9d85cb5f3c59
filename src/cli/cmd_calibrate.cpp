// arwb calibrate: the paper's first module. A video or a folder of images of a chessboard (or a ChArUco board)
// becomes a calibration file (camera_matrix, distortion_coefficients and the paper's cameraMatrix, distCoeffs) with a quality report.
#include "calibration/board.hpp"
#include "calibration/calibration_file.hpp"
#include "calibration/solve.hpp"
#include "capture/image_io.hpp"
#include "capture/library_output.hpp"
#include "capture/source.hpp"
#include "capture/video_reader.hpp"
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace arwb {
namespace {

constexpr const char* kCommand = "arwb calibrate";

// The frames of a video or of a folder's images, one at a time.
class Frames {
 public:
  virtual ~Frames() = default;
  // The next frame into *out and its name ("frame 12", "img_004.png"); false at the end. A frame that cannot be
  // read is reported once in *problem.
  virtual bool next(cv::Mat* out, std::string* name, std::string* problem) = 0;
  virtual int64_t count() const = 0;   // 0 when unknown
};

class VideoFrames : public Frames {
 public:
  VideoFrames(VideoReader r, cv::Mat first) : reader_(std::move(r)), first_(std::move(first)) {}
  bool next(cv::Mat* out, std::string* name, std::string* problem) override {
    const int64_t index = index_++;
    *name = "frame " + std::to_string(index);
    if (!first_.empty()) {
      *out = std::move(first_);
      first_ = cv::Mat();
      return true;
    }
    const VideoReader::Read r = reader_.read(out);
    if (r == VideoReader::Read::damaged) *problem = reader_.error();
    return r == VideoReader::Read::frame;
  }
  int64_t count() const override { return reader_.frame_count(); }

 private:
  VideoReader reader_;
  cv::Mat first_;
  int64_t index_ = 0;
};

class FolderFrames : public Frames {
 public:
  explicit FolderFrames(std::vector<std::string> files) : files_(std::move(files)) {}
  bool next(cv::Mat* out, std::string* name, std::string* problem) override {
    while (next_ < files_.size()) {
      const std::string& f = files_[next_++];
      LoadedImage img = load_image(f);
      if (!img.ok()) {   // a damaged image is named and skipped: the others may still calibrate
        print_problem("%s: %s (skipped)\n", kCommand, img.error.c_str());
        continue;
      }
      *name = std::filesystem::path(f).filename().string();
      *out = std::move(img.image);
      return true;
    }
    (void)problem;
    return false;
  }
  int64_t count() const override { return int64_t(files_.size()); }

 private:
  std::vector<std::string> files_;
  size_t next_ = 0;
};

// A camera's frames until the time given runs out, enough views are kept, or the user presses Ctrl+C: then the
// views kept so far are solved, so stopping early loses nothing.
volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_interrupt(int) { g_stop = 1; }

class CameraFrames : public Frames {
 public:
  CameraFrames(std::unique_ptr<FrameSource> source, double seconds)
      : source_(std::move(source)),
        until_(std::chrono::steady_clock::now() +
               std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds))) {
    g_stop = 0;
    previous_ = std::signal(SIGINT, on_interrupt);
  }
  ~CameraFrames() override { std::signal(SIGINT, previous_); }
  bool next(cv::Mat* out, std::string* name, std::string* problem) override {
    if (g_stop || std::chrono::steady_clock::now() >= until_) return false;
    const SourceStatus st = source_->next(0, *out);
    if (st.status != FrameStatus::ok) {   // a camera that stops giving frames ends the input; what was kept is solved
      *problem = st.message.empty() ? source_->info().name + ": no frame" : st.message;
      return false;
    }
    *name = "frame " + std::to_string(index_++);
    return true;
  }
  int64_t count() const override { return 0; }
  bool interrupted() const { return g_stop != 0; }

 private:
  std::unique_ptr<FrameSource> source_;
  std::chrono::steady_clock::time_point until_;
  void (*previous_)(int) = SIG_DFL;
  int64_t index_ = 0;
};

// A board's size said the way the user gave theirs (9x6 rather than 6x9, when they gave more columns than rows).
cv::Size as_given(cv::Size found, const BoardSpec& given) {
  const int hi = std::max(found.width, found.height), lo = std::min(found.width, found.height);
  return given.cols >= given.rows ? cv::Size(hi, lo) : cv::Size(lo, hi);
}

// When no board of the size given is in any frame, a board of another size often is: rows and columns
// swapped, squares counted instead of inner corners, one line miscounted, the paper's 9x6, other common sizes.
// Looked for, at their exact sizes, in a few frames kept for this.
std::string other_board_hint(const std::vector<std::pair<std::string, cv::Mat>>& samples, const BoardSpec& given) {
  const int c = given.cols, r = given.rows;
  std::vector<cv::Size> sizes{{c - 1, r - 1}, {c + 1, r + 1}, {c - 1, r}, {c, r - 1}, {c + 1, r}, {c, r + 1},
                               {c - 2, r - 2}, {9, 6}, {8, 6}, {7, 6}, {7, 5}, {10, 7}, {11, 8}, {8, 5}, {6, 4}, {5, 4}};
  for (const auto& [name, grey] : samples) {
    const std::optional<cv::Size> found = find_any_chessboard(grey, sizes);   // the largest there
    if (!found) continue;
    const cv::Size size = as_given(*found, given);
    return "; a " + std::to_string(size.width) + "x" + std::to_string(size.height) + " chessboard is in " + name +
           ": give --cols " + std::to_string(size.width) + " --rows " + std::to_string(size.height);
  }
  return "; count the inner corners, where four squares meet (the paper's board has 9x6)";
}

// Whether a file can be made in `dir` ("" the working folder), tried with an empty file removed at once: asked
// before the input is read, so that a folder that cannot be written is said before a long video or a camera
// session, not after. The reason, as the system gives it, in *why.
bool can_write_in(const std::string& dir, std::string* why) {
  const std::filesystem::path probe =
      std::filesystem::path(dir.empty() ? "." : dir) / (".arwb-calibrate-probe-" + std::to_string(::getpid()));
  FILE* f = std::fopen(probe.c_str(), "wx");
  if (!f) {
    *why = std::strerror(errno);
    return false;
  }
  std::fclose(f);
  std::remove(probe.c_str());
  return true;
}

std::string tally_text(const std::map<std::string, int>& tally) {
  std::string t;
  for (const auto& [kind, n] : tally) {
    if (kind == "kept") continue;
    t += (t.empty() ? "" : ", ") + std::to_string(n) + " " + kind;
  }
  return t.empty() ? "none refused" : "not kept: " + t;
}

// What the command line asked for.
struct CalibrateArgs {
  std::string input, out, paper_dir;
  BoardOptions board_options;
  int max_views = 40;
  bool json = false;
  double seconds = 120;
};

// The options, declared on `app` for `a` to receive.
void declare_options(CLI::App& app, CalibrateArgs& a) {
  app.add_option("--input", a.input,
                 "a video, a folder of images of the board, or a camera (camera:N or camera:N@WxH: frames are read "
                 "until --max-views views are kept, --seconds pass, or Ctrl+C, and the views kept are solved)")
      ->type_name("VIDEO|DIR|camera:N[@WxH]")->required();
  app.add_option("--seconds", a.seconds, "a camera: read it this long at most (120)")->type_name("S")
      ->check(CLI::Range(1.0, 3600.0));
  add_board_options(app, a.board_options);
  app.add_option("--out", a.out, "the calibration file to write")->type_name("FILE.xml|FILE.yml")->required();
  app.add_option("--paper-files", a.paper_dir, "also write the paper's cameraMatrix.xml and distCoeffs.xml here")
      ->type_name("DIR");
  app.add_option("--max-views", a.max_views, "views kept at most")->type_name("N")->check(whole_number(6, 500));
  app.add_flag("--json", a.json, "print the result and the quality report as one JSON object");
}

// What can be refused before a long input is read, is: --out's name, and both folders there and writable. The
// exit status after saying why, or nullopt.
std::optional<int> check_outputs(const CommandLine& cl, const CalibrateArgs& a) {
  const std::string ext = std::filesystem::path(a.out).extension().string();
  if (ext != ".xml" && ext != ".yml" && ext != ".yaml")
    return cl.usage_error("--out " + a.out + ": the file name must end in .xml, .yml or .yaml");
  std::error_code ec;
  const std::filesystem::path out_dir = std::filesystem::path(a.out).parent_path();
  if (!out_dir.empty() && !std::filesystem::is_directory(out_dir, ec)) {
    print_problem("%s: %s: cannot write (no such folder %s)\n", kCommand, a.out.c_str(), out_dir.c_str());
    return 1;
  }
  if (!a.paper_dir.empty() && !std::filesystem::is_directory(a.paper_dir, ec)) {
    print_problem("%s: --paper-files %s: no such folder\n", kCommand, a.paper_dir.c_str());
    return 1;
  }
  std::string why;
  if (!can_write_in(out_dir.string(), &why)) {
    print_problem("%s: %s: cannot write in %s (%s)\n", kCommand, a.out.c_str(),
                  out_dir.empty() ? "the working folder" : out_dir.c_str(), why.c_str());
    return 1;
  }
  if (!a.paper_dir.empty() && !can_write_in(a.paper_dir, &why)) {
    print_problem("%s: --paper-files %s: cannot write there (%s)\n", kCommand, a.paper_dir.c_str(), why.c_str());
    return 1;
  }
  return std::nullopt;
}

// The input's frames: a camera's (`camera`, when --input names one), a folder's images or a video's; null after
// saying why there are none. Stills are not judged by motion (select->video).
std::unique_ptr<Frames> open_frames(const CalibrateArgs& a, const std::optional<SourceSpec>& camera,
                                    SelectOptions* select) {
  if (camera) {
    std::string error;
    std::unique_ptr<FrameSource> source = open_capture_source(*camera, &error);
    if (!source) {
      print_problem("%s: %s\n", kCommand, error.c_str());
      return nullptr;
    }
    auto frames = std::make_unique<CameraFrames>(std::move(source), a.seconds);
    std::fprintf(stderr, "%s: reading %s for up to %.0f s; show the board still, in many places and tilts; Ctrl+C "
                 "stops and solves with the views kept\n", kCommand, a.input.c_str(), a.seconds);
    return frames;
  }
  switch (classify_path(a.input)) {
    case PathKind::folder: {
      std::string error;
      std::vector<std::string> skipped;
      std::vector<std::string> files = list_images(a.input, &skipped, &error);
      if (!error.empty()) {
        print_problem("%s: %s\n", kCommand, error.c_str());
        return nullptr;
      }
      if (files.empty()) {
        print_problem("%s: %s: no images in the folder\n", kCommand, a.input.c_str());
        return nullptr;
      }
      select->video = false;   // stills: no motion to measure between them
      return std::make_unique<FolderFrames>(std::move(files));
    }
    case PathKind::video: {
      cv::Mat first;
      Result<VideoReader> r = VideoReader::open(a.input, &first);
      if (!r) {
        print_problem("%s: %s\n", kCommand, r.error().c_str());
        return nullptr;
      }
      return std::make_unique<VideoFrames>(std::move(*r), std::move(first));
    }
    case PathKind::missing: print_problem("%s: %s: no such file or folder\n", kCommand, a.input.c_str()); break;
    case PathKind::image:
      print_problem("%s: %s: one image cannot calibrate; give a video or a folder of images\n", kCommand,
                    a.input.c_str());
      break;
    case PathKind::other:
      print_problem("%s: %s: neither a video nor a folder of images\n", kCommand, a.input.c_str());
      break;
  }
  return nullptr;
}

// What reading the input gave: the views kept, why the others were not, a few frames for the wrong-size hint.
struct Reading {
  std::vector<CalibrationView> views;
  std::map<std::string, int> tally;
  std::vector<std::pair<std::string, cv::Mat>> samples;
  cv::Size size;
  int read = 0, boards = 0;
  std::string problem;   // a frame that could not be read, reported once
};

// Every frame searched for the board and judged by the selector, with a progress line on a terminal; the exit
// status after saying why the input cannot calibrate (frames of two sizes, a larger chessboard than given), or
// nullopt. A camera stops once max_views views are kept.
std::optional<int> read_views(Frames& frames, const BoardSpec& board, const SelectOptions& select, bool camera,
                              Reading& r) {
  ViewSelector selector(board, select);
  std::string first_name, name;
  const int64_t total = frames.count();
  const bool progress = ::isatty(2) && (total == 0 || total > 30);
  cv::Mat frame, grey;
  while (frames.next(&frame, &name, &r.problem)) {
    ++r.read;
    if (r.size.area() == 0) {
      r.size = frame.size();
      first_name = name;
    } else if (frame.size() != r.size) {
      if (progress) std::fputc('\n', stderr);
      print_problem("%s: %s: %dx%d, but %s is %dx%d; calibrate one camera at one size\n", kCommand, name.c_str(),
                    frame.cols, frame.rows, first_name.c_str(), r.size.width, r.size.height);
      return 1;
    }
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    const BoardDetection d = detect_board(grey, board);
    if (d.found && r.boards == 0 && board.kind == BoardKind::chessboard) {
      if (std::optional<cv::Size> larger = larger_board(grey, board, d.corners)) {
        *larger = as_given(*larger, board);
        if (progress) std::fputc('\n', stderr);
        print_problem("%s: %s: the chessboard has more inner corners than %dx%d (%dx%d): give --cols %d --rows %d\n",
                      kCommand, name.c_str(), board.cols, board.rows, larger->width, larger->height, larger->width,
                      larger->height);
        return 1;
      }
    }
    r.boards += d.found;
    const Verdict v = selector.consider(d, r.size);
    ++r.tally[v.kind];
    if (v.keep) r.views.push_back({name, d.corners, d.ids});
    if (camera && int(r.views.size()) >= select.max_views) break;
    if (r.samples.size() < 3 && (r.read - 1) % 10 == 0) r.samples.emplace_back(name, grey.clone());
    if (progress && r.read % 5 == 0) {
      std::fprintf(stderr, "\r%s: %d", kCommand, r.read);
      if (total > 0) std::fprintf(stderr, "/%lld", static_cast<long long>(total));
      std::fprintf(stderr, " frames, board in %d, %zu views kept (this frame: %s)   ", r.boards, r.views.size(),
                   v.kind.c_str());
    }
  }
  if (progress) std::fputc('\n', stderr);
  return std::nullopt;
}

}  // namespace

int cmd_calibrate(int argc, char** argv) {
  CommandLine cl(kCommand,
                 "Calibrates a camera from a video or a folder of images of a chessboard (the paper's: 9x6 inner "
                 "corners, 25 mm squares) or of a ChArUco board (--board charuco: cols and rows count squares, as "
                 "OpenCV's CharucoBoard; OpenCV 4.6's layout, so boards printed for the older layout, before 4.6, "
                 "which differs for an even number of rows, are not read; a view may show part of it). Views are "
                 "chosen by themselves: the board still and sharp, its pose unlike "
                 "the views already kept, its corners away from the image's edge. Solves with OpenCV, drops outlier "
                 "views, fixes what the views cannot determine, and writes OpenCV FileStorage with the paper's names.",
                 "The report checks the four criteria of OpenCV's interactive calibration (enough views, RMS error, "
                 "95 % intervals of fx, fy, cx, cy under 5 %, image coverage) and shows ROS's X, Y, size and skew "
                 "coverage and the views worst first. Exit status 0 when a file was written, 1 when the input could "
                 "not calibrate, 2 for a bad option.");
  CalibrateArgs a;
  declare_options(cl.app, a);
  if (const auto status = cl.parse(argc, argv)) return *status;

  std::string board_problem;
  const std::optional<BoardSpec> board_given = board_from_options(a.board_options, &board_problem);
  if (!board_given) return cl.usage_error(board_problem);
  const BoardSpec board = *board_given;
  std::optional<SourceSpec> camera;
  if (a.input.rfind("camera:", 0) == 0) {
    std::string error;
    camera.emplace();
    if (!parse_source_spec(a.input, &*camera, &error)) return cl.usage_error("--input " + error);
  }
  if (const auto status = check_outputs(cl, a)) return *status;

  keep_opencv_quiet();
  SelectOptions select;
  select.max_views = a.max_views;
  const std::unique_ptr<Frames> frames = open_frames(a, camera, &select);
  if (!frames) return 1;
  Reading r;
  if (const auto status = read_views(*frames, board, select, camera.has_value(), r)) return *status;
  const auto* camera_frames = dynamic_cast<const CameraFrames*>(frames.get());
  if (camera_frames && camera_frames->interrupted())
    std::fprintf(stderr, "%s: stopped (Ctrl+C): solving with the %zu views kept\n", kCommand, r.views.size());
  if (!r.problem.empty()) print_problem("%s: %s\n", kCommand, r.problem.c_str());
  const std::string summary = std::to_string(r.read) + " frame" + (r.read == 1 ? "" : "s") + " read, board in " +
                              std::to_string(r.boards) + ", " + std::to_string(r.views.size()) +
                              (r.views.size() == 1 ? " view kept; " : " views kept; ") + tally_text(r.tally);
  if (r.boards == 0 && board.kind == BoardKind::charuco) {
    print_problem("%s: no %s in any of the %d frames of %s (at least %d corners, not on one line); check --cols, "
                  "--rows (squares) and --dict; boards printed for OpenCV's older ChArUco layout (before 4.6; it "
                  "differs for an even number of rows) are not read\n",
                  kCommand, board.describe().c_str(), r.read, a.input.c_str(), kMinCharucoCorners);
    return 1;
  }
  if (r.boards == 0) {
    print_problem("%s: no %dx%d chessboard in any of the %d frames of %s%s\n", kCommand, board.cols, board.rows,
                  r.read, a.input.c_str(), other_board_hint(r.samples, board).c_str());
    return 1;
  }
  const Result<Solution> s = solve_calibration(r.views, board, r.size);
  if (!s) {
    print_problem("%s: %s: %s (%s)\n", kCommand, a.input.c_str(), s.error().c_str(), summary.c_str());
    return 1;
  }
  CalibrationFileExtras x;
  x.avg_reprojection_error = s->rms;
  x.per_view_reprojection_errors = s->per_view_errors;
  x.std_intrinsics = s->std_intrinsics;
  x.std_distortion = s->std_distortion;
  x.board = board.describe();
  x.view_count = int(s->view_names.size());
  x.notes = s->notes;
  // The file and the paper's files together: all of them or none.
  if (Status st = write_calibration(a.out, s->calibration, x, a.paper_dir); !st) {
    print_problem("%s: %s\n", kCommand, st.error().c_str());
    return 1;
  }
  if (a.json) {
    nlohmann::json j = nlohmann::json::parse(solution_json(*s, board));
    j["input"] = a.input;
    j["out"] = a.out;
    j["frames_read"] = r.read;
    j["boards_found"] = r.boards;
    j["views_kept"] = r.views.size();
    j["not_kept"] = r.tally;
    j["not_kept"].erase("kept");
    std::puts(json_text(j).c_str());
  } else {
    std::printf("%s\n%s", summary.c_str(), solution_text(*s).c_str());
    std::printf("wrote %s%s%s\n", a.out.c_str(), a.paper_dir.empty() ? "" : " and the paper's files in ",
                a.paper_dir.c_str());
  }
  return 0;
}

}  // namespace arwb
