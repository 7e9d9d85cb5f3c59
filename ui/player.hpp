// The player: "the application the paper generated". The camera view with the scene's media fills the window (the
// image's aspect kept, black bars), with no menus or panels; F1 (or I) shows a small overlay for whoever sets it up.
// It is the workbench's Engine, SceneStage and compositor without the debugging, so the sandbox, the limits and
// where media land are the workbench's. `arwb play BUNDLE` (src/cli/cmd_play.cpp) opens a bundle and runs this.
#pragma once

#include "workbench/options.hpp"

namespace arwb {

// Runs until the window closes, q, Esc in a window (Esc in full screen leaves full screen), or `frames` are drawn.
// Returns the exit status.
int run_player(const PlayerOptions& options);

}  // namespace arwb
