// [SECTION] Index
//   State        what the player keeps between frames
//   Requests     what a key or an --actions step (overlay, stage, click, fullscreen, quit) asks for
//   Drawing      the picture with black bars, the set-up overlay
//   Frame loop   window, keys, clicks, screenshot, stats at exit
#include "ui/player.hpp"

#include "base/decimals.hpp"
#include "base/result.hpp"
#include "media/open_url.hpp"
#include "render/compositor.hpp"
#include "render/texture.hpp"
#include "ui/gl_window.hpp"
#include "ui/request.hpp"
#include "workbench/actions.hpp"
#include "workbench/engine.hpp"
#include "workbench/log.hpp"
#include "base/json_text.hpp"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <variant>
#include <vector>

namespace arwb {

namespace {

using Clock = std::chrono::steady_clock;

ImTextureID texture_id(unsigned id) { return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(id)); }

// What the player can be asked to do, by its keys or an --actions step; the workbench's requests where the two
// windows do the same (ui/request.hpp).
struct ShowOverlay {
  std::optional<bool> on;   // none: the other way round
};
struct CycleStage {   // to the next (+1) or previous (-1) stage with a picture on this frame
  int delta = 1;
};
struct PlayerFullscreen {
  bool on = true;
};
using PlayerRequest =
    std::variant<ShowOverlay, CycleStage, ui::ShowStage, ui::ClickLiveView, PlayerFullscreen, ui::Quit>;

// [SECTION] State
struct Player {
  const PlayerOptions& opt;
  Clock::time_point t0 = Clock::now();
  Log log{t0};
  std::vector<LogEntry> log_copy;
  uint64_t log_seen = 0;
  std::unique_ptr<Engine> engine;
  std::unique_ptr<render::Compositor> compositor;
  render::TextureCache textures;
  std::shared_ptr<const Frame> frame;
  GLFWwindow* window = nullptr;
  bool fullscreen = false;
  bool overlay = false;           // the set-up overlay (F1, I)
  int stage = -1;                 // the overlay's stage picture: -1 the input image, else a Stage
  std::string dictionary;         // what the detector reads now
  uint64_t scene_generation = 0;
  cv::Rect2d picture;             // where the image was drawn in the window, in window pixels
  double ui_fps = 0;
  std::deque<double> frame_times;
  int composite_failures = 0;
  std::vector<std::string> opened;   // links opened by clicks, for --stats

  explicit Player(const PlayerOptions& o) : opt(o) {}

  void info(const std::string& s) { log.add(LogLevel::info, s); }
  void warn(const std::string& s) { log.add(LogLevel::warning, s); }

  // Full screen on the primary monitor at its own mode, or back to a window of the size asked for.
  void set_fullscreen(bool on) {
    if (const std::string problem = ui::set_fullscreen(window, on, opt.window); !problem.empty())
      return warn("full screen: " + problem);
    fullscreen = ui::is_fullscreen(window);
  }

  // The stage after (or before) the current one that has a picture on this frame; -1 is the input image.
  void cycle_stage(int delta) {
    for (int tries = 0; tries <= kStageCount; ++tries) {
      stage += delta;
      if (stage >= kStageCount) stage = -1;
      if (stage < -1) stage = kStageCount - 1;
      if (stage < 0 || !frame || !frame->thumbs[static_cast<size_t>(stage)].empty()) return;
    }
  }

  // A click on image pixel p: the web card under it opens, as in the workbench's live view.
  void click(cv::Point2d p) {
    const int hit = frame ? overlay_at(frame->overlays, p, true) : -1;
    if (hit < 0) return;
    const std::string& url = frame->overlays[static_cast<size_t>(hit)].media.url;
    const std::string err = media::open_url(url);
    if (err.empty()) {
      info("opening " + url + " in the browser");
      opened.push_back(url);
    } else {
      log.add(LogLevel::error, "cannot open " + url + ": " + err);
    }
  }

