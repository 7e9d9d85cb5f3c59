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
  std::string input, out, paper_dir;
  BoardOptions board_options;
  int max_views = 40;
  bool json = false;
  double seconds = 120;
  cl.app.add_option("--input", input,
                    "a video, a folder of images of the board, or a camera (camera:N or camera:N@WxH: frames are read "
                    "until --max-views views are kept, --seconds pass, or Ctrl+C, and the views kept are solved)")
      ->type_name("VIDEO|DIR|camera:N[@WxH]")->required();
  cl.app.add_option("--seconds", seconds, "a camera: read it this long at most (120)")->type_name("S")
      ->check(CLI::Range(1.0, 3600.0));
  add_board_options(cl.app, board_options);
  cl.app.add_option("--out", out, "the calibration file to write")->type_name("FILE.xml|FILE.yml")->required();
  cl.app.add_option("--paper-files", paper_dir, "also write the paper's cameraMatrix.xml and distCoeffs.xml here")
      ->type_name("DIR");
  cl.app.add_option("--max-views", max_views, "views kept at most")->type_name("N")->check(whole_number(6, 500));
  cl.app.add_flag("--json", json, "print the result and the quality report as one JSON object");
  if (const auto status = cl.parse(argc, argv)) return *status;

  std::string board_problem;
  const std::optional<BoardSpec> board_given = board_from_options(board_options, &board_problem);
  if (!board_given) return cl.usage_error(board_problem);
  const BoardSpec board = *board_given;
  SourceSpec camera;
  const bool is_camera = input.rfind("camera:", 0) == 0;
  if (is_camera) {
    std::string error;
    if (!parse_source_spec(input, &camera, &error)) return cl.usage_error("--input " + error);
  }
  // What can be refused before a long input is read, is.
  const std::string ext = std::filesystem::path(out).extension().string();
  if (ext != ".xml" && ext != ".yml" && ext != ".yaml")
    return cl.usage_error("--out " + out + ": the file name must end in .xml, .yml or .yaml");
  std::error_code ec;
  const std::filesystem::path out_dir = std::filesystem::path(out).parent_path();
  if (!out_dir.empty() && !std::filesystem::is_directory(out_dir, ec)) {
    print_problem("%s: %s: cannot write (no such folder %s)\n", kCommand, out.c_str(), out_dir.c_str());
    return 1;
  }
  if (!paper_dir.empty() && !std::filesystem::is_directory(paper_dir, ec)) {
    print_problem("%s: --paper-files %s: no such folder\n", kCommand, paper_dir.c_str());
    return 1;
  }
  std::string why;
  if (!can_write_in(out_dir.string(), &why)) {
    print_problem("%s: %s: cannot write in %s (%s)\n", kCommand, out.c_str(),
                  out_dir.empty() ? "the working folder" : out_dir.c_str(), why.c_str());
    return 1;
  }
  if (!paper_dir.empty() && !can_write_in(paper_dir, &why)) {
    print_problem("%s: --paper-files %s: cannot write there (%s)\n", kCommand, paper_dir.c_str(), why.c_str());
    return 1;
  }

  keep_opencv_quiet();
  std::unique_ptr<Frames> frames;
  SelectOptions select;
  select.max_views = max_views;
  CameraFrames* camera_frames = nullptr;
  if (is_camera) {
    std::string error;
    std::unique_ptr<FrameSource> source = open_capture_source(camera, &error);
    if (!source) {
      print_problem("%s: %s\n", kCommand, error.c_str());
      return 1;
    }
    auto f = std::make_unique<CameraFrames>(std::move(source), seconds);
    camera_frames = f.get();
    frames = std::move(f);
    std::fprintf(stderr, "%s: reading %s for up to %.0f s; show the board still, in many places and tilts; Ctrl+C "
                 "stops and solves with the views kept\n", kCommand, input.c_str(), seconds);
  } else switch (classify_path(input)) {
    case PathKind::folder: {
      std::string error;
      std::vector<std::string> skipped;
      std::vector<std::string> files = list_images(input, &skipped, &error);
      if (!error.empty()) {
        print_problem("%s: %s\n", kCommand, error.c_str());
        return 1;
      }
      if (files.empty()) {
        print_problem("%s: %s: no images in the folder\n", kCommand, input.c_str());
        return 1;
      }
      frames = std::make_unique<FolderFrames>(std::move(files));
      select.video = false;   // stills: no motion to measure between them
      break;
    }
    case PathKind::video: {
      cv::Mat first;
      Result<VideoReader> r = VideoReader::open(input, &first);
      if (!r) {
        print_problem("%s: %s\n", kCommand, r.error().c_str());
        return 1;
      }
      frames = std::make_unique<VideoFrames>(std::move(*r), std::move(first));
      break;
    }
    case PathKind::missing: print_problem("%s: %s: no such file or folder\n", kCommand, input.c_str()); return 1;
    case PathKind::image:
      print_problem("%s: %s: one image cannot calibrate; give a video or a folder of images\n", kCommand,
                    input.c_str());
      return 1;
    case PathKind::other:
      print_problem("%s: %s: neither a video nor a folder of images\n", kCommand, input.c_str());
      return 1;
  }

  ViewSelector selector(board, select);
  std::vector<CalibrationView> views;
  std::map<std::string, int> tally;
  std::vector<std::pair<std::string, cv::Mat>> samples;   // a few frames for the wrong-size hint
  cv::Size size;
  std::string first_name, name, problem;
  int read = 0, boards = 0;
  const int64_t total = frames->count();
  const bool progress = ::isatty(2) && (total == 0 || total > 30);
  cv::Mat frame, grey;
  while (frames->next(&frame, &name, &problem)) {
    ++read;
    if (size.area() == 0) {
      size = frame.size();
      first_name = name;
    } else if (frame.size() != size) {
      if (progress) std::fputc('\n', stderr);
      print_problem("%s: %s: %dx%d, but %s is %dx%d; calibrate one camera at one size\n", kCommand, name.c_str(),
                    frame.cols, frame.rows, first_name.c_str(), size.width, size.height);
      return 1;
    }
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    const BoardDetection d = detect_board(grey, board);
    if (d.found && boards == 0 && board.kind == BoardKind::chessboard) {
      if (std::optional<cv::Size> larger = larger_board(grey, board, d.corners)) {
        *larger = as_given(*larger, board);
        if (progress) std::fputc('\n', stderr);
        print_problem("%s: %s: the chessboard has more inner corners than %dx%d (%dx%d): give --cols %d --rows %d\n",
                      kCommand, name.c_str(), board.cols, board.rows, larger->width, larger->height, larger->width,
                      larger->height);
        return 1;
      }
    }
    boards += d.found;
    const Verdict v = selector.consider(d, size);
    ++tally[v.kind];
    if (v.keep) views.push_back({name, d.corners, d.ids});
    if (camera_frames && int(views.size()) >= max_views) break;
    if (samples.size() < 3 && (read - 1) % 10 == 0) samples.emplace_back(name, grey.clone());
    if (progress && read % 5 == 0) {
      std::fprintf(stderr, "\r%s: %d", kCommand, read);
      if (total > 0) std::fprintf(stderr, "/%lld", static_cast<long long>(total));
      std::fprintf(stderr, " frames, board in %d, %zu views kept (this frame: %s)   ", boards, views.size(),
                   v.kind.c_str());
    }
  }
  if (progress) std::fputc('\n', stderr);
  if (camera_frames && camera_frames->interrupted())
    std::fprintf(stderr, "%s: stopped (Ctrl+C): solving with the %zu views kept\n", kCommand, views.size());
  if (!problem.empty()) print_problem("%s: %s\n", kCommand, problem.c_str());
  const std::string summary = std::to_string(read) + " frame" + (read == 1 ? "" : "s") + " read, board in " +
                              std::to_string(boards) + ", " + std::to_string(views.size()) +
                              (views.size() == 1 ? " view kept; " : " views kept; ") + tally_text(tally);
  if (boards == 0 && board.kind == BoardKind::charuco) {
    print_problem("%s: no %s in any of the %d frames of %s (at least %d corners, not on one line); check --cols, "
                  "--rows (squares) and --dict; boards printed for OpenCV's older ChArUco layout (before 4.6; it "
                  "differs for an even number of rows) are not read\n",
                  kCommand, board.describe().c_str(), read, input.c_str(), kMinCharucoCorners);
    return 1;
  }
  if (boards == 0) {
    print_problem("%s: no %dx%d chessboard in any of the %d frames of %s%s\n", kCommand, board.cols, board.rows, read,
                  input.c_str(), other_board_hint(samples, board).c_str());
    return 1;
  }
  const Result<Solution> s = solve_calibration(views, board, size);
  if (!s) {
    print_problem("%s: %s: %s (%s)\n", kCommand, input.c_str(), s.error().c_str(), summary.c_str());
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
  if (Status st = write_calibration(out, s->calibration, x, paper_dir); !st) {
    print_problem("%s: %s\n", kCommand, st.error().c_str());
    return 1;
  }
  if (json) {
    nlohmann::json j = nlohmann::json::parse(solution_json(*s, board));
    j["input"] = input;
    j["out"] = out;
    j["frames_read"] = read;
    j["boards_found"] = boards;
    j["views_kept"] = views.size();
    j["not_kept"] = tally;
    j["not_kept"].erase("kept");
    std::puts(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
  } else {
    std::printf("%s\n%s", summary.c_str(), solution_text(*s).c_str());
    std::printf("wrote %s%s%s\n", out.c_str(), paper_dir.empty() ? "" : " and the paper's files in ",
                paper_dir.c_str());
  }
  return 0;
}

}  // namespace arwb
