// Keeps the OpenGL driver loaded until the process exits. Mesa loads its driver (dri/*_dri.so: llvmpipe under
// Xvfb and on EGL's surfaceless platform) when a display is initialised and unloads it when the display is
// closed (glfwTerminate, eglTerminate). The driver allocates a table once (under pthread_once, when the
// display is initialised) that it never frees; unloaded, that block is unreachable, and LeakSanitizer reports it as a
// leak from a module that is gone, so no suppression can name it. Kept loaded, the driver's globals still point
// at it and the sanitizer build reports only leaks of ours. It also spares a second context loading the driver
// (and LLVM) again. Call it once a context exists; the window and OffscreenContext do.
#pragma once

namespace arwb::render {

// Pins every Mesa driver the process has loaded (RTLD_NOLOAD | RTLD_NODELETE); returns how many it found.
int keep_gl_driver_loaded();

}  // namespace arwb::render