  // A newly (re)loaded scene that names a dictionary switches the detector to it, as the workbench does.
  void sync_scene() {
    if (!frame || frame->scene.generation == scene_generation) return;
    scene_generation = frame->scene.generation;
    const std::string& d = frame->scene.dictionary;
    if (!d.empty() && d != dictionary) {
      dictionary = d;
      engine->set_dictionaries({d});
    }
  }

  void carry_out(const PlayerRequest& request);
  void run_step(const Action& a);
  void draw_picture(ImTextureID tex, cv::Size image, ImVec2 window_size);
  void draw_overlay();
  void handle_input();
};

// [SECTION] Requests
// An --actions step as the request it makes, or why it cannot be one, naming the verb and the argument.
Result<PlayerRequest> player_request(const Action& a) {
  const bool on_off = a.arg == "on" || a.arg == "off";
  if (a.verb == "overlay") {
    if (a.arg.empty()) return PlayerRequest(ShowOverlay{});
    if (on_off) return PlayerRequest(ShowOverlay{a.arg == "on"});
    return fail("--actions overlay: on or off, not '" + a.arg + "'");
  }
  if (a.verb == "stage") {
    Stage s;
    if (a.arg == "next" || a.arg == "previous") return PlayerRequest(CycleStage{a.arg == "next" ? 1 : -1});
    if (a.arg == "input") return PlayerRequest(ui::ShowStage{});
    if (stage_from_name(a.arg, &s)) return PlayerRequest(ui::ShowStage{s});
    return fail("--actions: no stage '" + a.arg + "'");
  }
  if (a.verb == "click") {
    double x = 0, y = 0;
    if (std::sscanf(a.arg.c_str(), "%lf,%lf", &x, &y) != 2) return fail("--actions click: X,Y in image pixels, not '" + a.arg + "'");
    return PlayerRequest(ui::ClickLiveView{{x, y}});
  }
  if (a.verb == "fullscreen") {
    if (!on_off) return fail("--actions fullscreen: on or off, not '" + a.arg + "'");
    return PlayerRequest(PlayerFullscreen{a.arg == "on"});
  }
  if (a.verb == "quit") return PlayerRequest(ui::Quit{});
  return fail("--actions: the player has no step '" + a.verb + "' (overlay, stage, click, fullscreen, quit)");
}

void Player::carry_out(const PlayerRequest& request) {
  std::visit(ui::Overloaded{
                 [&](const ShowOverlay& r) { overlay = r.on.value_or(!overlay); },
                 [&](const CycleStage& r) { cycle_stage(r.delta); },
                 [&](const ui::ShowStage& r) { stage = r.stage ? static_cast<int>(*r.stage) : -1; },
                 [&](const ui::ClickLiveView& r) { click(r.at); },
                 [&](const PlayerFullscreen& r) { set_fullscreen(r.on); },
                 [&](const ui::Quit&) { glfwSetWindowShouldClose(window, 1); },
             },
             request);
}

// An --actions step carried out, or why it cannot be said in the log.
void Player::run_step(const Action& a) {
  const Result<PlayerRequest> r = player_request(a);
  if (r) carry_out(*r);
  else warn(r.error());
}

// [SECTION] Drawing
// The image as large as the window allows with its aspect kept; the rest stays black.
void Player::draw_picture(ImTextureID tex, cv::Size image, ImVec2 win) {
  if (image.width <= 0 || image.height <= 0) return;
  const double s = std::min(double(win.x) / image.width, double(win.y) / image.height);
  const double w = image.width * s, h = image.height * s;
  picture = {std::floor((win.x - w) / 2), std::floor((win.y - h) / 2), w, h};
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  dl->AddImage(tex, {float(picture.x), float(picture.y)}, {float(picture.x + w), float(picture.y + h)});
}

// For whoever sets the installation up: what is running and how well, the markers seen, the newest problem, and
// one stage of the pipeline as a thumbnail. Small, in a corner, over the picture.
void Player::draw_overlay() {
  const float pad = 10;
  ImGui::SetNextWindowPos({pad, pad});
  ImGui::SetNextWindowBgAlpha(0.75f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove;
  ImGui::Begin("##player_overlay", nullptr, flags);
  ImGui::TextUnformatted(opt.title.empty() ? "(untitled)" : opt.title.c_str());
  ImGui::TextDisabled("%s", engine->source().text().c_str());
  ImGui::Text("%.0f fps shown, %.0f fps detected", ui_fps, engine->detect_fps());
  std::string ids;
  if (frame)
    for (const Marker& m : frame->trace.markers) {
      if (!ids.empty()) ids += ' ';
      ids += std::to_string(m.id);
    }
  ImGui::Text("markers: %s", ids.empty() ? "none in view" : ids.c_str());
  if (frame) ImGui::Text("media shown: %zu", frame->overlays.size());
  // The newest error (a scene's runtime error, media that failed), one line in red.
  for (auto it = log_copy.rbegin(); it != log_copy.rend(); ++it) {
    if (it->level != LogLevel::error) continue;
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 28);
    ImGui::TextColored(ImVec4(1, 0.35f, 0.3f, 1), "%s", it->text.c_str());
    ImGui::PopTextWrapPos();
    break;
  }
  if (frame) {
    const cv::Mat& pic = stage < 0 ? frame->image_thumb : frame->thumbs[static_cast<size_t>(stage)];
    const std::string name = stage < 0 ? "input" : std::string(stage_name(static_cast<Stage>(stage)));
    if (!pic.empty()) {
      const render::Texture& t = textures.get("stage", pic, frame->index * (kStageCount + 1) + size_t(stage + 1));
      const float w = 200, h = w * float(pic.rows) / float(std::max(1, pic.cols));
      ImGui::Image(texture_id(t.id()), {w, h});
    }
    ImGui::Text("stage: %s", name.c_str());
  }
  ImGui::TextDisabled("Left/Right stage, F1 hide, Esc %s, q quit", fullscreen ? "window" : "quit");
  ImGui::End();
}

// [SECTION] Frame loop
void Player::handle_input() {
  if (ImGui::IsKeyPressed(GLFW_KEY_F1) || ImGui::IsKeyPressed(GLFW_KEY_I)) carry_out(ShowOverlay{});
  if (ImGui::IsKeyPressed(GLFW_KEY_RIGHT)) carry_out(CycleStage{1});
  if (ImGui::IsKeyPressed(GLFW_KEY_LEFT)) carry_out(CycleStage{-1});
  if (ImGui::IsKeyPressed(GLFW_KEY_F11)) carry_out(PlayerFullscreen{!fullscreen});
  if (ImGui::IsKeyPressed(GLFW_KEY_Q)) carry_out(ui::Quit{});
  if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE)) carry_out(fullscreen ? PlayerRequest(PlayerFullscreen{false}) : ui::Quit{});
  // A click on the picture (not on the overlay) in image pixels.
  if (ImGui::IsMouseClicked(ImGuiMouseButton_Left) && !ImGui::GetIO().WantCaptureMouse && frame && picture.width > 0) {
    const ImVec2 m = ImGui::GetMousePos();
    if (picture.contains({m.x, m.y})) {
      const double s = picture.width / frame->image.cols;
      carry_out(ui::ClickLiveView{{(m.x - picture.x) / s, (m.y - picture.y) / s}});
    }
  }
}

}  // namespace

