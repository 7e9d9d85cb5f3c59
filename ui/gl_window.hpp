// The window both the workbench (ui/window.cpp) and the player (ui/player.cpp) run in: GLFW, an OpenGL 3.3 core
// context and Dear ImGui with the house style and fonts, opened and closed the same way for both, and the
// window's pixels saved for --screenshot.
#pragma once

#include <opencv2/core.hpp>

#include <map>
#include <string>

struct GLFWwindow;
struct ImFont;
struct ImDrawData;

namespace arwb::ui {

struct GlWindow {
  GLFWwindow* window = nullptr;
  ImFont* font_normal = nullptr;
  std::map<int, ImFont*> fonts_large;   // 20, 25 and 30 px, for presentation mode and the player's overlay
};

// Opens the window (on the primary monitor, at its own resolution, when `fullscreen`), makes its context current,
// creates the ImGui context with the dark style, opaque windows and DejaVu Sans, and initialises ImGui's GLFW and
// OpenGL back ends. `program` prefixes the one-line message printed to stderr when there is no display or no
// OpenGL 3.3; false then, and nothing is left open. ImGui's ini file is off (io.IniFilename): callers that keep
// settings load and save them by hand.
bool open_gl_window(const char* program, const char* title, cv::Size size, bool fullscreen, GlWindow* out);
// Full screen on the primary monitor at its own mode, or back to a window of `window_size`. The reason when it
// cannot ("no monitor"), else "".
std::string set_fullscreen(GLFWwindow* window, bool on, cv::Size window_size);
bool is_fullscreen(GLFWwindow* window);
// Shuts ImGui's back ends and context down, destroys the window and ends GLFW. Textures must be freed before.
void close_gl_window(GlWindow& w);
// The window's framebuffer as a PNG (or any format OpenCV writes by the extension). False when it cannot be
// written, with the reason in *error.
bool save_window_image(GLFWwindow* window, const std::string& path, std::string* error);
// Ends an ImGui frame on a black window: renders ImGui's draw data over the whole framebuffer and waits for GL
// (the player and the message window; the workbench counts its draw calls in between, so it keeps its own).
void present_imgui_frame(GlWindow& w);
// The framebuffer pixels ImGui's draw data covers, each triangle counted (so a pixel drawn twice counts twice),
// clipped to its command's clip rectangle by the share of its bounding box inside it: over the window's area, the
// overdraw a software renderer pays for.
double covered_area(const ImDrawData* dd);

}  // namespace arwb::ui
