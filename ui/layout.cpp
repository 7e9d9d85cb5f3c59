// [SECTION] Index
//   Layout file      ImGui's own settings (table columns) in imgui.ini
//   Workspaces file  the workspaces' trees, ratios and tabs in workspaces.json (ui/workspace.hpp)
//   Presentation     larger fonts and sizes for teaching, chosen by the window's height
#include "ui/app.hpp"

#include "base/files.hpp"
#include "base/text.hpp"

#include <imgui_internal.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace arwb {

// [SECTION] Layout file
std::string default_config_dir() {
  if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return std::string(x) + "/arwb";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.config/arwb";
  return ".arwb";
}

bool load_layout(const std::string& ini_path) {
  // Read through the shared file check, not ImGui's fopen: a FIFO or a device in its place must not stop the
  // window from opening.
  if (!std::filesystem::exists(ini_path)) return true;
  const Result<std::string> ini = read_text_file(ini_path, FileLimit{"a layout file", 1u << 20});
  if (ini) {
    ImGui::LoadIniSettingsFromMemory(ini->data(), ini->size());
    return true;
  }
  // Set aside, so that the layout saved at exit does not replace what could not be read.
  const Result<std::string> aside = set_aside(ini_path);
  std::fprintf(stderr, "arwb: %s (the default layout is used; %s)\n", printable(ini.error()).c_str(),
               aside ? ("the file is kept as " + printable(*aside)).c_str()
                     : (printable(aside.error()) + ", and the layout is not saved").c_str());
  return aside.ok();
}

void save_layout(const std::string& ini_path) {
  size_t len = 0;
  const char* ini = ImGui::SaveIniSettingsToMemory(&len);
  // Opening a FIFO to write waits for a reader: quitting would hang. Only a regular file (or none) is written.
  std::error_code ec;
  const auto type = std::filesystem::status(ini_path, ec).type();
  if (type != std::filesystem::file_type::not_found && type != std::filesystem::file_type::regular) {
    std::fprintf(stderr, "arwb: %s: not a regular file; the layout is not saved\n", printable(ini_path).c_str());
    return;
  }
  if (FILE* f = std::fopen(ini_path.c_str(), "wb")) {
    std::fwrite(ini, 1, len, f);
    std::fclose(f);
  } else {
    std::fprintf(stderr, "arwb: cannot save the layout to %s\n", printable(ini_path).c_str());
  }
}

// [SECTION] Workspaces file
void App::load_workspaces(const std::string& path) {
  if (!std::filesystem::exists(path)) return;
  const Result<std::string> text = read_text_file(path, FileLimit{"a workspaces file", 1u << 20});
  std::string problem;
  if (!text) problem = text.error();
  else if (!ui::workspaces_from_json(*text, &workspaces, &problem)) problem = path + ": " + problem;
  if (problem.empty()) return;
  // The file is set aside (never over an older one), not overwritten at exit, so the user can still mend it.
  const Result<std::string> aside = set_aside(path);
  workspaces_unsaved = !aside;
  warn("workspaces: " + printable(problem) + " (the shipped workspaces are used; " +
       (aside ? "the file is kept as " + printable(*aside) : printable(aside.error()) + ", and is not saved") + ")");
}

void App::save_workspaces(const std::string& path) {
  if (workspaces_unsaved) return;
  std::error_code ec;
  const auto type = std::filesystem::status(path, ec).type();
  if (type != std::filesystem::file_type::not_found && type != std::filesystem::file_type::regular) {
    std::fprintf(stderr, "arwb: %s: not a regular file; the workspaces are not saved\n", printable(path).c_str());
    return;
  }
  std::string err;
  if (!write_file_atomically(path, ui::workspaces_to_json(workspaces), &err)) {
    std::fprintf(stderr, "arwb: cannot save the workspaces: %s\n", printable(err).c_str());
  }
}

// [SECTION] Presentation
// Three font sizes are loaded (ui/window.cpp); the scale is the one whose font fits the window's height, so a
// 720-line projector gets 20 px text and a 1080-line one 30 px.
float presentation_scale(float height) {
  if (height >= 1000) return 2.0f;
  if (height >= 850) return 5.0f / 3.0f;
  return 4.0f / 3.0f;
}

void App::set_presentation(bool on) {
  view.presentation = on;
  presentation_applied = on;
  scale = on ? presentation_scale(window_height) : 1.0f;
  ImGuiStyle& style = ImGui::GetStyle();
  style = base_style;
  if (on) style.ScaleAllSizes(scale);
  ImFont* font = font_normal;
  const auto it = fonts_large.find(static_cast<int>(std::lround(15 * scale)));
  if (on && it != fonts_large.end()) font = it->second;
  ImGui::GetIO().FontDefault = font;
  ui::switch_workspace(workspaces, workspaces.current, view);   // its presentation arrangement, or back
}

}  // namespace arwb
