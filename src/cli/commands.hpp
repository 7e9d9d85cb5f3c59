// The arwb subcommands. Each takes the arguments after its own name and returns the process exit status;
// each prints its own usage on --help and a one-line error naming the bad argument otherwise.
#pragma once

#include "workbench/options.hpp"

namespace arwb {

int cmd_detect(int argc, char** argv);
int cmd_markers(int argc, char** argv);
int cmd_synth(int argc, char** argv);
int cmd_bench(int argc, char** argv);
int cmd_render(int argc, char** argv);
int cmd_make_media(int argc, char** argv);

// `arwb [options]` with no subcommand: reads the workbench's options and hands them to `run` (the window, which
// lives above the command line in ui/window.hpp; main passes it in).
int cmd_workbench(int argc, char** argv, int (*run)(const WorkbenchOptions&));

}  // namespace arwb
