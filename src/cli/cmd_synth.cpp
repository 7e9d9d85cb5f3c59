// arwb synth: synthetic photographs of markers with exact truth, for benchmarks, tests and teaching.
#include "calibration/calibration_file.hpp"
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "synth/chessboard_view.hpp"
#include "synth/synth_set.hpp"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

namespace arwb {

namespace {

// --chessboard: views of a calibration board (by default the paper's, 9x6 inner corners, 25 mm; or a ChArUco
// board, a quarter of its views held partly out of the image) through a known camera with barrel distortion, for
// arwb calibrate; the camera itself goes beside them as a calibration file to compare with.
int write_chessboard_views(const std::string& out, int count, int seed, const BoardSpec& spec, cv::Size size) {
  const SynthCamera camera = SynthCamera{}.resized(size);
  const SynthChessboard board = SynthChessboard::of(spec);
  const ChessboardRenderer renderer(camera, board);
  const int partial = spec.kind == BoardKind::charuco ? count / 4 : 0;
  auto poses = chessboard_poses(camera, board, count - partial, unsigned(seed));
  const auto more = partial_board_poses(camera, board, partial, unsigned(seed) + 1);
  poses.insert(poses.end(), more.begin(), more.end());
  for (size_t i = 0; i < poses.size(); ++i) {
    const ChessboardView v = renderer.render(poses[i].first, poses[i].second, 0.6, 1.5, unsigned(i + 1));
    char name[32];
    std::snprintf(name, sizeof name, "/board_%03zu.png", i);
    if (!cv::imwrite(out + name, v.image)) {
      print_problem("arwb synth: %s%s: cannot write\n", out.c_str(), name);
      return 1;
    }
  }
  Calibration truth;
  truth.camera_matrix = camera.camera_matrix;
  truth.distortion = camera.distortion;
  truth.image_size = camera.size;
  CalibrationFileExtras x;
  x.board = spec.describe();
  x.view_count = int(poses.size());
  x.notes = {"the synthetic camera the views were rendered through (the truth)"};
  if (Status st = write_calibration(out + "/truth_camera.yml", truth, x); !st) {
    print_problem("arwb synth: %s\n", st.error().c_str());
    return 1;
  }
  std::printf("wrote %zu views of the %s and truth_camera.yml to %s\n", poses.size(), spec.describe().c_str(),
              out.c_str());
  return 0;
}

}  // namespace

int cmd_synth(int argc, char** argv) {
  CommandLine cl("arwb synth",
                 "Writes N synthetic photographs (PNG) and DIR/truth.jsonl: per image its file, size and markers (id, "
                 "dict, corners: outer black corners, top-left first, clockwise; pixel centres at integers). Images "
                 "mix perspective, scales from tiny to large, in-plane rotation, blur, noise, light gradients and "
                 "shadows, JPEG, clutter that looks like markers, and some images with no marker. The same seed gives "
                 "the same set.");
  std::string out, dict_arg = "ARUCO_ORIGINAL", size_arg = "mixed";
  int count = 30, seed = 1;
  cl.app.add_option("--out", out, "the folder to write (created if needed)")
      ->type_name("DIR")
      ->required()
      ->check(out_kinds({}, true));
  cl.app.add_option("--count", count, "images")->type_name("N")->check(whole_number(1, 100000));
  cl.app.add_option("--seed", seed, "the random seed")->type_name("S")->check(whole_number(0, 2147483647));
  bool chessboard = false;
  cl.app.add_flag("--chessboard", chessboard,
                  "instead: views of a calibration board (the paper's 9x6 chessboard unless --board and its options "
                  "say otherwise) through a known camera with lens distortion (640x480, or --size), and that camera as "
                  "DIR/truth_camera.yml, for arwb calibrate");
  // The board's options are calibrate's; --dict is shared: the markers' dictionaries, or a ChArUco board's.
  BoardOptions board_options;
  add_board_options(cl.app, board_options);
  cl.app.get_option("--dict")
      ->description("dictionaries, as for arwb detect (ARUCO_ORIGINAL); with --chessboard --board charuco, the "
                    "ChArUco board's (DICT_5X5_100)")
      ->type_name("NAME[,NAME...]");
  cl.app.add_option("--size", size_arg, "WxH, or mixed: the set's sizes in turn (640x480, 1280x720 and 1920x1080, and 3840x2160 in a hard set)")
      ->type_name("WxH|mixed")
      ->check(frame_size({64, 64}, {8192, 8192}, "mixed"));
  std::string set_arg = "standard";
  cl.app.add_option("--set", set_arg,
                    "standard: the photographs above; hard: what detectors miss, each image one of low_contrast "
                    "(large markers grey on grey, a soft shadow edge and a steep light gradient across them), tiny "
                    "(markers of 10 to 24 px), low_light (strong sensor noise and blur) and crossed (thin lines "
                    "across markers' borders, a large marker half in a shadow band), at 640x480 up to 3840x2160 "
                    "unless --size says otherwise")
      ->type_name("standard|hard")
      ->check(CLI::IsMember({"standard", "hard"}));
  if (const auto status = cl.parse(argc, argv)) return *status;
  if (chessboard && cl.app.count("--set")) return cl.usage_error("--set is for marker photographs, not --chessboard");
  const SetKind kind = set_arg == "hard" ? SetKind::hard : SetKind::standard;
  if (!board_options.dict.empty() && !chessboard) dict_arg = board_options.dict;
  std::optional<BoardSpec> board;
  if (chessboard) {
    std::string problem;
    board = board_from_options(board_options, &problem);
    if (!board) return cl.usage_error(problem);
  } else if (!board_options.kind.empty() || board_options.cols || board_options.rows || board_options.square_mm != 0 ||
             board_options.marker_mm != 0) {
    return cl.usage_error("--board, --cols, --rows, --square-mm and --marker-mm are for --chessboard");
  }
  std::vector<cv::Size> sizes = kind == SetKind::hard ? hard_sizes() : mixed_sizes();
  if (size_arg != "mixed") sizes = {*parse_frame_size(size_arg)};
  const auto dicts = dictionaries_option(dict_arg, "arwb synth");
  if (!dicts) return 2;
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (chessboard) {
    if (ec) {
      print_problem("arwb synth: %s: cannot create the folder\n", out.c_str());
      return 1;
    }
    // One size for a calibration: the default camera's, 640x480, unless --size gives another.
    return write_chessboard_views(out, count, seed, *board, size_arg == "mixed" ? SynthCamera{}.size : sizes[0]);
  }
  std::ofstream truth(out + "/truth.jsonl");
  if (ec || !truth) {
    print_problem("arwb synth: %s: cannot create the folder or its truth.jsonl\n", out.c_str());
    return 1;
  }
  int markers = 0;
  for (int i = 0; i < count; ++i) {
    const SetItem item = make_set_item(*dicts, sizes, uint64_t(seed), i, kind);
    if (!cv::imwrite(out + "/" + item.file, item.image)) {
      print_problem("arwb synth: %s/%s: cannot write\n", out.c_str(), item.file.c_str());
      return 1;
    }
    truth << truth_line(item) << "\n";
    markers += int(item.truth.size());
  }
  truth.close();
  std::printf("wrote %d images with %d markers and truth.jsonl to %s\n", count, markers, out.c_str());
  return 0;
}

}  // namespace arwb
