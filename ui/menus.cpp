// The window's menu bar, its keys and its status bar. Each menu item and key makes the request (ui/request.hpp) an
// --actions step or a panel would, carried out at once.
#include "ui/app.hpp"
#include "ui/gl_window.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_internal.h>

#include <algorithm>
#include <chrono>

namespace arwb {

namespace {

void file_menu(App& app) {
  if (!ImGui::BeginMenu("File")) return;
  if (ImGui::MenuItem("Synthetic source")) app.carry_out(ui::OpenSource{"synthetic"});
  // The browser opens at this frame's draw_dialogs: a menu item cannot open a modal inside the menu.
  if (ImGui::MenuItem("Open source...")) app.carry_out(ui::Browse{ui::FileKind::source});
  if (ImGui::MenuItem("Open scene...")) app.carry_out(ui::Browse{ui::FileKind::scene});
  if (ImGui::MenuItem("Load preset...")) app.carry_out(ui::Browse{ui::FileKind::preset});
  const ui::RecentFiles& recent = app.status.recent;
  if (ImGui::BeginMenu("Recent", !recent.of(ui::FileKind::source).empty() || !recent.of(ui::FileKind::scene).empty() ||
                                     !recent.of(ui::FileKind::preset).empty())) {
    for (ui::FileKind k : {ui::FileKind::source, ui::FileKind::scene, ui::FileKind::preset}) {
      for (const std::string& p : recent.of(k)) {
        const std::string label = std::string(ui::file_kind_name(k)) + ": " + p;
        if (ImGui::MenuItem(label.c_str())) app.carry_out(ui::OpenRecent{k, p});
      }
    }
    ImGui::EndMenu();
  }
  ImGui::Separator();
  if (ImGui::MenuItem("Snapshot", "S")) app.carry_out(ui::Snapshot{});
  if (ImGui::MenuItem("Print marker sheet...")) app.carry_out(ui::OpenSheetDialog{});
  ImGui::Separator();
  // The paper's Code Generator: the scene as a bundle that runs on its own, and trying one in the player.
  if (ImGui::MenuItem("Export...", nullptr, false, app.frame && !app.frame->scene.file.empty()))
    app.carry_out(ui::OpenExportDialog{});
  if (ImGui::MenuItem("Play bundle...")) app.carry_out(ui::Browse{ui::FileKind::bundle});
  ImGui::Separator();
  if (ImGui::MenuItem("Quit", "Ctrl+Q")) app.carry_out(ui::Quit{});
  ImGui::EndMenu();
}

void help_menu(App& app) {
  if (!ImGui::BeginMenu("Help")) return;
  const Dialogs& d = app.dialogs;
  if (ImGui::MenuItem("Keyboard shortcuts", nullptr, d.show_shortcuts))
    app.carry_out(ui::ShowHelp{ui::HelpPage::shortcuts, !d.show_shortcuts});
  if (ImGui::MenuItem("First five minutes", nullptr, d.show_first_steps))
    app.carry_out(ui::ShowHelp{ui::HelpPage::first_steps, !d.show_first_steps});
  ImGui::Separator();
  if (ImGui::MenuItem("About ArUco Workbench", nullptr, d.show_about))
    app.carry_out(ui::ShowHelp{ui::HelpPage::about, !d.show_about});
  ImGui::EndMenu();
}

}  // namespace

void App::draw_menu() {
  if (!ImGui::BeginMainMenuBar()) return;
  file_menu(*this);
  if (ImGui::BeginMenu("Edit")) {
    const std::string u = history.undo_name(), r = history.redo_name();
    if (ImGui::MenuItem(u.empty() ? "Undo" : ("Undo " + u).c_str(), "Ctrl+Z", false, !u.empty())) carry_out(ui::Undo{});
    if (ImGui::MenuItem(r.empty() ? "Redo" : ("Redo " + r).c_str(), "Ctrl+Shift+Z", false, !r.empty())) carry_out(ui::Redo{});
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("View")) {
    for (int i = 0; i < ui::kPanelCount; ++i) {
      const bool open = view.open[static_cast<size_t>(i)];
      if (ImGui::MenuItem(ui::panel_title(static_cast<ui::Panel>(i)), nullptr, open))
        carry_out(ui::SetPanelOpen{static_cast<ui::Panel>(i), !open});
    }
    ImGui::Separator();
    if (ImGui::MenuItem("Presentation mode", "F5", view.presentation)) carry_out(ui::TogglePresentation{});
    if (ImGui::MenuItem("Full screen", "F11", ui::is_fullscreen(glfw_window))) carry_out(ui::SetFullscreen{});
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Teach")) {
    if (ImGui::MenuItem("Guided tour", "T")) carry_out(ui::StartTour{});
    if (ImGui::MenuItem("Freeze frame", "Space", settings.frozen)) carry_out(ui::Freeze{!settings.frozen});
    if (ImGui::MenuItem("Next frame", "N")) carry_out(ui::NextFrame{});
    ImGui::EndMenu();
  }
  help_menu(*this);
  ImGui::EndMainMenuBar();
}

// Keys (ImGui 1.86 indexes keys by GLFW key code). None fires while a text field has the keyboard: io.WantTextInput
// alone says what the previous frame wanted, so a field activated in this frame (or a popup's field) would let
// the first letter typed through as a shortcut; the active item, looked at now, is what is being typed into.
void App::handle_keys() {
  const ImGuiIO& io = ImGui::GetIO();
  const ImGuiContext& g = *ImGui::GetCurrentContext();
  const bool text_field = io.WantTextInput || (g.ActiveId != 0 && g.ActiveId == g.InputTextState.ID);
  // Ctrl+Q types nothing, so it quits from a text field too (with the unsaved-edits question).
  if (ImGui::IsKeyPressed(GLFW_KEY_Q) && io.KeyCtrl) carry_out(ui::Quit{});
  if (text_field || ImGui::GetTopMostPopupModal() != nullptr) return;
  if (ImGui::IsKeyPressed(GLFW_KEY_S) && !io.KeyCtrl) carry_out(ui::Snapshot{});
  if (ImGui::IsKeyPressed(GLFW_KEY_SPACE)) carry_out(ui::Freeze{!settings.frozen});
  if (ImGui::IsKeyPressed(GLFW_KEY_N) && !io.KeyCtrl) carry_out(ui::NextFrame{});
  if (ImGui::IsKeyPressed(GLFW_KEY_T) && !io.KeyCtrl) carry_out(ui::StartTour{});
  if (ImGui::IsKeyPressed(GLFW_KEY_F5)) carry_out(ui::TogglePresentation{});
  if (ImGui::IsKeyPressed(GLFW_KEY_F11)) carry_out(ui::SetFullscreen{});
  if (ImGui::IsKeyPressed(GLFW_KEY_Z) && io.KeyCtrl) carry_out(io.KeyShift ? ui::Request(ui::Redo{}) : ui::Undo{});
}

void App::draw_status_bar(float height) {
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos({vp->Pos.x, vp->Pos.y + vp->Size.y - height});
  ImGui::SetNextWindowSize({vp->Size.x, height});
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                                 ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav |
                                 ImGuiWindowFlags_NoBringToFrontOnFocus;
  // Its one line is lower than ImGui's smallest window (32 px, 64 in presentation mode), which made it reach a
  // few pixels past the screen's bottom (the layout audit's off_screen).
  ImGui::PushStyleVar(ImGuiStyleVar_WindowMinSize, {0, 0});
  ImGui::Begin("##status", nullptr, flags);
  ImGui::PopStyleVar();
  ImGui::Text("%s | UI %.0f fps | detection %.0f fps | %s", status.source.text().c_str(), status.ui_fps, status.detect_fps,
              settings.frozen ? "FROZEN" : "live");
  // A note (undo, redo, a file written) stays for a while; then the newest warning or error.
  const double now = std::chrono::duration<double>(Clock::now() - t0).count();
  if (!note.empty() && now - note_time < kNoteSeconds) {
    ImGui::SameLine();
    ImGui::TextColored(ImVec4(0.6f, 0.85f, 1, 1), "| %s", note.c_str());
  }
  // A scene that runs with mappings skipped, disabled or failing says so for as long as it lasts.
  if (frame) {
    const auto& rows = frame->scene.mappings;
    if (const auto bad = std::count_if(rows.begin(), rows.end(), [](const MappingRow& r) { return r.health != MappingHealth::ok; })) {
      ImGui::SameLine();
      ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "| scene: %d of %zu mappings not working", static_cast<int>(bad), rows.size());
    }
  }
  // The newest warning or error stays visible for a while.
  for (auto it = log_copy.rbegin(); it != log_copy.rend(); ++it) {
    const double age = std::chrono::duration<double>(Clock::now() - t0).count() - it->time_s;
    if (age > 15) break;
    if (it->level == LogLevel::info) continue;
    ImGui::SameLine();
    ImGui::TextColored(it->level == LogLevel::error ? ImVec4(1, 0.35f, 0.3f, 1) : ImVec4(1, 0.8f, 0.3f, 1), "| %s",
                       it->text.c_str());
    break;
  }
  ImGui::End();
}

}  // namespace arwb
