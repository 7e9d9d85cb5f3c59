// arwb: the ArUco Workbench binary, the top of the house: it links the command-line tools (src/cli) and the
// window (ui/). `arwb [options]` opens the workbench window; `arwb <subcommand> ...` runs a
// command-line tool. See `arwb --help`.
#include "cli/commands.hpp"
#include "ui/window.hpp"
#include "cli/opencv_limits.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string_view>

#include <unistd.h>

namespace {

struct Subcommand {
  const char* name;
  int (*run)(int, char**);
  const char* summary;
};

constexpr Subcommand kSubcommands[] = {
    {"detect", arwb::cmd_detect, "detect markers in images, folders or videos (--json: one line per frame)"},
    {"markers", arwb::cmd_markers, "write marker PNGs, or a printable PDF/SVG sheet at true size"},
    {"synth", arwb::cmd_synth, "make synthetic photographs of markers with a truth.jsonl"},
    {"bench", arwb::cmd_bench, "compare arwb with OpenCV aruco and AprilTag on a synthetic set"},
    {"make-media", arwb::cmd_make_media, "paint the example scenes' pictures and clip (no downloads)"},
    {"render", arwb::cmd_render, "composite a scene's media onto a video, images or the synthetic source (no display)"},
};

void usage(std::FILE* to) {
  std::fprintf(to,
               "usage: arwb [--source synthetic|camera:N|PATH] [--frames N] [--screenshot FILE.png] [--stats] ...\n"
               "       arwb <subcommand> [options]\n\n"
               "Without a subcommand, arwb opens the workbench window (options below).\n\n"
               "subcommands:\n");
  for (const auto& s : kSubcommands) std::fprintf(to, "  %-10s %s\n", s.name, s.summary);
  std::fprintf(to, "\n`arwb <subcommand> --help` describes each one.\n");
}

}  // namespace

int main(int argc, char** argv) {
  // FFmpeg's own log lines ("moov atom not found") would duplicate arwb's one-line messages; a user can
  // still ask for them by setting the variable.
  setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
  // OpenCV reads its image limits while its library loads, before main(): when they had to be set, start again
  // with them (once; exec only returns on failure, and then OpenCV's own defaults stay).
  if (arwb::set_opencv_image_limits()) execv("/proc/self/exe", argv);
  if (argc >= 2 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    usage(stdout);
    std::printf("\nthe workbench:\n");
    char help[] = "--help";
    char* args[] = {help};
    return arwb::cmd_workbench(1, args, arwb::run_workbench);
  }
  // No subcommand, or options first: the workbench.
  if (argc < 2 || argv[1][0] == '-') {
    try {
      return arwb::cmd_workbench(argc - 1, argv + 1, arwb::run_workbench);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "arwb: %s\n", e.what());
      return 1;
    }
  }
  std::string_view name = argv[1];
  for (const auto& s : kSubcommands) {
    if (name == s.name) {
      try {
        return s.run(argc - 2, argv + 2);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "arwb %s: %s\n", s.name, e.what());
        return 1;
      }
    }
  }
  std::fprintf(stderr, "arwb: unknown subcommand '%s'\n", argv[1]);
  usage(stderr);
  return 2;
}
