// A small window with one message and a Close button: how `arwb play --error-window` says that a bundle was
// refused when it was started without a terminal (the desktop's file association), where stderr is seen by no one.
// The same GLFW and ImGui window as the workbench and the player (ui/gl_window.hpp).
#pragma once

#include "workbench/options.hpp"

namespace arwb {

// Shows options.message until Close, Enter, Esc or the window's own close button, or `frames` are drawn. Returns
// 1 (what was shown is a failure), also when no window can be opened (the message is on stderr already).
int run_message_window(const MessageWindowOptions& options);

}  // namespace arwb
