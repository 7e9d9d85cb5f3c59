// The workbench window: GLFW + OpenGL 3.3 core + Dear ImGui. The UI thread draws the latest finished frame from
// the Engine (workbench/engine.hpp) through the panels in ui/, forwards the user's edits to the engine, and carries
// out the panels' requests (snapshots, presets, the parameter sweep, marker sheets).
#pragma once

#include "workbench/options.hpp"

namespace arwb {

// Runs until the window closes (or `frames` are drawn). Returns the exit status.
int run_workbench(const WorkbenchOptions& options);

}  // namespace arwb
