// The arwb subcommands. Each takes the arguments after its own name and returns the process exit status;
// each prints its help on --help and a one-line error naming the bad argument otherwise.
#pragma once

#include "workbench/options.hpp"

#include <span>

namespace arwb {

int cmd_detect(int argc, char** argv);
int cmd_markers(int argc, char** argv);
int cmd_synth(int argc, char** argv);
int cmd_bench(int argc, char** argv);
int cmd_render(int argc, char** argv);
int cmd_make_media(int argc, char** argv);
int cmd_calibrate(int argc, char** argv);
int cmd_lab(int argc, char** argv);
int cmd_export(int argc, char** argv);
int cmd_serve(int argc, char** argv);

// The table main dispatches on and `arwb --help` lists.
struct Subcommand {
  const char* name;
  int (*run)(int argc, char** argv);
  const char* summary;
};
std::span<const Subcommand> arwb_subcommands();

// `arwb [options]` with no subcommand: reads the workbench's options and hands them to `run` (the window, which
// lives above the command line in ui/window.hpp; main passes it in). Its help is `arwb --help`.
int cmd_workbench(int argc, char** argv, int (*run)(const WorkbenchOptions&));

// `arwb play BUNDLE [options]`: opens and verifies the bundle (bundle/bundle.hpp), then hands the player's options
// to `run` (the player window, ui/player.hpp; main passes it in, as for the workbench). A refused bundle is said on
// stderr, and with --error-window in a window too (`show_error`, ui/message_window.hpp, passed in likewise).
int cmd_play(int argc, char** argv, int (*run)(const PlayerOptions&), int (*show_error)(const MessageWindowOptions&));
inline constexpr const char* kPlaySummary =
    "play a bundle made by arwb export: the camera view with its media, no panels, in a window (F11: full screen)";

}  // namespace arwb
