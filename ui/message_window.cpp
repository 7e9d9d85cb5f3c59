#include "ui/message_window.hpp"

#include "ui/gl_window.hpp"
#include "base/json_text.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

namespace arwb {

int run_message_window(const MessageWindowOptions& options) {
  ui::GlWindow gl;
  // Small and fixed: a message box, not a workspace. The message wraps, and scrolls when it is very long.
  if (!ui::open_gl_window("arwb play", options.title.c_str(), {640, 220}, false, &gl)) return 1;
  std::string closed_by = "frames";
  int frames = 0;
  while (!glfwWindowShouldClose(gl.window)) {
    // Nothing moves here: wait for input rather than spin, except in scripted runs that count frames.
    if (options.frames > 0) glfwPollEvents();
    else glfwWaitEventsTimeout(0.5);
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    const ImGuiViewport* vp = ImGui::GetMainViewport();
    ImGui::SetNextWindowPos(vp->Pos);
    ImGui::SetNextWindowSize(vp->Size);
    ImGui::Begin("##message", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                     ImGuiWindowFlags_NoBringToFrontOnFocus);
    ImGui::TextColored(ImVec4(1, 0.45f, 0.4f, 1), "%s", options.heading.c_str());
    ImGui::Spacing();
    const float button_row = ImGui::GetFrameHeightWithSpacing() + ImGui::GetStyle().ItemSpacing.y;
    ImGui::BeginChild("##text", {0, -button_row});
    ImGui::PushTextWrapPos(0);
    ImGui::TextUnformatted(options.message.c_str());
    ImGui::PopTextWrapPos();
    ImGui::EndChild();
    const float w = 100;
    ImGui::SetCursorPosX(ImGui::GetWindowWidth() - w - ImGui::GetStyle().WindowPadding.x);
    if (ImGui::Button("Close", {w, 0})) closed_by = "button";
    if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE) || ImGui::IsKeyPressed(GLFW_KEY_ENTER) ||
        ImGui::IsKeyPressed(GLFW_KEY_KP_ENTER))
      closed_by = "key";
    ImGui::End();
    ui::present_imgui_frame(gl);
    ++frames;
    const bool last = options.frames > 0 && frames >= options.frames;
    const bool closing = last || closed_by != "frames" || glfwWindowShouldClose(gl.window);
    if (closing && !options.screenshot.empty()) {
      std::string why;
      if (!ui::save_window_image(gl.window, options.screenshot, &why)) std::fprintf(stderr, "arwb play: screenshot: %s\n", why.c_str());
    }
    glfwSwapBuffers(gl.window);
    if (closing) break;
    if (options.frames > 0) std::this_thread::sleep_for(std::chrono::milliseconds(16));
  }
  if (closed_by == "frames" && (options.frames == 0 || frames < options.frames)) closed_by = "window";
  if (options.stats) {
    const nlohmann::ordered_json s = {{"window", "error"},   {"title", options.title}, {"heading", options.heading},
                                      {"message", options.message}, {"frames", frames},   {"closed_by", closed_by}};
    std::printf("%s\n", json_text(s).c_str());
  }
  ui::close_gl_window(gl);
  return 1;
}

}  // namespace arwb
