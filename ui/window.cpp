// [SECTION] Index
//   Settings     the layout file, panel visibility kept between runs
//   Requests     what panels asked for: snapshots, presets, sweeps, sheets
//   Frame loop   window, ImGui, panels, forwarding edits to the engine, stats
#include "ui/window.hpp"

#include "base/files.hpp"
#include "workbench/actions.hpp"
#include "workbench/log.hpp"

#include "synth/marker_sheet.hpp"
#include "workbench/snapshot.hpp"
#include "detect/diagnose.hpp"
#include "base/decimals.hpp"
#include "teach/tour.hpp"
#include "media/open_url.hpp"
#include "render/compositor.hpp"
#include "render/texture.hpp"
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <cerrno>
#include <filesystem>
#include <future>
#include <map>
#include <mutex>
#include <thread>

#ifndef ARWB_ASSETS_DIR
#define ARWB_ASSETS_DIR "assets"
#endif

namespace arwb {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// [SECTION] Settings
std::string default_config_dir() {
  if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return std::string(x) + "/arwb";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.config/arwb";
  return ".arwb";
}

// Panel visibility and presentation mode, saved in the same imgui.ini as the window layout.
ui::View* g_view = nullptr;

void* settings_open(ImGuiContext*, ImGuiSettingsHandler*, const char* name) {
  return std::string_view(name) == "Panels" ? static_cast<void*>(g_view) : nullptr;
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
  buf->appendf("[%s][Panels]\n", h->TypeName);
  for (int i = 0; i < ui::kPanelCount; ++i) {
    buf->appendf("%s=%d\n", ui::panel_key(static_cast<ui::Panel>(i)), g_view->open[static_cast<size_t>(i)] ? 1 : 0);
  }
  buf->append("\n");
}

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

struct App {
  WorkbenchOptions opt;
  Clock::time_point t0 = Clock::now();
  Log log{t0};
  std::unique_ptr<Engine> engine;
  ui::Settings settings, sent;
  ui::View view;
  ui::Status status;
  std::vector<LogEntry> log_copy;
  uint64_t log_seen = 0;
  std::vector<ui::Request> requests;
  std::vector<TourStep> tour;
  render::TextureCache textures;
  std::unique_ptr<render::Compositor> compositor;   // the frame with the scene's media, for the live view
  uint64_t scene_generation = 0;
  double composite_ms = 0;
  int composites = 0;
  std::shared_ptr<const Frame> frame;
  uint64_t region_frame = 0;
  cv::Rect2f region_done{-1, -1, 0, 0};
  // Sweep on its own thread; the UI polls.
  std::future<SweepResult> sweep_future;
  std::atomic<double> sweep_progress{0};
  std::atomic<bool> sweep_cancel{false};
  // Stats
  uint64_t last_frame_index = 0;
  int detected_seen = 0;
  double detect_ms_sum = 0;
  std::array<double, kStageCount> stage_ms_sum{};
  std::map<std::string, std::pair<double, int>> peer_ms;   // name: summed ms, frames
  std::array<int, kStageCount> stage_ms_n{};
  std::deque<double> ui_frame_times;
  ImFont* font_normal = nullptr;
  ImFont* font_large = nullptr;
  ImGuiStyle base_style;
  bool presentation_applied = false;
  double draw_calls = 0, vertices = 0;   // summed over UI frames
  std::array<double, 3> ui_ms{};   // summed: building the panels, rendering them, swapping

  void info(const std::string& s) { log.add(LogLevel::info, s); }
  void warn(const std::string& s) { log.add(LogLevel::warning, s); }
  void error(const std::string& s) { log.add(LogLevel::error, s); }