int run_player(const PlayerOptions& options) {
  Player p(options);
  p.log.verbose = options.verbose;
  std::vector<Action> actions;
  {
    std::string err;
    if (!parse_actions(options.actions, &actions, &err, player_action_verbs())) {
      std::fprintf(stderr, "arwb play: %s\n", err.c_str());
      return 2;
    }
  }
  const std::string title = (options.title.empty() ? std::string("ArUco Workbench") : options.title) + " - arwb play";
  ui::GlWindow gl;
  if (!ui::open_gl_window("arwb play", title.c_str(), options.window, options.fullscreen, &gl)) return 1;
  p.window = gl.window;
  p.fullscreen = options.fullscreen && glfwGetWindowMonitor(gl.window) != nullptr;
  // The overlay's text a little larger than the workbench's, to be read from a step back.
  if (auto it = gl.fonts_large.find(20); it != gl.fonts_large.end() && it->second) ImGui::GetIO().FontDefault = it->second;
  ImGui::GetStyle().Colors[ImGuiCol_WindowBg].w = 0.75f;

  p.dictionary = options.engine.dictionaries.empty() ? "" : options.engine.dictionaries.front();
  p.engine = std::make_unique<Engine>(options.engine, [&p, &options](int level, std::string m) {
    if (!options.private_dir.empty()) {
      const std::string from = options.private_dir + "/", to = options.bundle + "/";
      for (size_t at = m.find(from); at != std::string::npos; at = m.find(from, at + to.size())) m.replace(at, from.size(), to);
    }
    p.log.add(level == 0 ? LogLevel::info : (level == 1 ? LogLevel::warning : LogLevel::error), m);
  });
  // Without a camera, the synthetic source shows the bundle's own markers in its dictionary.
  if (!options.ids.empty()) {
    SyntheticControls c;
    c.ids = options.ids;
    if (!p.dictionary.empty()) c.dict = p.dictionary;
    c.markers = static_cast<int>(std::min<size_t>(options.ids.size(), 8));
    p.engine->set_synthetic(c);
  }
  p.engine->start();
  p.compositor = std::make_unique<render::Compositor>(4);

  const double ui_period = 1.0 / 60.0;
  int ui_frames = 0;
  size_t next_action = 0;
  const auto loop_start = Clock::now();
  auto last = Clock::now();
  while (!glfwWindowShouldClose(gl.window)) {
    glfwPollEvents();
    p.frame = p.engine->latest();
    // Before a scripted screenshot, make sure there is a finished frame to show.
    if (!p.frame && options.frames > 0) p.frame = p.engine->wait_newer(0, 5.0);
    p.log.sync(p.log_copy, p.log_seen);
    p.sync_scene();
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    while (next_action < actions.size() && actions[next_action].frame <= ui_frames) p.run_step(actions[next_action++]);
    p.handle_input();
    const ImVec2 win = ImGui::GetIO().DisplaySize;
    if (p.frame && !p.frame->image.empty()) {
      // The scene's media on the frame: drawn every UI frame, so a video's texture moves on between detections.
      if (p.composite_failures == 0 && p.compositor->draw(p.frame->image, p.frame->index, p.frame->overlays)) {
        p.draw_picture(texture_id(p.compositor->texture()), p.compositor->size(), win);
      } else {
        if (p.composite_failures++ == 0) p.log.add(LogLevel::error, "media: " + p.compositor->error());
        const render::Texture& t = p.textures.get("frame", p.frame->image, p.frame->index, false);
        p.draw_picture(texture_id(t.id()), p.frame->image.size(), win);
      }
    }
    if (p.overlay) p.draw_overlay();
    ui::present_imgui_frame(gl);
    p.textures.end_frame();
    ++ui_frames;
    const bool last_frame = options.frames > 0 && ui_frames >= options.frames;
    if (!options.screenshot.empty() && (last_frame || glfwWindowShouldClose(gl.window))) {
      std::string why;
      if (ui::save_window_image(gl.window, options.screenshot, &why)) p.info("screenshot: " + options.screenshot);
      else p.log.add(LogLevel::error, "screenshot: " + why);
    }
    glfwSwapBuffers(gl.window);

    const auto now = Clock::now();
    p.frame_times.push_back(std::chrono::duration<double>(now - loop_start).count());
    while (p.frame_times.size() > 1 && p.frame_times.front() < p.frame_times.back() - 1.0) p.frame_times.pop_front();
    if (p.frame_times.size() > 1)
      p.ui_fps = double(p.frame_times.size() - 1) / (p.frame_times.back() - p.frame_times.front());
    if (last_frame) break;
    const double spent = std::chrono::duration<double>(now - last).count();
    if (spent < ui_period) std::this_thread::sleep_for(std::chrono::duration<double>(ui_period - spent));
    last = Clock::now();
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - loop_start).count();
  const uint64_t detected = p.engine->frames_done();
  const bool worker_stopped = p.engine->stop(0.5);
  if (options.stats) {
    using Json = nlohmann::ordered_json;
    Json s = {{"title", options.title},
              {"frames", ui_frames},
              {"ui_fps", round_decimals(elapsed > 0 ? ui_frames / elapsed : 0, 1)},
              {"detect_fps", round_decimals(elapsed > 0 ? double(detected) / elapsed : 0, 1)},
              {"detected", detected},
              {"source", p.engine->source().text()},
              {"dictionary", p.dictionary},
              {"fullscreen", p.fullscreen},
              {"overlay", p.overlay},
              {"stage", p.stage < 0 ? std::string("input") : std::string(stage_name(static_cast<Stage>(p.stage)))}};
    Json ids = Json::array();
    if (p.frame)
      for (const Marker& m : p.frame->trace.markers) ids.push_back(m.id);
    s["markers"] = ids.size();
    s["marker_ids"] = ids;
    // Each media drawn on the last frame: its marker and its quad in image pixels, and where the image itself was
    // drawn in the window (x, y, w, h), so a test can find the media's pixels in the screenshot.
    Json overlays = Json::array();
    if (p.frame)
      for (const Overlay& o : p.frame->overlays) {
        Json quad = Json::array();
        for (const cv::Point2d& c : o.quad.corners) quad.push_back({round_decimals(c.x, 2), round_decimals(c.y, 2)});
        overlays.push_back({{"marker", o.marker_id}, {"media", o.media.describe()}, {"quad", quad}});
      }
    s["overlays"] = overlays.size();
    s["media"] = overlays;
    s["image_size"] = p.frame ? Json{p.frame->image.cols, p.frame->image.rows} : Json::array();
    s["picture"] = {round_decimals(p.picture.x, 2), round_decimals(p.picture.y, 2), round_decimals(p.picture.width, 2),
                    round_decimals(p.picture.height, 2)};
    s["scene"] = p.frame ? p.frame->scene.file : "";
    s["scene_ok"] = p.frame && p.frame->scene.ok;
    s["scene_mappings"] = Json::array();
    if (p.frame)
      for (const MappingRow& r : p.frame->scene.mappings)
        s["scene_mappings"].push_back({{"ids", r.ids}, {"health", mapping_health_name(r.health)}, {"reason", r.reason}});
    s["calibration"] = p.frame && p.frame->loaded_calibration ? p.frame->loaded_calibration->source : "";
    s["pose_camera"] = p.frame ? (p.frame->pose_camera.assumed ? "assumed" : p.frame->pose_camera.source) : "";
    s["pose_marker_side"] = p.frame ? p.frame->pose_marker_side : 1.0;
    p.log.sync(p.log_copy, p.log_seen);
    int errors = 0;
    for (const LogEntry& e : p.log_copy) errors += e.level == LogLevel::error;
    s["log_errors"] = errors;
    s["opened"] = p.opened;
    std::printf("%s\n", json_text(s).c_str());
  }
  if (!worker_stopped) {
    std::fprintf(stderr, "arwb play: %s\n", p.engine->stuck_message(0.5).c_str());
    std::fflush(stdout);
    std::fflush(stderr);
    std::_Exit(0);
  }
  p.textures = render::TextureCache{};
  p.compositor.reset();
  ui::close_gl_window(gl);
  return 0;
}

}  // namespace arwb
