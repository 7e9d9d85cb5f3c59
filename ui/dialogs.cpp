// [SECTION] Index
//   Opening      File > Open..., the file browser's picks, files dropped on the window
//   Undo         one history entry per completed edit of the parameters and dictionaries
//   Unsaved      "save, discard or cancel" before a quit, a source or a scene change drops the editor's edits
//   Typing       --actions type=: keys and characters fed to ImGui as a keyboard would
//   Help         the Help windows: shortcuts, first five minutes, About
//   Dialogs      drawn each frame after the panels: the browsers, the unsaved-edits question, the marker sheet
//                dialog, the Help windows
#include "ui/app.hpp"
#include "ui/help_text.hpp"

#include "base/files.hpp"
#include "base/text.hpp"
#include "base/version.hpp"
#include "capture/image_io.hpp"
#include "synth/marker_sheet.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <lua.hpp>
#include <opencv2/core/version.hpp>

#include <span>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <utility>


namespace arwb {

namespace fs = std::filesystem;

namespace {
constexpr FileLimit kRecentFile{"a recent-files list", 1u << 20};
}  // namespace

void App::note_status(const std::string& s) {
  info(s);
  note = s;
  note_time = std::chrono::duration<double>(Clock::now() - t0).count();
}

// [SECTION] Opening
void App::open_path(ui::FileKind kind, const std::string& path) {
  switch (kind) {
    case ui::FileKind::source: requests.push_back(ui::OpenSource{path}); break;
    case ui::FileKind::scene: requests.push_back(ui::LoadScene{path}); break;
    case ui::FileKind::preset: requests.push_back(ui::LoadPreset{path}); break;
    case ui::FileKind::bundle: requests.push_back(ui::PlayBundle{path}); break;
    case ui::FileKind::calibration:
    case ui::FileKind::count: warn("calibration files cannot be opened yet: " + path); return;
  }
  // Camera and synthetic specs are one click away in the browser; only files are remembered.
  if (kind != ui::FileKind::source || (path != "synthetic" && path.rfind("camera:", 0) != 0)) {
    status.recent.add(kind, path);
    save_recent();
  }
}

void App::drop(const std::string& path) {
  const PathKind k = classify_path(path);
  const ui::DropKind d = ui::drop_kind(path, k == PathKind::folder, k == PathKind::image || k == PathKind::video);
  const std::string abs = fs::absolute(path).lexically_normal().string();
  switch (d) {
    case ui::DropKind::scene: info("dropped " + abs + ": loading it as the scene"); open_path(ui::FileKind::scene, abs); break;
    case ui::DropKind::preset: info("dropped " + abs + ": loading it as a preset"); open_path(ui::FileKind::preset, abs); break;
    case ui::DropKind::source: info("dropped " + abs + ": opening it as the source"); open_path(ui::FileKind::source, abs); break;
    case ui::DropKind::none:
      warn("dropped " + abs + ": " +
           (k == PathKind::missing ? std::string("no such file")
                                   : "not a scene (.lua, .xml), a preset (.yml) or an image, video or folder") +
           "; nothing opened");
      break;
  }
}

void App::load_recent() {
  const std::string path = status.config_dir + "/recent.txt";
  std::error_code ec;
  if (!fs::exists(path, ec)) return;
  const Result<std::string> text = read_text_file(path, kRecentFile);
  if (!text) {
    // Set aside, never written over: the user's starred folders are in it.
    const Result<std::string> aside = set_aside(path);
    status.recent.unsaved = !aside;
    warn("recent files: " + printable(text.error()) + " (starting with none; " +
         (aside ? "the file is kept as " + printable(*aside) : printable(aside.error()) + ", and is not saved") + ")");
    return;
  }
  std::vector<std::string> problems;
  status.recent = ui::parse_recent(*text, &problems);
  for (const auto& p : problems) warn("recent files: " + path + ": " + p + " (kept as it is)");
}

void App::save_recent() {
  if (status.recent.unsaved) return;
  std::string err;
  const std::string path = status.config_dir + "/recent.txt";
  if (!write_file_atomically(path, ui::recent_text(status.recent), &err)) warn("recent files: cannot save " + path + ": " + err);
}

// [SECTION] Undo
// Called after the panels: an edit is complete when no widget is active (the slider let go, the typed value
// entered), so a drag over fifty frames is one entry.
void App::track_edits() {
  const ui::DetectorState now{settings.params, settings.dictionaries};
  if (now == committed || ImGui::IsAnyItemActive()) return;
  history.record(committed, now, change_name);
  committed = now;
  change_name.clear();
}

void App::undo() {
  ui::DetectorState s;
  std::string name;
  if (!history.undo(&s, &name)) return note_status("nothing to undo");
  settings.params = s.params;
  settings.dictionaries = s.dictionaries;
  committed = s;
  note_status("undo: " + name);
}

void App::redo() {
  ui::DetectorState s;
  std::string name;
  if (!history.redo(&s, &name)) return note_status("nothing to redo");
  settings.params = s.params;
  settings.dictionaries = s.dictionaries;
  committed = s;
  note_status("redo: " + name);
}

// [SECTION] Unsaved
namespace {
// The question is asked when the Script editor has unsaved edits; `r` waits for the answer.
template <class R>
bool defer(App& app, R r) {
  if (r.asked || !app.view.script_unsaved) return false;
  r.asked = true;
  Dialogs::Unsaved& u = app.dialogs.unsaved;
  u.deferred = std::move(r);
  u.quit_waiting = false;
  u.ask = true;
  return true;
}
}  // namespace

bool App::ask_before(const ui::OpenSource& r) { return defer(*this, r); }

bool App::ask_before(const ui::LoadScene& r) {
  if (frame && r.path == frame->scene.file) return false;   // a reload
  return defer(*this, r);
}

void App::proceed() {
  Dialogs::Unsaved& u = dialogs.unsaved;
  if (u.quit_waiting) {
    u.quit_confirmed = true;
    if (glfw_window) glfwSetWindowShouldClose(glfw_window, 1);
  } else if (u.deferred) {
    requests.push_back(*u.deferred);
  }
  u.quit_waiting = false;
  u.deferred.reset();
  u.save_wait = -1;
}

namespace {
std::string file_name(const std::string& p) {
  const size_t s = p.find_last_of('/');
  return s == std::string::npos ? p : p.substr(s + 1);
}
}  // namespace

// [SECTION] Typing
void App::type_text(const std::string& text) {
  for (const char c : text) dialogs.typing.push_back(static_cast<unsigned char>(c));
}

void App::feed_typing() {
  ImGuiIO& io = ImGui::GetIO();
  int& key_down = dialogs.key_down;
  const int released = key_down;
  if (key_down >= 0) {
    io.KeysDown[key_down] = false;
    key_down = -1;
  }
  std::deque<int>& typing = dialogs.typing;
  if (typing.empty()) return;
  const int c = typing.front();
  // ImGui 1.86 indexes keys by GLFW key code; a letter's code is its upper-case ASCII.
  const int key = c == '\n' ? GLFW_KEY_ENTER : std::toupper(c);
  if (key == released) return;   // the same key again: up for one frame first, or it is not pressed again
  typing.pop_front();
  if (key >= 0 && key < IM_ARRAYSIZE(io.KeysDown)) {
    io.KeysDown[key] = true;
    key_down = key;
  }
  if (c != '\n') io.AddInputCharacter(static_cast<unsigned>(c));
}

// [SECTION] Help
namespace {

// `shift` in screen pixels from the centre, so the Help windows opened together do not hide each other.
void centred_window(const char* title, bool* open, ImVec2 size, ImVec2 shift) {
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  // On the screen at any scale (presentation mode doubles the sizes): no larger than it, and moved in from an
  // edge the shift would take it past; two opened together may then overlap, neither is cut.
  size = {std::min(size.x, vp->Size.x * 0.96f), std::min(size.y, vp->Size.y * 0.9f)};
  const float cx = std::clamp(vp->GetCenter().x + shift.x, vp->Pos.x + size.x / 2, vp->Pos.x + vp->Size.x - size.x / 2);
  const float cy = std::clamp(vp->GetCenter().y + shift.y, vp->Pos.y + size.y / 2, vp->Pos.y + vp->Size.y - size.y / 2);
  ImGui::SetNextWindowPos({cx, cy}, ImGuiCond_Appearing, {0.5f, 0.5f});
  ImGui::SetNextWindowSize(size, ImGuiCond_Appearing);
  ImGui::Begin(title, open, ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse);
}

void first_steps_page(std::span<const char* const> lines) {
  for (const char* line : lines) {
    ImGui::Bullet();
    ImGui::TextWrapped("%s", line);
  }
}

}  // namespace

// [SECTION] Dialogs
namespace {

// The file browser asked for (File > Open..., a panel's Browse...), and the Calibrate panel's Save...: where to
// write the calibration, then a request.
void draw_browsers(App& app, ui::Context& ctx) {
  Dialogs& d = app.dialogs;
  if (const std::optional<ui::FileKind> k = std::exchange(d.browse, std::nullopt)) {
    const std::string title = std::string("Open ") + ui::file_kind_name(*k);
    const auto& recent = app.status.recent.of(*k);
    // Where the last file of this kind came from; else the user's presets folder for presets; else here.
    std::string folder = ".";
    std::error_code ec;
    const std::string presets = app.status.config_dir + "/presets";
    if (!recent.empty()) folder = fs::path(recent[0]).parent_path().string();
    else if (*k == ui::FileKind::preset && fs::is_directory(presets, ec)) folder = presets;
    ui::open_browser(ctx, d.browser, *k, title, folder);
  }
  ui::draw_file_browser(ctx, d.browser);
  if (d.browser.visible) d.modal = "File browser";
  if (std::exchange(d.save_calibration, false)) {
    const auto& recent = app.status.recent.of(ui::FileKind::calibration);
    const std::string folder = recent.empty() ? "." : fs::path(recent[0]).parent_path().string();
    ui::open_browser(ctx, d.calibration_browser, ui::FileKind::calibration, "Save the calibration as", folder, true,
                     "camera.yml");
  }
  std::string chosen;
  if (ui::draw_file_browser(ctx, d.calibration_browser, &chosen)) app.requests.push_back(ui::SaveCalibration{chosen});
  if (d.calibration_browser.visible) d.modal = "File browser";
}

// "Save, discard or cancel" before a quit, a source or a scene change drops the Script editor's edits.
void draw_unsaved_question(App& app) {
  Dialogs::Unsaved& u = app.dialogs.unsaved;
  if (std::exchange(u.ask, false)) ImGui::OpenPopup("Unsaved edits");
  ImGui::SetNextWindowPos(ImGui::GetMainViewport()->GetCenter(), ImGuiCond_Appearing, {0.5f, 0.5f});
  if (!ImGui::BeginPopupModal("Unsaved edits", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  app.dialogs.modal = "Unsaved edits";
  const std::string file = file_name(app.status.script_file.path);
  std::string what = "quitting";
  if (const auto* r = u.deferred ? std::get_if<ui::OpenSource>(&*u.deferred) : nullptr) what = "opening the source " + r->spec;
  if (const auto* r = u.deferred ? std::get_if<ui::LoadScene>(&*u.deferred) : nullptr)
    what = r->path.empty() ? "unloading the scene" : "loading the scene " + file_name(r->path);
  ImGui::Text("The Script editor has unsaved edits to %s.", file.c_str());
  ImGui::Text("Save them before %s?", what.c_str());
  ImGui::Spacing();
  const std::optional<ui::DialogButton> a = std::exchange(app.dialogs.answer, std::nullopt);
  if (u.save_wait >= 0) {
    ImGui::TextDisabled("Saving...");
  } else {
    if (ImGui::Button("Save") || a == ui::DialogButton::save) {
      app.view.script_save_now = true;   // the editor saves at its next draw; the request's result proceeds
      app.view.show(ui::Panel::script);
      u.save_wait = 0;
    }
    ImGui::SameLine();
    if (ImGui::Button("Discard") || a == ui::DialogButton::discard) {
      app.view.script_discard = true;
      app.info("unsaved edits to " + file + " discarded");
      app.proceed();
      ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel") || a == ui::DialogButton::cancel || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) {
      u.quit_waiting = false;
      u.deferred.reset();
      ImGui::CloseCurrentPopup();
    }
  }
  if (u.save_wait >= 0 && ++u.save_wait > 180) {
    app.error("the Script editor did not save " + file + " (is it open?); nothing else was done");
    u.save_wait = -1;
    u.quit_waiting = false;
    u.deferred.reset();
  }
  if (!u.quit_waiting && !u.deferred && u.save_wait < 0) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
}

// File > Print marker sheet..., or a panel's button (the Dictionary explorer, the tour).
void draw_sheet_dialog(App& app, ui::Context& ctx) {
  Dialogs::Sheet& sheet = app.dialogs.sheet;
  if (std::exchange(sheet.opening, false)) ImGui::OpenPopup("Print marker sheet");
  ImGui::SetNextWindowPos(ImGui::GetMainViewport()->GetCenter(), ImGuiCond_Appearing, {0.5f, 0.5f});
  if (!ImGui::BeginPopupModal("Print marker sheet", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  app.dialogs.modal = "Print marker sheet";
  const float w = 360 * ctx.scale;
  ImGui::SetNextItemWidth(w);
  if (ImGui::BeginCombo("dictionary", sheet.dictionary.c_str(), ImGuiComboFlags_HeightLarge)) {
    for (const std::string& n : dictionary_names())
      if (ImGui::Selectable(n.c_str(), n == sheet.dictionary)) sheet.dictionary = n;
    ImGui::EndCombo();
  }
  ImGui::SetNextItemWidth(w);
  ImGui::InputTextWithHint("ids", "0-11 or 3,7,9", sheet.ids, sizeof sheet.ids);
  ImGui::SetNextItemWidth(w);
  ImGui::InputDouble("marker size (mm)", &sheet.size_mm, 1, 10, "%.1f");
  sheet.size_mm = std::clamp(sheet.size_mm, kSheetMinMarkerMm, kSheetMaxMarkerMm);
  ImGui::SetNextItemWidth(w);
  ImGui::InputText("##sheet_path", sheet.path, sizeof sheet.path);
  ImGui::SameLine();
  const std::optional<ui::DialogButton> a = std::exchange(app.dialogs.answer, std::nullopt);
  if (ImGui::Button("Browse...") || a == ui::DialogButton::browse) {
    const fs::path p(sheet.path);
    ui::open_browser(ctx, sheet.browser, ui::FileKind::calibration, "Save the marker sheet as",
                     p.parent_path().string(), true, p.filename().string());
  }
  std::string chosen;
  if (ui::draw_file_browser(ctx, sheet.browser, &chosen)) std::snprintf(sheet.path, sizeof sheet.path, "%s", chosen.c_str());
  if (sheet.browser.visible) app.dialogs.modal = "File browser";
  ImGui::TextDisabled("A PDF of A4 pages; print it at 100%% and check the 100 mm bar.");
  if (ImGui::Button("Write") || a == ui::DialogButton::write) {
    app.requests.push_back(ui::WriteMarkerSheet{sheet.path, sheet.dictionary, sheet.ids, sheet.size_mm});
    ImGui::CloseCurrentPopup();
  }
  ImGui::SameLine();
  if (ImGui::Button("Cancel") || a == ui::DialogButton::cancel) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
}

void draw_help_windows(Dialogs& d, float scale, const std::string& config_dir) {
  if (d.show_shortcuts) {
    centred_window("Keyboard shortcuts", &d.show_shortcuts, {560 * scale, 420 * scale}, {-300 * scale, 0});
    if (ImGui::BeginTable("##keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
      ImGui::TableSetupColumn("Keys", ImGuiTableColumnFlags_WidthFixed, ImGui::CalcTextSize("Wheel, right-drag").x);
      ImGui::TableSetupColumn("What", ImGuiTableColumnFlags_WidthStretch);
      ImGui::TableHeadersRow();
      for (const ui::Shortcut& s : ui::shortcuts()) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(s.keys);
        ImGui::TableNextColumn();
        ImGui::TextWrapped("%s", s.what);
      }
      ImGui::EndTable();
    }
    ImGui::TextDisabled("Keys do nothing while you type in a text field.");
    ImGui::End();
  }
  if (d.show_first_steps) {
    centred_window("First five minutes", &d.show_first_steps, {620 * scale, 460 * scale}, {300 * scale, 0});
    if (ImGui::BeginTabBar("##who")) {
      for (const ui::FirstStepsPage& page : ui::first_steps_pages()) {
        if (ImGui::BeginTabItem(page.tab)) {
          first_steps_page(page.lines);
          ImGui::EndTabItem();
        }
      }
      ImGui::EndTabBar();
    }
    ImGui::End();
  }
  if (d.show_about) {
    centred_window("About ArUco Workbench", &d.show_about, {560 * scale, 300 * scale}, {0, 0});
    ImGui::Text("ArUco Workbench %s", kVersion);
    // No initials: ImGui 1.86 may wrap a line after a full stop, which would leave a lone comma.
    ImGui::TextWrapped("Seeing, teaching and scripting marker-based augmented reality, after Avola, Cinque, Foresti, "
                       "Mercuri and Pannone: \"A Practical Framework for the Development of Augmented Reality "
                       "Applications by using ArUco Markers\" (ICPRAM 2016).");
    ImGui::Spacing();
    ImGui::Text("OpenCV %s", CV_VERSION);
    ImGui::Text("Dear ImGui %s", IMGUI_VERSION);
    ImGui::Text("%s", LUA_RELEASE);
    ImGui::Text("Configuration: %s", config_dir.c_str());
    ImGui::End();
  }
}

}  // namespace

// File > Print marker sheet... keeps the ids as last typed; a panel's button gives its dictionary, and twelve ids
// from its first. Into the user's own folder, never the working folder (which may be the source tree or read-only).
void App::open_sheet_dialog(const ui::OpenSheetDialog& r) {
  Dialogs::Sheet& sheet = dialogs.sheet;
  sheet.opening = true;
  sheet.dictionary = settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : settings.dictionaries[0];
  if (!r.dictionary.empty()) {
    sheet.dictionary = r.dictionary;
    int last = r.first_id + 11;
    std::string err;
    if (const auto d = dictionary_by_name(sheet.dictionary, &err)) last = std::min(last, d->size() - 1);
    std::snprintf(sheet.ids, sizeof sheet.ids, "%d-%d", r.first_id, last);
  }
  const std::string path = status.config_dir + "/marker-sheets/" + sheet.dictionary + ".pdf";
  std::snprintf(sheet.path, sizeof sheet.path, "%s", path.c_str());
}

void App::draw_dialogs(ui::Context& ctx) {
  dialogs.modal.clear();
  draw_browsers(*this, ctx);
  draw_unsaved_question(*this);
  draw_sheet_dialog(*this, ctx);
  draw_export_dialog(ctx);   // File > Export... (ui/export_requests.cpp)
  dialogs.answer.reset();    // an answer given while no dialog asked is a click on nothing
  draw_help_windows(dialogs, ctx.scale, status.config_dir);
}

}  // namespace arwb
