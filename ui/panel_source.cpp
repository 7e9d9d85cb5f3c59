// Source: where frames come from (synthetic source, camera, video, image, folder), playback, the paper's
// acquisition step (fps cap and resize), and the synthetic source's sliders.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace arwb::ui {

namespace {

struct SourceViewState : PanelState {
  char path[1024] = "";
  int camera = 0;
  int resolution = 0;  // index into kResolutions
};

void section(const char* title) {
  ImGui::Spacing();
  ImGui::TextDisabled("%s", title);
  ImGui::Separator();
}

constexpr const char* kResolutions[] = {"device default", "640x480", "1280x720", "1920x1080"};
// A width keeps the source's aspect (the height follows); two sides are exact, and squash another aspect.
const cv::Size kSizes[] = {{320, 0}, {640, 0}, {800, 0}, {1280, 0}, {1920, 0}, {640, 480}, {1280, 720}};

void size_label(cv::Size s, char* out, size_t n) {
  if (s.height == 0) std::snprintf(out, n, "%d wide", s.width);
  else if (s.width == 0) std::snprintf(out, n, "%d high", s.height);
  else std::snprintf(out, n, "%dx%d exactly", s.width, s.height);
}

void source_choice(Context& ctx, SourceViewState& st) {
  const SourceSpec& now = ctx.status.source;
  ImGui::TextWrapped("Source: %s", now.text().c_str());
  if (ImGui::Button("Synthetic source")) ctx.request(OpenSource{"synthetic"});
  flow(text_width("(markers moving in 3D, with exact truth)"));
  text_disabled_wrapped("(markers moving in 3D, with exact truth)");

  // Cameras: /dev/videoN found at start.
  ImGui::SetNextItemWidth(110 * ctx.scale);
  const std::string cam_label = "camera:" + std::to_string(st.camera);
  if (ImGui::BeginCombo("##camera", cam_label.c_str())) {
    for (int dev : ctx.status.cameras) {
      const std::string l = "camera:" + std::to_string(dev);
      if (ImGui::Selectable(l.c_str(), dev == st.camera)) st.camera = dev;
    }
    if (ctx.status.cameras.empty()) ImGui::TextDisabled("no /dev/video* found");
    ImGui::EndCombo();
  }
  flow(130 * ctx.scale);
  ImGui::SetNextItemWidth(130 * ctx.scale);
  ImGui::Combo("##res", &st.resolution, kResolutions, IM_ARRAYSIZE(kResolutions));
  flow(button_width("Open camera"));
  if (ImGui::Button("Open camera")) {
    std::string spec = "camera:" + std::to_string(st.camera);
    if (st.resolution > 0) spec += std::string("@") + kResolutions[st.resolution];
    ctx.request(OpenSource{spec});
  }
  if (ctx.status.cameras.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("No camera was found at start.");

  // The field keeps a usable width however narrow the panel: the buttons go to the next line rather than
  // squeezing it to nothing.
  const ImGuiStyle& style = ImGui::GetStyle();
  const float buttons_w = ImGui::CalcTextSize("Open file").x + ImGui::CalcTextSize("Browse...").x +
                          style.FramePadding.x * 4 + style.ItemSpacing.x * 2;
  const float avail = ImGui::GetContentRegionAvail().x;
  const bool one_line = avail - buttons_w >= 160 * ctx.scale;
  ImGui::SetNextItemWidth(one_line ? avail - buttons_w : avail);
  if (ctx.view.focus_field == TextField::source_path) {   // --actions focus=source_path
    ImGui::SetKeyboardFocusHere();
    ctx.view.focus_field = TextField::none;
  }
  const bool enter = ImGui::InputTextWithHint("##path", "video, image or folder path", st.path, sizeof st.path,
                                              ImGuiInputTextFlags_EnterReturnsTrue);
  if (one_line) ImGui::SameLine();
  if ((ImGui::Button("Open file") || enter) && st.path[0] != '\0') ctx.request(OpenSource{st.path});
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("The kind (video, image, folder) is read from the file itself.");
  ImGui::SameLine();
  if (ImGui::Button("Browse...")) ctx.request(Browse{FileKind::source});
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("The file browser: folders, recent sources, favourites.");
}

void playback(Context& ctx) {
  if (!ctx.frame) return;
  const SourceInfo& info = ctx.frame->source;
  if (info.kind != SourceKind::video && info.kind != SourceKind::folder) return;
  Playback& p = ctx.settings.playback;
  section(info.kind == SourceKind::video ? "Playback" : "Images");
  if (ImGui::Button(p.playing ? "Pause" : "Play")) p.playing = !p.playing;
  flow(button_width("< Step"));
  if (ImGui::Button("< Step")) ctx.request(StepFrames{-1});
  flow(button_width("Step >"));
  if (ImGui::Button("Step >")) ctx.request(StepFrames{+1});
  flow(checkbox_width("Loop"));
  ImGui::Checkbox("Loop", &p.loop);
  if (info.kind == SourceKind::video) {
    float speed = static_cast<float>(p.speed);
    fit_item_width(160 * ctx.scale, "speed");
    if (ImGui::SliderFloat("speed", &speed, 0.1f, 8.0f, "%.2fx", ImGuiSliderFlags_Logarithmic)) p.speed = speed;
  }
  if (info.count > 0) {
    int pos = info.position;
    ImGui::SetNextItemWidth(-1);
    if (ImGui::SliderInt("##seek", &pos, 0, info.count - 1, info.kind == SourceKind::video ? "frame %d" : "image %d")) {
      ctx.request(Seek{pos});
    }
  }
  if (!info.item.empty()) text_disabled_wrapped(info.item.c_str());
}

void acquisition(Context& ctx) {
  AcquisitionSettings& a = ctx.settings.acquisition;
  section("Acquisition");
  float cap = static_cast<float>(a.fps_cap);
  fit_item_width(160 * ctx.scale, "fps cap");
  if (ImGui::SliderFloat("fps cap", &cap, 0.0f, 60.0f, cap <= 0 ? "off" : "%.0f fps")) a.fps_cap = std::round(cap);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Frames taken from the source per second (the paper uses 20). 0: no cap.");
  ImGui::Checkbox("resize", &a.resize);
  flow(130 * ctx.scale);
  char cur[48];
  size_label(a.size, cur, sizeof cur);
  ImGui::SetNextItemWidth(130 * ctx.scale);
  if (ImGui::BeginCombo("##size", cur)) {
    for (const cv::Size s : kSizes) {
      size_label(s, cur, sizeof cur);
      if (ImGui::Selectable(cur, s == a.size)) a.size = s;
    }
    ImGui::EndCombo();
  }
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("A width keeps the source's aspect; WxH exactly squashes a source of another aspect.");
  if (ctx.frame) {
    const SourceInfo& i = ctx.frame->source;
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    const cv::Size work = ctx.frame->image.size();
    ImGui::TextWrapped("source %dx%d%s -> working %dx%d", i.size.width, i.size.height,
                        i.native_fps > 0 ? (" at " + std::to_string(static_cast<int>(i.native_fps)) + " fps").c_str() : "",
                        work.width, work.height);
    // Said, not left to be noticed: markers, poses and calibrations of a squashed picture are squashed too.
    if (i.size.area() > 0 && work.area() > 0) {
      const double from = double(i.size.width) / i.size.height, to = double(work.width) / work.height;
      if (std::abs(to / from - 1) > 0.01)
        ImGui::TextWrapped("squashed: aspect %.2f -> %.2f; choose a width to keep the source's", from, to);
    }
    ImGui::PopStyleColor();
  }
}

void synthetic_controls(Context& ctx) {
  if (!ctx.frame || ctx.frame->source.kind != SourceKind::synthetic) return;
  SyntheticControls& c = ctx.settings.synthetic;
  section("Synthetic source");
  // What the source shows: markers, or a calibration board held in front of a camera with a known lens (the
  // Calibrate workspace puts its board here by itself).
  static const char* kShows[] = {"markers", "chessboard (9x6, 25 mm)", "ChArUco board (5x7, 35 mm)"};
  static const char* kBoards[] = {"", "chessboard", "charuco"};
  int shows = c.board == "chessboard" ? 1 : c.board == "charuco" ? 2 : 0;
  fit_item_width(220 * ctx.scale, "shows##synthetic");
  if (ImGui::Combo("shows##synthetic", &shows, kShows, IM_ARRAYSIZE(kShows))) c.board = kBoards[shows];
  const bool board = !c.board.empty();
  ImGui::Checkbox("animate", &c.animate);
  auto slider = [&](const char* label, double& v, float lo, float hi, const char* fmt) {
    float f = static_cast<float>(v);
    fit_item_width(180 * ctx.scale, label);
    if (ImGui::SliderFloat(label, &f, lo, hi, fmt)) v = f;
  };
  if (c.animate) slider("speed##synthetic", c.speed, 0.0f, 4.0f, "%.2fx");
  else slider("time", c.time_s, 0.0f, 120.0f, "%.1f s");
  slider("light", c.light, 0.2f, 1.5f, "%.2f");
  slider("blur", c.blur_px, 0.0f, 5.0f, "%.1f px");
  slider("noise", c.noise, 0.0f, 40.0f, "%.0f grey levels");
  if (board) {   // the board's poses and its camera are fixed: the rest are the markers' own
    text_disabled_wrapped("The board moves from pose to pose in front of a camera with a known lens: calibrate it in "
                          "the Calibrate workspace, which shows that camera beside the result.");
    if (ImGui::Button("Reset synthetic")) c = SyntheticControls{};
    return;
  }
  slider("distance", c.distance_m, 0.2f, 3.0f, "%.2f m");
  slider("tilt", c.tilt_deg, 0.0f, 80.0f, "%.0f deg");
  slider("marker size", c.marker_size_m, 0.02f, 0.3f, "%.3f m");
  fit_item_width(180 * ctx.scale, "markers");
  ImGui::SliderInt("markers", &c.markers, 1, 8);
  fit_item_width(180 * ctx.scale, "first id");
  ImGui::InputInt("first id", &c.first_id);
  c.first_id = std::max(0, c.first_id);
  fit_item_width(180 * ctx.scale, "dictionary##synthetic");
  if (ImGui::BeginCombo("dictionary##synthetic", c.dict.c_str())) {
    for (const std::string& n : dictionary_names()) {
      if (ImGui::Selectable(n.c_str(), n == c.dict)) c.dict = n;
    }
    ImGui::EndCombo();
  }
  if (c.dict != (ctx.settings.dictionaries.empty() ? "" : ctx.settings.dictionaries[0])) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.8f, 0.3f, 1));
    ImGui::TextWrapped("The detector reads %s, not %s.",
                       ctx.settings.dictionaries.empty() ? "nothing" : ctx.settings.dictionaries[0].c_str(),
                       c.dict.c_str());
    ImGui::PopStyleColor();
    if (ImGui::SmallButton("Detect this dictionary")) ctx.settings.dictionaries = {c.dict};
  }
  if (ImGui::Button("Reset synthetic")) c = SyntheticControls{};
}

}  // namespace

void draw_source(Context& ctx) {
  SourceViewState& st = panel_state<SourceViewState>(ctx.view, Panel::source);
  source_choice(ctx, st);
  playback(ctx);
  acquisition(ctx);
  synthetic_controls(ctx);
}

}  // namespace arwb::ui
