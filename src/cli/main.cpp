// arwb: the ArUco Workbench binary, the top of the house: it links the command-line tools (src/cli) and the
// window (ui/). `arwb [options]` opens the workbench window; `arwb <subcommand> ...` runs a
// command-line tool. See `arwb --help`.
#include "base/allocator.hpp"
#include "base/temp_dir.hpp"
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "cli/opencv_limits.hpp"
#include "capture/library_output.hpp"
#include "ui/message_window.hpp"
#include "ui/player.hpp"
#include "ui/window.hpp"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string_view>

#include <unistd.h>

int main(int argc, char** argv) {
  arwb::keep_freed_buffers();
  // FFmpeg's, OpenCV's and its error handler's own lines would duplicate arwb's one-line messages; a user can
  // still ask for them by setting OPENCV_FFMPEG_LOGLEVEL or OPENCV_LOG_LEVEL.
  arwb::keep_opencv_quiet();
  // OpenCV reads its image limits while its library loads, before main(): when they had to be set, start again
  // with them (once; exec only returns on failure, and then OpenCV's own defaults stay).
  if (arwb::set_opencv_image_limits()) execv("/proc/self/exe", argv);
  // A played bundle's copy and an unfinished export go with the process, however it is stopped.
  arwb::remove_temp_dirs_on_exit_and_signals();
  // No subcommand, or options first (--help among them): the workbench, whose help lists the subcommands.
  if (argc < 2 || argv[1][0] == '-') {
    try {
      return arwb::cmd_workbench(argc - 1, argv + 1, arwb::run_workbench);
    } catch (const std::exception& e) {
      arwb::print_problem("arwb: %s\n", e.what());
      return 1;
    }
  }
  const std::string_view name = argv[1];
  // The player is a window too: like the workbench, it gets ui's run function from here.
  if (name == "play") {
    try {
      return arwb::cmd_play(argc - 2, argv + 2, arwb::run_player, arwb::run_message_window);
    } catch (const std::exception& e) {
      arwb::print_problem("arwb play: %s\n", e.what());
      return 1;
    }
  }
  for (const auto& s : arwb::arwb_subcommands()) {
    if (name == s.name) {
      try {
        return s.run(argc - 2, argv + 2);
      } catch (const std::exception& e) {
        arwb::print_problem("arwb %s: %s\n", s.name, e.what());
        return 1;
      }
    }
  }
  arwb::print_problem("arwb: unknown subcommand '%s' (see arwb --help)\n", argv[1]);
  return 2;
}
