// arwb synth: synthetic photographs of markers with exact truth, for benchmarks, tests and teaching.
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "synth/synth_set.hpp"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace arwb {
namespace {
constexpr const char* kUsage =
    "usage: arwb synth --out DIR [--count N] [--seed S] [--dict NAME[,NAME...]] [--size WxH|mixed]\n"
    "\n"
    "Writes N synthetic photographs (PNG) and DIR/truth.jsonl: per image its file, size and markers (id, dict,\n"
    "corners: outer black corners, top-left first, clockwise; pixel centres at integers). Images mix\n"
    "perspective, scales from tiny to large, in-plane rotation, blur, noise, light gradients and shadows, JPEG,\n"
    "clutter that looks like markers, and some images with no marker. The same seed gives the same set.\n"
    "  --count  images (default 30)     --seed  (default 1)     --dict  (default ARUCO_ORIGINAL)\n"
    "  --size   WxH, or mixed: 640x480, 1280x720 and 1920x1080 in turn (default mixed)\n";
}  // namespace

int cmd_synth(int argc, char** argv) {
  Args args(argc, argv);
  if (args.flag("--help") || args.flag("-h")) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  const std::string out = args.value("--out", "");
  const int count = args.int_value("--count", 30, 1, 100000);
  const int seed = args.int_value("--seed", 1, 0, 2147483647);
  const std::string dict_arg = args.value("--dict", "ARUCO_ORIGINAL");
  const std::string size_arg = args.value("--size", "mixed");
  if (!args.ok() || !args.no_positional()) return args.fail("arwb synth");
  if (out.empty()) {
    std::fprintf(stderr, "arwb synth: --out DIR is required (see arwb synth --help)\n");
    return 2;
  }
  std::vector<cv::Size> sizes = mixed_sizes();
  if (size_arg != "mixed") {
    int w = 0, h = 0;
    char tail = 0;
    if (std::sscanf(size_arg.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 64 || h < 64 || w > 8192 || h > 8192) {
      std::fprintf(stderr, "arwb synth: --size %s: expected WxH between 64x64 and 8192x8192, or mixed\n",
                   size_arg.c_str());
      return 2;
    }
    sizes = {cv::Size(w, h)};
  }
  const auto dicts = dictionaries_option(dict_arg, "arwb synth");
  if (!dicts) return 2;
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  std::ofstream truth(out + "/truth.jsonl");
  if (ec || !truth) {
    std::fprintf(stderr, "arwb synth: %s: cannot create the folder or its truth.jsonl\n", out.c_str());
    return 1;
  }
  int markers = 0;
  for (int i = 0; i < count; ++i) {
    const SetItem item = make_set_item(*dicts, sizes, uint64_t(seed), i);
    if (!cv::imwrite(out + "/" + item.file, item.image)) {
      std::fprintf(stderr, "arwb synth: %s/%s: cannot write\n", out.c_str(), item.file.c_str());
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
