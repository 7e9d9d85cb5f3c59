#include "ui/gl_window.hpp"

#include "render/gl_driver.hpp"
#include "render/texture.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace arwb::ui {

namespace {
void glfw_error(int code, const char* text) { std::fprintf(stderr, "arwb: GLFW error %d: %s\n", code, text); }
}  // namespace

std::string set_fullscreen(GLFWwindow* window, bool on, cv::Size window_size) {
  if (on == is_fullscreen(window)) return "";
  GLFWmonitor* monitor = on ? glfwGetPrimaryMonitor() : nullptr;
  const GLFWvidmode* mode = monitor ? glfwGetVideoMode(monitor) : nullptr;
  if (on && !mode) return "no monitor";
  if (on) glfwSetWindowMonitor(window, monitor, 0, 0, mode->width, mode->height, mode->refreshRate);
  else glfwSetWindowMonitor(window, nullptr, 80, 80, window_size.width, window_size.height, GLFW_DONT_CARE);
  return "";
}

bool is_fullscreen(GLFWwindow* window) { return glfwGetWindowMonitor(window) != nullptr; }

bool open_gl_window(const char* program, const char* title, cv::Size size, bool fullscreen, GlWindow* out) {
  glfwSetErrorCallback(glfw_error);
  if (!glfwInit()) {
    std::fprintf(stderr, "%s: cannot open a window (no display? run under xvfb-run, or use `arwb detect`)\n", program);
    return false;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWmonitor* monitor = fullscreen ? glfwGetPrimaryMonitor() : nullptr;
  if (monitor) {
    // The monitor's own mode: no change of resolution, the picture fills the screen.
    if (const GLFWvidmode* mode = glfwGetVideoMode(monitor)) size = {mode->width, mode->height};
  } else if (fullscreen) {
    std::fprintf(stderr, "%s: no monitor for --fullscreen; opening a window instead\n", program);
  }
  GLFWwindow* window = glfwCreateWindow(size.width, size.height, title, monitor, nullptr);
  if (!window) {
    std::fprintf(stderr, "%s: cannot create an OpenGL 3.3 window\n", program);
    glfwTerminate();
    return false;
  }
  glfwMakeContextCurrent(window);
  render::keep_gl_driver_loaded();  // see render/gl_driver.hpp
  glfwSwapInterval(0);  // paced by the caller; vsync under Xvfb is absent anyway

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // loaded and saved by hand, so a bad path is a message, not a silent loss
  ImGui::StyleColorsDark();
  // Opaque windows: panels opened over others (the scene's, on a first start) stay readable.
  ImGui::GetStyle().Colors[ImGuiCol_WindowBg].w = 1.0f;
  ImGui::GetStyle().Colors[ImGuiCol_PopupBg].w = 1.0f;   // dialogs and menus: no panel text showing through
  const char* font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  out->fonts_large.clear();
  out->font_normal = nullptr;
  if (std::filesystem::exists(font)) {
    out->font_normal = io.Fonts->AddFontFromFileTTF(font, 15.0f);
    // Presentation mode's sizes (presentation_scale): crisp text at each rather than one font stretched.
    for (int px : {20, 25, 30}) out->fonts_large[px] = io.Fonts->AddFontFromFileTTF(font, static_cast<float>(px));
  }
  if (!out->font_normal) out->font_normal = io.Fonts->AddFontDefault();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
  out->window = window;
  return true;
}

void close_gl_window(GlWindow& w) {
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  if (w.window) glfwDestroyWindow(w.window);
  w.window = nullptr;
  glfwTerminate();
}

void present_imgui_frame(GlWindow& w) {
  ImGui::Render();
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(w.window, &fw, &fh);
  glViewport(0, 0, fw, fh);
  glClearColor(0, 0, 0, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  glFinish();
}

bool save_window_image(GLFWwindow* window, const std::string& path, std::string* error) {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window, &w, &h);
  const cv::Mat img = render::read_framebuffer(w, h);
  try {
    if (cv::imwrite(path, img)) return true;
  } catch (const cv::Exception&) {
  }
  *error = "cannot write " + path;
  return false;
}

double covered_area(const ImDrawData* dd) {
  double total = 0;
  for (int l = 0; l < dd->CmdListsCount; ++l) {
    const ImDrawList* list = dd->CmdLists[l];
    for (const ImDrawCmd& cmd : list->CmdBuffer) {
      if (cmd.UserCallback) continue;
      const ImVec4& c = cmd.ClipRect;
      for (unsigned i = 0; i + 2 < cmd.ElemCount; i += 3) {
        const ImVec2& a = list->VtxBuffer[int(cmd.VtxOffset + list->IdxBuffer[int(cmd.IdxOffset + i)])].pos;
        const ImVec2& b = list->VtxBuffer[int(cmd.VtxOffset + list->IdxBuffer[int(cmd.IdxOffset + i + 1)])].pos;
        const ImVec2& d = list->VtxBuffer[int(cmd.VtxOffset + list->IdxBuffer[int(cmd.IdxOffset + i + 2)])].pos;
        const double area = std::abs(double(b.x - a.x) * (d.y - a.y) - double(d.x - a.x) * (b.y - a.y)) / 2;
        const float x0 = std::min({a.x, b.x, d.x}), x1 = std::max({a.x, b.x, d.x});
        const float y0 = std::min({a.y, b.y, d.y}), y1 = std::max({a.y, b.y, d.y});
        const double box = double(x1 - x0) * (y1 - y0);
        const double inside = double(std::max(0.0f, std::min(x1, c.z) - std::max(x0, c.x))) *
                              std::max(0.0f, std::min(y1, c.w) - std::max(y0, c.y));
        total += box > 0 ? area * inside / box : 0;
      }
    }
  }
  return total;
}

}  // namespace arwb::ui
