// [SECTION] Index
//   Layout file     panel visibility kept in imgui.ini beside the window places; loading and saving it
//   First layout    where each panel opens on a first start
//   Presentation    larger fonts and sizes for teaching
#include "ui/app.hpp"

#include "base/files.hpp"
#include "base/text.hpp"

#include <imgui_internal.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string_view>

namespace arwb {

// [SECTION] Layout file
std::string default_config_dir() {
  if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return std::string(x) + "/arwb";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.config/arwb";
  return ".arwb";
}

namespace {
// Panel visibility, saved in the same imgui.ini as the window layout; the handler's UserData is the View.
void* settings_open(ImGuiContext*, ImGuiSettingsHandler* h, const char* name) {
  return std::string_view(name) == "Panels" ? h->UserData : nullptr;
}
void settings_read_line(ImGuiContext*, ImGuiSettingsHandler*, void* entry, const char* line) {
  auto* v = static_cast<ui::View*>(entry);
  char key[64];
  int on = 0;
  if (std::sscanf(line, "%63[^=]=%d", key, &on) != 2) return;
  ui::Panel p;
  if (ui::panel_from_key(key, &p)) v->open[static_cast<size_t>(p)] = on != 0;
}
void settings_write_all(ImGuiContext*, ImGuiSettingsHandler* h, ImGuiTextBuffer* buf) {
  const auto* v = static_cast<const ui::View*>(h->UserData);
  buf->appendf("[%s][Panels]\n", h->TypeName);
  for (int i = 0; i < ui::kPanelCount; ++i) {
    buf->appendf("%s=%d\n", ui::panel_key(static_cast<ui::Panel>(i)), v->open[static_cast<size_t>(i)] ? 1 : 0);
  }
  buf->append("\n");
}
}  // namespace

void load_layout(ui::View& view, const std::string& ini_path) {
  ImGuiSettingsHandler handler;
  handler.TypeName = "Arwb";
  handler.TypeHash = ImHashStr("Arwb");
  handler.ReadOpenFn = settings_open;
  handler.ReadLineFn = settings_read_line;
  handler.WriteAllFn = settings_write_all;
  handler.UserData = &view;
  ImGui::GetCurrentContext()->SettingsHandlers.push_back(handler);
  // Read through the shared file check, not ImGui's fopen: a FIFO or a device in its place must not stop the
  // window from opening.
  if (!std::filesystem::exists(ini_path)) return;
  const Result<std::string> ini = read_text_file(ini_path, FileLimit{"a layout file", 1u << 20});
  if (ini) ImGui::LoadIniSettingsFromMemory(ini->data(), ini->size());
  else std::fprintf(stderr, "arwb: %s (the default layout is used)\n", printable(ini.error()).c_str());
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

// [SECTION] First layout
// The first start's layout: live view large on the left, the pipeline under it, tools on the right.
void default_layout(ui::Panel p, ImVec2 size, float menu_h, float status_h) {
  const float W = size.x, H = size.y - menu_h - status_h;
  const float left = W * 0.50f, mid = W * 0.25f, right = W - left - mid;
  const float top = menu_h;
  ImVec2 pos, sz;
  switch (p) {
    case ui::Panel::live_view: pos = {0, top}; sz = {left, H * 0.64f}; break;
    case ui::Panel::pipeline: pos = {0, top + H * 0.64f}; sz = {left, H * 0.36f}; break;
    case ui::Panel::candidates: pos = {left, top}; sz = {mid, H * 0.42f}; break;
    case ui::Panel::inspector: pos = {left, top + H * 0.42f}; sz = {mid, H * 0.40f}; break;
    case ui::Panel::parameters: pos = {left + mid, top}; sz = {right, H * 0.45f}; break;
    case ui::Panel::source: pos = {left + mid, top + H * 0.45f}; sz = {right, H * 0.3f}; break;
    case ui::Panel::timings: pos = {left + mid, top + H * 0.75f}; sz = {right, H * 0.25f}; break;
    case ui::Panel::dictionary: pos = {left + 40, top + 60}; sz = {mid + 80, H * 0.6f}; break;
    case ui::Panel::peers: pos = {left + mid, top + H * 0.75f}; sz = {right, H * 0.25f}; break;
    case ui::Panel::log: pos = {left, top + H * 0.82f}; sz = {mid, H * 0.18f}; break;
    case ui::Panel::tour: pos = {W * 0.2f, top + 40}; sz = {W * 0.35f, H * 0.55f}; break;
    case ui::Panel::why: pos = {left + 20, top + 30}; sz = {mid + 60, H * 0.55f}; break;
    case ui::Panel::scene: pos = {left + mid, top}; sz = {right, H * 0.45f}; break;
    case ui::Panel::script: pos = {left, top}; sz = {mid, H * 0.82f}; break;
    case ui::Panel::console: pos = {left + mid, top + H * 0.75f}; sz = {right, H * 0.25f}; break;
    default: return;
  }
  ImGui::SetNextWindowPos(pos, ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(sz, ImGuiCond_FirstUseEver);
}

// [SECTION] Presentation
void App::set_presentation(bool on) {
  view.presentation = on;
  presentation_applied = on;
  ImGuiStyle& style = ImGui::GetStyle();
  style = base_style;
  if (on) style.ScaleAllSizes(2.0f);
  ImGui::GetIO().FontDefault = on && font_large ? font_large : font_normal;
}

}  // namespace arwb