  void run_action(const Action& a);
  void sync_scene();
  void handle_requests();
  void forward_settings();
  void poll_sweep();
  void update_region();
  void record_stats();
  void draw_menu(GLFWwindow* window);
  void draw_status_bar(float height);
  void set_presentation(bool on);
  bool take_screenshot(const std::string& path, GLFWwindow* window);
};

void App::run_action(const Action& a) {
  ui::Panel p;
  if (a.verb == "open" || a.verb == "close") {
    if (a.arg == "all") {
      view.open.fill(a.verb == "open");
      return;
    }
    if (!ui::panel_from_key(a.arg, &p)) return warn("--actions: no panel '" + a.arg + "'");
    view.open[static_cast<size_t>(p)] = a.verb == "open";
    if (a.verb == "open") ImGui::SetWindowFocus(ui::panel_title(p));
  } else if (a.verb == "source") {
    requests.push_back({ui::RequestKind::open_source, a.arg, 0, {}, {}});
  } else if (a.verb == "freeze" || a.verb == "unfreeze") {
    settings.frozen = a.verb == "freeze";
  } else if (a.verb == "next") {
    requests.push_back({ui::RequestKind::next_frame, "", 0, {}, {}});
  } else if (a.verb == "snapshot") {
    requests.push_back({ui::RequestKind::snapshot, "", 0, {}, {}});
  } else if (a.verb == "stage") {
    Stage s;
    if (a.arg == "input") view.pipeline_stage = -1;
    else if (stage_from_name(a.arg, &s)) view.pipeline_stage = static_cast<int>(s);
    else warn("--actions: no stage '" + a.arg + "'");
  } else if (a.verb == "select") {
    // select=N: candidate N; select=marker: the candidate that became the frame's first marker.
    view.selected_candidate = std::atoi(a.arg.c_str());
    if (a.arg == "marker" && frame) {
      view.selected_candidate = -1;
      for (size_t i = 0; i < frame->trace.candidates.size(); ++i) {
        if (frame->trace.candidates[i].marker == 0) view.selected_candidate = static_cast<int>(i);
      }
    }
    if (view.selected_candidate >= 0) view.open[static_cast<size_t>(ui::Panel::inspector)] = true;
  } else if (a.verb == "region") {
    float x, y, w, h;
    if (std::sscanf(a.arg.c_str(), "%f,%f,%f,%f", &x, &y, &w, &h) == 4 && w > 0 && h > 0) {
      view.region = {x, y, w, h};
      view.has_region = true;
      view.open[static_cast<size_t>(ui::Panel::why)] = true;
    } else {
      warn("--actions: region wants X,Y,W,H, not '" + a.arg + "'");
    }
  } else if (a.verb == "sweep") {
    if (view.has_region) requests.push_back({ui::RequestKind::sweep, "", 0, view.region, {}});
  } else if (a.verb == "tour") {
    view.tour_active = true;
    settings.frozen = true;
    view.open[static_cast<size_t>(ui::Panel::tour)] = true;
    if (!a.arg.empty()) view.tour_step = std::atoi(a.arg.c_str());
  } else if (a.verb == "presentation") {
    set_presentation(!view.presentation);
  } else if (a.verb == "preset") {
    requests.push_back({ui::RequestKind::load_preset, a.arg, 0, {}, {}});
  } else if (a.verb == "scene") {
    requests.push_back({ui::RequestKind::load_scene, a.arg, 0, {}, {}});
  } else if (a.verb == "media") {
    view.show_media = a.arg != "off";
  } else if (a.verb == "click") {
    // A click on the live view at image pixel X,Y: what a user's click on a web card does.
    double x = 0, y = 0;
    if (std::sscanf(a.arg.c_str(), "%lf,%lf", &x, &y) != 2) {
      error("--actions click=" + a.arg + ": expected X,Y in image pixels");
      return;
    }
    const int hit = frame ? overlay_at(frame->overlays, {x, y}, true) : -1;
    if (hit >= 0) requests.push_back({ui::RequestKind::open_url, frame->overlays[size_t(hit)].media.url, 0, {}, {}});
    else info("click " + a.arg + ": no web card there");
  } else if (a.verb == "peers") {
    settings.peer_opencv = settings.peer_apriltag = true;
  }
}

// A newly (re)loaded scene that names a dictionary switches the detector to it, as `arwb render` does.
void App::sync_scene() {
  if (!frame || frame->scene.generation == scene_generation) return;
  scene_generation = frame->scene.generation;
  const std::string& d = frame->scene.dictionary;
  if (!d.empty() && (settings.dictionaries.size() != 1 || settings.dictionaries[0] != d)) {
    settings.dictionaries = {d};
    info("scene: detecting " + d + ", the scene's dictionary");
  }
}

// [SECTION] Requests
void App::handle_requests() {
  std::vector<ui::Request> todo;
  todo.swap(requests);
  for (const ui::Request& r : todo) {
    switch (r.kind) {
      case ui::RequestKind::open_source: {
        SourceSpec spec;
        std::string err;
        if (parse_source_spec(r.text, &spec, &err)) engine->open_source(spec);
        else error(err);
        break;
      }
      case ui::RequestKind::step: engine->step(r.value); break;
      case ui::RequestKind::seek: engine->seek(r.value); break;
      case ui::RequestKind::next_frame: engine->next_frame(); break;
      case ui::RequestKind::snapshot: {
        if (!frame) {
          warn("snapshot: no frame yet");
          break;
        }
        const SnapshotResult s = write_snapshot(opt.snapshot_dir, frame->image, frame->trace, &frame->views);
        if (s.ok) {
          status.last_snapshot = s.dir;
          info("snapshot: " + std::to_string(s.files.size()) + " files in " + s.dir);
        } else {
          error("snapshot: " + s.error);
        }
        break;
      }
      case ui::RequestKind::sweep: {
        if (!frame || sweep_future.valid()) break;
        std::string err;
        std::string list;
        for (const auto& n : settings.dictionaries) list += (list.empty() ? "" : ",") + n;
        auto dicts = parse_dictionaries(list, &err);
        if (!dicts) {
          error("sweep: " + err);
          break;
        }
        status.sweep = {};
        status.sweep.running = true;
        status.sweep.region = r.region;
        sweep_progress = 0;
        sweep_cancel = false;
        std::shared_ptr<const Frame> f = frame;
        Detector det(std::move(*dicts), settings.params);
        sweep_future = std::async(std::launch::async, [this, f, det, region = r.region] {
          return sweep_region(f->image, det, region, [this](double p) { sweep_progress = p; }, &sweep_cancel);
        });
        info("sweep: trying the parameter table on frame " + std::to_string(f->index));
        break;
      }
      case ui::RequestKind::load_preset: {
        std::vector<std::string> errors, notes;
        DetectorParams p = settings.params;
        const bool ok = load_params_yaml(r.text, p, &errors, &notes);
        for (const auto& n : notes) warn("preset: " + n);
        if (ok) {
          settings.params = p;
          info("preset: loaded " + r.text);
        } else {
          for (const auto& e : errors) error("preset: " + e);
          if (errors.empty()) error("preset: cannot load " + r.text);
        }
        break;
      }
      case ui::RequestKind::load_scene: engine->load_scene(r.text); break;
      case ui::RequestKind::save_script: {
        std::string err;
        if (write_file_atomically(r.text, r.payload, &err)) info("saved " + r.text + " (the scene reloads by itself)");
        else error("cannot save " + r.text + ": " + err + "; your text is still in the editor");
        break;
      }
      case ui::RequestKind::open_url: {
        const std::string err = media::open_url(r.text);
        if (err.empty()) info("opening " + r.text + " in the browser");
        else error("cannot open " + r.text + ": " + err);
        break;
      }
      case ui::RequestKind::save_preset: {
        std::string err;
        if (save_params_yaml(r.text, settings.params, &err)) info("preset: saved " + r.text);
        else error("preset: " + err);
        break;
      }
      case ui::RequestKind::marker_sheet: {
        const std::string dict_name = settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : settings.dictionaries[0];
        std::string err;
        auto dict = dictionary_by_name(dict_name, &err);
        if (!dict) {
          error("marker sheet: " + err);
          break;
        }
        std::vector<int> ids;
        for (int i = std::max(0, r.value); i < std::min(dict->size(), std::max(0, r.value) + 12); ++i) ids.push_back(i);
        try {
          const SheetResult s = write_marker_sheet(*dict, ids, 50.0, SheetFormat::pdf, r.text);
          info("marker sheet: " + r.text + " (" + std::to_string(s.pages) + " page(s), 50 mm markers of " + dict_name +
               "); print at 100% and check the 100 mm bar");
        } catch (const std::exception& e) {
          error(std::string("marker sheet: ") + e.what());
        }
        break;
      }
    }
  }
}

void App::forward_settings() {
  if (!(settings.params == sent.params)) engine->set_params(settings.params);
  if (settings.dictionaries != sent.dictionaries) engine->set_dictionaries(settings.dictionaries);
  if (!(settings.acquisition == sent.acquisition)) engine->set_acquisition(settings.acquisition);
  if (!(settings.playback == sent.playback)) engine->set_playback(settings.playback);
  if (!(settings.synthetic == sent.synthetic)) engine->set_synthetic(settings.synthetic);
  if (settings.frozen != sent.frozen) engine->set_frozen(settings.frozen);
  if (settings.peer_opencv != sent.peer_opencv || settings.peer_apriltag != sent.peer_apriltag) {
    engine->set_peers(settings.peer_opencv, settings.peer_apriltag);
  }
  sent = settings;
}

void App::poll_sweep() {
  status.sweep.progress = sweep_progress;
  if (!sweep_future.valid()) return;
  if (sweep_future.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  status.sweep.running = false;
  status.sweep.has_result = true;
  try {
    status.sweep.result = sweep_future.get();
    info("sweep: " + status.sweep.result.message);
  } catch (const std::exception& e) {
    sweep_future = {};
    error(std::string("sweep: ") + e.what());
  }
}

void App::update_region() {
  if (!view.has_region || !frame) return;
  const cv::Rect2f& r = view.region;
  if (frame->index == region_frame && r == region_done) return;
  view.region_report = explain_region(frame->trace, r);
  region_frame = frame->index;
  region_done = r;
}

void App::record_stats() {
  if (!frame || frame->index == last_frame_index) return;
  last_frame_index = frame->index;
  ++detected_seen;
  std::array<float, kStageCount + 1> row{};
  for (const StageRecord& s : frame->trace.stages) {
    const auto i = static_cast<size_t>(s.stage);
    row[i] = static_cast<float>(s.ms);
    stage_ms_sum[i] += s.ms;
    ++stage_ms_n[i];
  }
  row[kStageCount] = static_cast<float>(frame->detect_ms);
  detect_ms_sum += frame->detect_ms;
  for (const PeerDetections& p : frame->peers) {
    if (!p.error.empty()) continue;
    peer_ms[p.name].first += p.ms;
    ++peer_ms[p.name].second;
  }
  status.history.push_back(row);
  while (status.history.size() > 300) status.history.pop_front();
}

void App::set_presentation(bool on) {
  view.presentation = on;
  presentation_applied = on;
  ImGuiStyle& style = ImGui::GetStyle();
  style = base_style;
  if (on) style.ScaleAllSizes(2.0f);
  ImGui::GetIO().FontDefault = on && font_large ? font_large : font_normal;
}

// [SECTION] Frame loop
void App::draw_menu(GLFWwindow* window) {
  if (!ImGui::BeginMainMenuBar()) return;
  if (ImGui::BeginMenu("File")) {
    if (ImGui::MenuItem("Synthetic source")) requests.push_back({ui::RequestKind::open_source, "synthetic", 0, {}, {}});
    if (ImGui::MenuItem("Open source...")) view.open[static_cast<size_t>(ui::Panel::source)] = true;
    if (ImGui::MenuItem("Snapshot", "S")) requests.push_back({ui::RequestKind::snapshot, "", 0, {}, {}});
    if (ImGui::MenuItem("Print marker sheet (PDF)")) {
      requests.push_back({ui::RequestKind::marker_sheet, "marker-sheet.pdf", 0, {}, {}});
    }
    ImGui::Separator();
    if (ImGui::MenuItem("Quit", "Ctrl+Q")) glfwSetWindowShouldClose(window, 1);
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("View")) {
    for (int i = 0; i < ui::kPanelCount; ++i) {
      ImGui::MenuItem(ui::panel_title(static_cast<ui::Panel>(i)), nullptr, &view.open[static_cast<size_t>(i)]);
    }
    ImGui::Separator();
    bool pres = view.presentation;
    if (ImGui::MenuItem("Presentation mode", "F5", &pres)) set_presentation(pres);
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Teach")) {
    if (ImGui::MenuItem("Guided tour", "T")) {
      view.tour_active = true;
      settings.frozen = true;  // a lesson explains one frame; "Next frame" moves on
      view.open[static_cast<size_t>(ui::Panel::tour)] = true;
    }
    ImGui::MenuItem("Freeze frame", "Space", &settings.frozen);
    if (ImGui::MenuItem("Next frame", "N")) requests.push_back({ui::RequestKind::next_frame, "", 0, {}, {}});
    ImGui::EndMenu();
  }
  ImGui::EndMainMenuBar();
}

void App::draw_status_bar(float height) {
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos({vp->Pos.x, vp->Pos.y + vp->Size.y - height});
  ImGui::SetNextWindowSize({vp->Size.x, height});
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                                 ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav |
                                 ImGuiWindowFlags_NoBringToFrontOnFocus;
  ImGui::Begin("##status", nullptr, flags);
  ImGui::Text("%s | UI %.0f fps | detection %.0f fps | %s", status.source.text().c_str(), status.ui_fps, status.detect_fps,
              settings.frozen ? "FROZEN" : "live");
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

bool App::take_screenshot(const std::string& path, GLFWwindow* window) {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window, &w, &h);
  const cv::Mat img = render::read_framebuffer(w, h);
  try {
    if (cv::imwrite(path, img)) {
      info("screenshot: " + path);
      return true;
    }
  } catch (const cv::Exception&) {
  }
  error("screenshot: cannot write " + path);
  return false;
}

void glfw_error(int code, const char* text) { std::fprintf(stderr, "arwb: GLFW error %d: %s\n", code, text); }

}  // namespace

int run_workbench(const WorkbenchOptions& options) {
  App app;
  app.opt = options;
  app.log.verbose = options.verbose;
  std::vector<Action> actions;
  {
    std::string err;
    if (!parse_actions(options.actions, &actions, &err)) {
      std::fprintf(stderr, "arwb: %s\n", err.c_str());
      return 2;
    }
  }
  glfwSetErrorCallback(glfw_error);
  if (!glfwInit()) {
    std::fprintf(stderr, "arwb: cannot open a window (no display? run under xvfb-run, or use `arwb detect`)\n");
    return 1;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWwindow* window = glfwCreateWindow(options.window.width, options.window.height, "ArUco Workbench", nullptr, nullptr);
  if (!window) {
    std::fprintf(stderr, "arwb: cannot create an OpenGL 3.3 window\n");
    glfwTerminate();
    return 1;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(0);  // paced below; vsync under Xvfb is absent anyway

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  const std::string config_dir = options.config_dir.empty() ? default_config_dir() : options.config_dir;
  std::error_code ec;
  fs::create_directories(config_dir, ec);
  const std::string ini_path = config_dir + "/imgui.ini";
  io.IniFilename = nullptr;  // loaded and saved by hand, so a bad path is a message, not a silent loss
  g_view = &app.view;
  ImGuiSettingsHandler handler;
  handler.TypeName = "Arwb";
  handler.TypeHash = ImHashStr("Arwb");
  handler.ReadOpenFn = settings_open;
  handler.ReadLineFn = settings_read_line;
  handler.WriteAllFn = settings_write_all;
  ImGui::GetCurrentContext()->SettingsHandlers.push_back(handler);
  if (fs::exists(ini_path)) ImGui::LoadIniSettingsFromDisk(ini_path.c_str());

  ImGui::StyleColorsDark();
  // Opaque windows: panels opened over others (the scene's, on a first start) stay readable.
  ImGui::GetStyle().Colors[ImGuiCol_WindowBg].w = 1.0f;
  app.base_style = ImGui::GetStyle();
  const char* font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  if (fs::exists(font)) {
    app.font_normal = io.Fonts->AddFontFromFileTTF(font, 15.0f);
    app.font_large = io.Fonts->AddFontFromFileTTF(font, 30.0f);
  }
  if (!app.font_normal) app.font_normal = io.Fonts->AddFontDefault();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
  if (options.presentation) app.set_presentation(true);

  // Tour text.
  {
    const std::string path = options.tour_path.empty() ? std::string(ARWB_ASSETS_DIR) + "/teaching/tour.txt"
                                                        : options.tour_path;
    std::vector<std::string> errors;
    load_tour(path, &app.tour, &errors);
    for (const auto& e : errors) app.warn("tour: " + e);
  }

  app.settings.params = options.engine.params;
  app.settings.dictionaries = options.engine.dictionaries;
  app.settings.acquisition = options.engine.acquisition;
  app.sent = app.settings;
  app.engine = std::make_unique<Engine>(options.engine, [&app](int level, const std::string& m) {
    app.log.add(level == 0 ? LogLevel::info : (level == 1 ? LogLevel::warning : LogLevel::error), m);
  });
  app.engine->start();
  app.status.cameras = list_cameras();
  app.status.assets_dir = ARWB_ASSETS_DIR;
  app.status.scripts_dir = ARWB_SCRIPTS_DIR;
  app.compositor = std::make_unique<render::Compositor>(4);
  if (!options.engine.scene_file.empty()) {
    for (ui::Panel p : {ui::Panel::scene, ui::Panel::console}) app.view.open[static_cast<size_t>(p)] = true;
  }

  const double ui_period = 1.0 / 60.0;
  int ui_frames = 0;
  size_t next_action = 0;
  auto loop_start = Clock::now();
  auto last = Clock::now();
  while (!glfwWindowShouldClose(window)) {
    glfwPollEvents();
    app.frame = app.engine->latest();
    app.status.source = app.engine->source();
    app.status.detect_fps = app.engine->detect_fps();
    app.log.sync(app.log_copy, app.log_seen);
    app.status.log = &app.log_copy;
    app.record_stats();
    app.poll_sweep();
    app.update_region();
    // Before a scripted screenshot, make sure there is a finished frame to show.
    if (!app.frame && options.frames > 0) app.frame = app.engine->wait_newer(0, 5.0);

    // Panels flip these; the font and style change between frames, never inside one.
    if (app.view.presentation != app.presentation_applied) app.set_presentation(app.view.presentation);
    if (!app.view.open[static_cast<size_t>(ui::Panel::tour)]) app.view.tour_active = false;
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    while (next_action < actions.size() && actions[next_action].frame <= ui_frames) {
      app.run_action(actions[next_action++]);
    }
    // Keys (ImGui 1.86 indexes keys by GLFW key code): S snapshot, Space freeze, N next frame, T tour, F5 presentation, Ctrl+Q quit.
    if (!io.WantTextInput) {
      if (ImGui::IsKeyPressed(GLFW_KEY_S) && !io.KeyCtrl) app.requests.push_back({ui::RequestKind::snapshot, "", 0, {}, {}});
      if (ImGui::IsKeyPressed(GLFW_KEY_SPACE)) app.settings.frozen = !app.settings.frozen;
      if (ImGui::IsKeyPressed(GLFW_KEY_N)) app.requests.push_back({ui::RequestKind::next_frame, "", 0, {}, {}});
      if (ImGui::IsKeyPressed(GLFW_KEY_T)) {
        app.view.tour_active = true;
        app.settings.frozen = true;
        app.view.open[static_cast<size_t>(ui::Panel::tour)] = true;
      }
      if (ImGui::IsKeyPressed(GLFW_KEY_F5)) app.set_presentation(!app.view.presentation);
      if (ImGui::IsKeyPressed(GLFW_KEY_Q) && io.KeyCtrl) glfwSetWindowShouldClose(window, 1);
    }
    app.draw_menu(window);
    const float status_h = ImGui::GetFrameHeightWithSpacing() + 4;
    const ImGuiViewport* vp = ImGui::GetMainViewport();
    const float menu_h = ImGui::GetFrameHeight();
    ui::Context ctx{app.frame.get(), app.settings, app.view, app.status, app.requests, app.textures, app.tour,
                    app.view.presentation ? 2.0f : 1.0f, nullptr,
                    [&](ui::Panel p) { default_layout(p, vp->Size, menu_h, status_h); }};
    app.sync_scene();
    // The scene's media on the frame: drawn every UI frame, so a video's texture moves on between detections.
    if (app.frame && app.view.show_media && !app.frame->scene.file.empty()) {
      const auto c0 = Clock::now();
      if (app.compositor->draw(app.frame->image, app.frame->index, app.frame->overlays)) {
        ctx.composite = reinterpret_cast<ImTextureID>(static_cast<intptr_t>(app.compositor->texture()));
        app.composite_ms += std::chrono::duration<double, std::milli>(Clock::now() - c0).count();
        ++app.composites;
      } else if (app.composites >= 0) {
        app.error("media: " + app.compositor->error());
        app.composites = -1;   // said once
      }
    }
    const auto tp0 = Clock::now();
    ui::draw_panels(ctx);
    app.draw_status_bar(status_h);
    ImGui::Render();
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window, &fw, &fh);
    glViewport(0, 0, fw, fh);
    glClearColor(0.08f, 0.08f, 0.1f, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    const auto tp1 = Clock::now();
    {
      const ImDrawData* dd = ImGui::GetDrawData();
      int cmds = 0;
      for (int i = 0; i < dd->CmdListsCount; ++i) cmds += dd->CmdLists[i]->CmdBuffer.Size;
      app.draw_calls += cmds;
      app.vertices += dd->TotalVtxCount;
    }
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glFinish();
    const auto tp2 = Clock::now();
    app.textures.end_frame();
    ++ui_frames;
    const bool last_frame = options.frames > 0 && ui_frames >= options.frames;
    // --screenshot: the last frame drawn, whether the run ends by --frames or by closing the window.
    if (!options.screenshot.empty() && (last_frame || glfwWindowShouldClose(window))) {
      app.take_screenshot(options.screenshot, window);
    }
    glfwSwapBuffers(window);
    const auto tp3 = Clock::now();
    app.ui_ms[0] += std::chrono::duration<double, std::milli>(tp1 - tp0).count();
    app.ui_ms[1] += std::chrono::duration<double, std::milli>(tp2 - tp1).count();
    app.ui_ms[2] += std::chrono::duration<double, std::milli>(tp3 - tp2).count();
    app.handle_requests();
    app.forward_settings();

    // UI pacing and its fps.
    const auto now = Clock::now();
    app.ui_frame_times.push_back(std::chrono::duration<double>(now - loop_start).count());
    while (app.ui_frame_times.size() > 1 && app.ui_frame_times.front() < app.ui_frame_times.back() - 1.0) {
      app.ui_frame_times.pop_front();
    }
    if (app.ui_frame_times.size() > 1) {
      app.status.ui_fps = static_cast<double>(app.ui_frame_times.size() - 1) /
                          (app.ui_frame_times.back() - app.ui_frame_times.front());
    }
    if (last_frame) break;
    const double spent = std::chrono::duration<double>(now - last).count();
    if (spent < ui_period) std::this_thread::sleep_for(std::chrono::duration<double>(ui_period - spent));
    last = Clock::now();
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - loop_start).count();
  if (app.sweep_future.valid()) {
    app.sweep_cancel = true;
    app.sweep_future.wait();
  }
  const uint64_t detected = app.engine->frames_done();
  app.engine->stop();

  // Save the layout (window places, open panels).
  {
    size_t len = 0;
    const char* ini = ImGui::SaveIniSettingsToMemory(&len);
    if (FILE* f = std::fopen(ini_path.c_str(), "wb")) {
      std::fwrite(ini, 1, len, f);
      std::fclose(f);
    } else {
      std::fprintf(stderr, "arwb: cannot save the layout to %s\n", ini_path.c_str());
    }
  }
  if (options.stats) {
    using Json = nlohmann::ordered_json;
    auto per = [](double sum, int n) { return sum / std::max(1, n); };
    Json s = {{"ui_fps", round_decimals(elapsed > 0 ? ui_frames / elapsed : 0, 1)},
              {"detect_fps", round_decimals(elapsed > 0 ? static_cast<double>(detected) / elapsed : 0, 1)},
              {"frames", ui_frames},
              {"detected", detected},
              {"stages", Json::object()}};
    for (int i = 0; i < kStageCount; ++i)
      if (const int n = app.stage_ms_n[static_cast<size_t>(i)])
        s["stages"][std::string(stage_name(static_cast<Stage>(i)))] =
            round_decimals(app.stage_ms_sum[static_cast<size_t>(i)] / n, 3);
    // Detection against the peers on the same frames (when they ran): the same run, the same machine load.
    s["detect_ms"] = round_decimals(per(app.detect_ms_sum, app.detected_seen), 3);
    s["peers_ms"] = Json::object();
    for (const auto& [name, v] : app.peer_ms) s["peers_ms"][name] = round_decimals(per(v.first, v.second), 3);
    s["fps_cap"] = round_decimals(app.settings.acquisition.fps_cap, 1);
    s["overlays"] = app.frame ? app.frame->overlays.size() : 0;
    s["composite_ms"] = round_decimals(per(app.composite_ms, app.composites), 2);
    s["scene"] = app.frame ? app.frame->scene.file : "";
    s["scene_ok"] = app.frame && app.frame->scene.ok;
    s["ui_ms"] = {{"panels", round_decimals(per(app.ui_ms[0], ui_frames), 2)},
                  {"render", round_decimals(per(app.ui_ms[1], ui_frames), 2)},
                  {"swap", round_decimals(per(app.ui_ms[2], ui_frames), 2)},
                  {"draw_calls", std::llround(per(app.draw_calls, ui_frames))},
                  {"vertices", std::llround(per(app.vertices, ui_frames))}};
    s["markers"] = app.frame ? app.frame->trace.markers.size() : 0;
    s["source"] = app.engine->source().text();
    s["problems"] = app.log.problems();
    std::printf("%s\n", s.dump(-1, ' ', false, Json::error_handler_t::replace).c_str());
  }
  app.textures = render::TextureCache{};
  app.compositor.reset();
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return 0;
}

}  // namespace arwb
