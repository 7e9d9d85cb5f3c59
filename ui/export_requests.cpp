// [SECTION] Index
//   Export dialog  File > Export...: title, marker size, calibration, where; Check shows the self-test
//   Requests       the check and the write on threads of their own; players verified, started and waited for
//   Polling        finished checks and writes, the players' messages, into the log
// The paper's Code Generator in the workbench (bundle/bundle.hpp does the work, as for `arwb export`). The dialog
// does no I/O: Check and Export are requests, carried out off the UI thread, and the dialog shows the result.
#include "ui/app.hpp"

#include "base/data_dirs.hpp"
#include "base/decimals.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <thread>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace arwb {

namespace {

namespace fs = std::filesystem;

template <typename T>
bool ready(const std::future<T>& f) {
  return f.valid() && f.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

// Runs on a thread of its own: the bundle verified as the player will verify it (so a refusal reaches the
// workbench's log, naming the entry), then `arwb play BUNDLE` started as a separate process and waited for, so
// its end is logged and it leaves no zombie. The workbench goes on meanwhile; quitting it leaves the player running.
void play_in_background(std::shared_ptr<Players> players, std::string path, std::vector<std::string> more) {
  auto say = [&](LogLevel level, const std::string& text) {
    std::lock_guard lock(players->mutex);
    players->messages.emplace_back(level, text);
  };
  auto end = [&](bool refused, int code) {
    std::lock_guard lock(players->mutex);
    --players->running;
    if (refused) ++players->refused;
    else {
      ++players->ended;
      players->exit_codes.push_back(code);
    }
  };
  {
    Result<bundle::OpenedBundle> opened = bundle::open_bundle(path);   // removed again at the end of this block
    if (!opened) {
      say(LogLevel::error, "play: refused: " + opened.error());
      return end(true, 1);
    }
  }
  std::vector<std::string> args = {"arwb", "play", path};
  args.insert(args.end(), more.begin(), more.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  // This very program, whatever it is called or wherever it was started from.
  const int err = posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ);
  if (err != 0) {
    say(LogLevel::error, "play: cannot start the player: " + std::string(std::strerror(err)));
    return end(true, 1);
  }
  {
    std::lock_guard lock(players->mutex);
    ++players->started;
  }
  say(LogLevel::info, "play: started the player on " + path + " (process " + std::to_string(pid) + ")");
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  say(code == 0 ? LogLevel::info : LogLevel::warning,
      "play: the player on " + path + " ended (exit status " + std::to_string(code) + ")");
  end(false, code);
}

}  // namespace

// The export's messages name `arwb export`'s options (--out, --calib, --force, ...), which mean nothing in this
// dialog: each is said as the field or checkbox it is here. Only the wording changes; bundle/ stays the command
// line's.
std::string export_window_wording(std::string text) {
  auto starts = [&](std::string_view p) { return text.compare(0, p.size(), p) == 0; };
  auto replace_all = [&](std::string_view from, std::string_view to) {
    for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
      text.replace(at, from.size(), to);
  };
  if (starts("no --calib:")) text = "no calibration:" + text.substr(std::string_view("no --calib:").size());
  else if (starts("--out: ")) text = "where to export: " + text.substr(7);
  else if (starts("--out ")) text = text.substr(6);   // the path itself, as in the field
  else if (starts("--calib ")) text = "the calibration " + text.substr(8);
  else if (starts("--marker-size-mm")) text = "the marker size" + text.substr(16);
  else if (starts("--title")) text = "the title" + text.substr(7);
  else if (starts("--scene: ")) text = "the scene: " + text.substr(9);
  replace_all("add --force to replace it", "tick 'replace an existing bundle there' to replace it");
  replace_all("--force", "'replace an existing bundle there'");
  replace_all("--web: ", "the web page for phones: ");
  replace_all("--convert-for-phones: ", "converting for phones: ");
  replace_all("--convert-for-phones makes", "'convert what phones cannot play' makes");
  return text;
}

bundle::ExportOptions App::export_options() const {
  bundle::ExportOptions o;
  o.scene = frame ? frame->scene.file : "";
  o.out = export_dialog.out;
  o.title = export_dialog.title;
  o.marker_size_mm = export_dialog.size_mm;
  if (export_dialog.use_calibration) o.calibration = opt.engine.calibration_file;
  o.force = export_dialog.force;
  if (export_dialog.web) o.web_site = data_dirs().web;
  o.convert_for_phones = export_dialog.web && export_dialog.convert_for_phones;
  return o;
}

// [SECTION] Export dialog
void App::open_export_dialog(const std::string& out) {
  ExportDialog& d = export_dialog;
  d.opening = true;
  d.error.clear();
  d.written.clear();
  const std::string scene = frame ? frame->scene.file : "";
  const std::string stem = scene.empty() ? "bundle" : fs::path(scene).stem().string();
  if (d.title[0] == 0) std::snprintf(d.title, sizeof d.title, "%s", stem.c_str());
  // Into the user's own folder by default, never the working folder (which may be the source tree).
  const std::string path = !out.empty() ? out : status.config_dir + "/bundles/" + stem + ".arwb";
  std::snprintf(d.out, sizeof d.out, "%s", path.c_str());
}

void App::draw_export_dialog(ui::Context& ctx) {
  ExportDialog& d = export_dialog;
  if (d.opening) {
    ImGui::OpenPopup("Export bundle");
    d.opening = false;
  }
  ImGui::SetNextWindowPos(ImGui::GetMainViewport()->GetCenter(), ImGuiCond_Appearing, {0.5f, 0.5f});
  if (!ImGui::BeginPopupModal("Export bundle", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) return;
  dialogs.modal = "Export bundle";
  const std::optional<ui::DialogButton> a = std::exchange(dialogs.answer, std::nullopt);
  const float w = 420 * ctx.scale;
  const std::string scene = frame ? frame->scene.file : "";
  ImGui::PushTextWrapPos(w * 1.6f);
  if (scene.empty()) ImGui::TextColored({1, 0.6f, 0.3f, 1}, "No scene is loaded: File > Open scene... first.");
  else ImGui::Text("Scene: %s", scene.c_str());
  ImGui::PopTextWrapPos();
  ImGui::SetNextItemWidth(w);
  ImGui::InputText("title", d.title, sizeof d.title);
  ImGui::SetNextItemWidth(w);
  ImGui::InputDouble("marker size (mm)", &d.size_mm, 1, 10, "%.1f");
  d.size_mm = std::clamp(d.size_mm, bundle::kMinMarkerSizeMm, bundle::kMaxMarkerSizeMm);
  if (opt.engine.calibration_file.empty()) {
    ImGui::TextDisabled("Calibration: none (the workbench was started without one); the player uses the paper's "
                        "default camera.");
  } else {
    const std::string label = "calibration: " + opt.engine.calibration_file;
    ImGui::Checkbox(label.c_str(), &d.use_calibration);
  }
  ImGui::SetNextItemWidth(w);
  ImGui::InputText("##export_out", d.out, sizeof d.out);
  ImGui::SameLine();
  if (ImGui::Button("Browse...") || a == ui::DialogButton::browse) {
    const fs::path p(d.out);
    ui::open_browser(ctx, d.browser, ui::FileKind::bundle, "Export the bundle as", p.parent_path().string(), true,
                     p.filename().string());
  }
  std::string chosen;
  if (ui::draw_file_browser(ctx, d.browser, &chosen)) std::snprintf(d.out, sizeof d.out, "%s", chosen.c_str());
  if (d.browser.visible) dialogs.modal = "File browser";
  ImGui::TextDisabled("A folder, or a zip when the name ends in .arwb or .zip.");
  ImGui::Checkbox("replace an existing bundle there", &d.force);
  ImGui::Checkbox("add a web page for phones (index.html: the bundle's detector in the browser)", &d.web);
  ImGui::BeginDisabled(!d.web);
  ImGui::Checkbox("convert what phones cannot play (pictures to PNG; videos to MP4/H.264 with ffmpeg)",
                  &d.convert_for_phones);
  ImGui::EndDisabled();

  const bool busy = d.checking.valid() || d.writing.valid();
  ImGui::BeginDisabled(busy || scene.empty());
  if (ImGui::Button("Check") || (a == ui::DialogButton::check && !busy)) requests.push_back(ui::CheckExport{});
  ImGui::SameLine();
  if (ImGui::Button("Export") || (a == ui::DialogButton::export_bundle && !busy)) requests.push_back(ui::WriteExport{});
  ImGui::EndDisabled();
  ImGui::SameLine();
  if (ImGui::Button("Close") || a == ui::DialogButton::cancel) ImGui::CloseCurrentPopup();
  if (busy) {
    ImGui::SameLine();
    ImGui::TextDisabled(d.writing.valid() ? "writing..." : "checking...");
  }
  ImGui::PushTextWrapPos(w * 1.6f);
  if (!d.error.empty()) ImGui::TextColored({1, 0.35f, 0.3f, 1}, "%s", d.error.c_str());
  if (!d.written.empty()) ImGui::TextColored({0.5f, 0.9f, 0.5f, 1}, "Written: %s", d.written.c_str());
  draw_serve_section(ctx, w * 1.6f);
  if (d.plan) {
    const bundle::Manifest& m = d.plan->manifest;
    std::uint64_t bytes = 0;
    for (const bundle::BundleFile& f : m.files) bytes += f.size;
    ImGui::Text("%s: %zu markers of %s at %.0f mm, %zu files, %.1f KiB; self-test %s", m.title.c_str(), m.ids.size(),
                m.dictionary.c_str(), m.marker_size_mm, m.files.size(), double(bytes) / 1024,
                m.self_test_passed ? "passed" : "FAILED");
    for (const std::string& warning : d.plan->warnings)
      ImGui::TextColored({1, 0.8f, 0.3f, 1}, "warning: %s", export_window_wording(warning).c_str());
  }
  ImGui::PopTextWrapPos();
  if (d.plan && ImGui::BeginTable("##self_test", 6,
                                  ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_ScrollY |
                                      ImGuiTableFlags_SizingFixedFit,
                                  {w * 1.6f, std::min(12.0f, float(d.plan->manifest.self_test.size()) + 1.5f) *
                                                 ImGui::GetTextLineHeightWithSpacing()})) {
    ImGui::TableSetupScrollFreeze(0, 1);
    for (const char* h : {"id", "line", "media", "detected", "fired", "why"}) ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (const bundle::SelfTestRow& r : d.plan->manifest.self_test) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::Text("%d", r.id);
      ImGui::TableNextColumn();
      ImGui::Text("%d", r.mapping_line);
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(r.media.c_str());
      const ImVec4 good{0.5f, 0.9f, 0.5f, 1}, bad{1, 0.35f, 0.3f, 1};
      ImGui::TableNextColumn();
      ImGui::TextColored(r.detected ? good : bad, "%s", r.detected ? "yes" : "no");
      ImGui::TableNextColumn();
      ImGui::TextColored(r.fired ? good : bad, "%s", r.fired ? "yes" : "no");
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(r.detail.c_str());
    }
    ImGui::EndTable();
  }
  ImGui::EndPopup();
}

// [SECTION] Requests
// Check (write false) or Export: the check runs on a thread of its own, and Export writes when it passes.
void App::start_export(bool write) {
  ExportDialog& d = export_dialog;
  if (d.checking.valid() || d.writing.valid()) return warn("export: a check or an export is running already");
  const bundle::ExportOptions o = export_options();
  if (o.scene.empty()) {
    d.error = "no scene is loaded: File > Open scene... first";
    return error("export: " + d.error);
  }
  d.error.clear();
  d.written.clear();
  d.write_after = write;
  // Loading the scene, drawing and detecting each marker: seconds, never on the UI thread.
  // The folder the bundle goes into is made first (the default one, in the user's config folder, may not
  // exist yet); the bundle itself is written only by Export.
  d.checking = std::async(std::launch::async, [o] {
    std::error_code ec;
    if (const fs::path parent = fs::path(o.out).parent_path(); !parent.empty()) fs::create_directories(parent, ec);
    return bundle::plan_export(o);
  });
  info(std::string("export: ") + (d.write_after ? "checking, then writing " : "checking ") + o.out);
}

// With `out`, what File > Export...'s Export button does with the dialog's values, the dialog unseen.
void App::write_export(const std::optional<std::string>& out) {
  if (out) {
    open_export_dialog(*out);
    export_dialog.opening = false;
  }
  start_export(true);
}

void App::play_bundle(const std::string& bundle) {
  std::error_code ec;
  const std::string path = fs::absolute(bundle, ec).lexically_normal().string();
  {
    std::lock_guard lock(players->mutex);
    ++players->running;
  }
  info("play: verifying " + path);
  std::thread(play_in_background, players, path, play_args).detach();
  status.recent.add(ui::FileKind::bundle, path);
  save_recent();
}

// [SECTION] Polling
void App::poll_export() {
  ExportDialog& d = export_dialog;
  if (ready(d.checking)) {
    Result<bundle::ExportPlan> plan = d.checking.get();
    if (!plan) {
      d.error = export_window_wording(plan.error());
      d.plan.reset();
      error("export: " + d.error);
    } else {
      d.plan = std::make_shared<const bundle::ExportPlan>(std::move(*plan));
      const bundle::Manifest& m = d.plan->manifest;
      info("export: checked " + m.title + ": " + std::to_string(m.ids.size()) + " markers, self-test " +
           (m.self_test_passed ? "passed" : "failed"));
      for (const std::string& w : d.plan->warnings) warn("export: " + export_window_wording(w));
      if (d.write_after) {
        std::shared_ptr<const bundle::ExportPlan> p = d.plan;
        d.writing = std::async(std::launch::async, [p] { return bundle::write_export(*p); });
      }
    }
  }
  if (ready(d.writing)) {
    const Status s = d.writing.get();
    if (s) {
      d.written = d.plan ? d.plan->options.out : "";
      d.written_web = d.plan && !d.plan->options.web_site.empty();
      // A server holds the copy it verified at its start: not this export's. One still starting is dropped too.
      if (d.server) serve_bundle(false);
      d.serve_stale = d.serve_starting.valid();
      note_status("export: wrote the bundle " + d.written + " (play it with arwb play or File > Play bundle...)");
    } else {
      d.error = export_window_wording(s.error());
      error("export: " + d.error);
    }
  }
  poll_serve();
  std::vector<std::pair<LogLevel, std::string>> messages;
  {
    std::lock_guard lock(players->mutex);
    messages.swap(players->messages);
  }
  for (const auto& [level, text] : messages) {
    if (level == LogLevel::info) note_status(text);
    else log.add(level, text);
  }
}

}  // namespace arwb
