#include "ui/widgets.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>

namespace arwb::ui {

ImU32 stage_colour(Stage s, float alpha) {
  // One hue per stage, early stages cool, late stages warm, so "how far it got" reads at a glance.
  static const ImVec4 kColours[kStageCount] = {
      {0.6f, 0.6f, 0.6f, 1}, {0.6f, 0.7f, 0.6f, 1}, {0.55f, 0.55f, 0.75f, 1}, {0.5f, 0.5f, 0.9f, 1}, {0.3f, 0.6f, 1.0f, 1}, {0.35f, 0.7f, 0.95f, 1}, {0.2f, 0.8f, 1.0f, 1},
      {0.2f, 0.9f, 0.8f, 1}, {0.6f, 0.9f, 0.3f, 1}, {0.9f, 0.9f, 0.2f, 1}, {1.0f, 0.75f, 0.2f, 1},
      {1.0f, 0.6f, 0.2f, 1}, {1.0f, 0.45f, 0.2f, 1}, {1.0f, 0.25f, 0.25f, 1}, {1.0f, 0.3f, 0.7f, 1},
      {0.3f, 0.75f, 0.9f, 1},  // fine_search: a search again, the search's hue
      {0.8f, 0.4f, 1.0f, 1},
  };
  const int i = static_cast<int>(s);
  ImVec4 c = (i >= 0 && i < kStageCount) ? kColours[i] : ImVec4(1, 1, 1, 1);
  c.w = alpha;
  return ImGui::ColorConvertFloat4ToU32(c);
}

void section_heading(const char* title) {
  ImGui::Spacing();
  ImGui::TextUnformatted(title);
  ImGui::Separator();
}

std::string short_number(double v) {
  char buf[32];
  if (std::abs(v - std::round(v)) < 1e-9 && std::abs(v) < 1e9) std::snprintf(buf, sizeof buf, "%.0f", v);
  else std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

bool waiting_for_frame(const Context& ctx) {
  if (ctx.frame) return false;
  ImGui::TextDisabled("Waiting for the first frame from the source...");
  return true;
}

void show_script_line(Context& ctx, int line) {
  ctx.view.script_goto_line = line;
  ctx.view.show(Panel::script);   // the workspace puts its tab in front
}

void flow(float width) {
  const float after = ImGui::GetItemRectMax().x + ImGui::GetStyle().ItemSpacing.x;
  // The right edge of the region the next item goes in: the window's, or a table column's inside a table.
  const float right = ImGui::GetCursorScreenPos().x + ImGui::GetContentRegionAvail().x;
  if (after + width <= right) ImGui::SameLine();
}

float checkbox_width(const char* label) {
  return ImGui::GetFrameHeight() + ImGui::GetStyle().ItemInnerSpacing.x + ImGui::CalcTextSize(label, nullptr, true).x;
}

float button_width(const char* label) {
  return ImGui::CalcTextSize(label, nullptr, true).x + ImGui::GetStyle().FramePadding.x * 2;
}

float text_width(const char* text) { return ImGui::CalcTextSize(text).x; }

void fit_item_width(float want, const char* label) {
  const float label_w = ImGui::CalcTextSize(label, nullptr, true).x;
  const float room = ImGui::GetContentRegionAvail().x - (label_w > 0 ? label_w + ImGui::GetStyle().ItemInnerSpacing.x : 0);
  ImGui::SetNextItemWidth(std::max(ImGui::GetFontSize() * 3, std::min(want, room)));
}

ImVec2 scroll_table_size(int rows) {
  const ImGuiStyle& st = ImGui::GetStyle();
  const float row = ImGui::GetTextLineHeight() + st.CellPadding.y * 2;
  return {0, static_cast<float>(rows) * row + st.ScrollbarSize + 4};
}

void text_disabled_wrapped(const char* text) {
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
  ImGui::TextWrapped("%s", text);
  ImGui::PopStyleColor();
}

int message_line_in(const std::string& message, const std::string& file) {
  if (file.empty()) return 0;
  // The first ":digits:" ends the file name.
  for (size_t i = message.find(':'); i != std::string::npos; i = message.find(':', i + 1)) {
    size_t j = i + 1;
    int line = 0;
    while (j < message.size() && message[j] >= '0' && message[j] <= '9' && line < 100000000) {
      line = line * 10 + (message[j] - '0');
      ++j;
    }
    if (j == i + 1 || j >= message.size() || message[j] != ':') continue;
    std::string_view named(message.data(), i);
    const std::string_view path(file);
    auto ends_with = [](std::string_view s, std::string_view tail, bool at_slash) {
      if (tail.empty() || s.size() < tail.size() || s.substr(s.size() - tail.size()) != tail) return false;
      return !at_slash || s.size() == tail.size() || s[s.size() - tail.size() - 1] == '/';
    };
    bool same = named == path || ends_with(named, path, true) || ends_with(path, named, true);
    if (!same && named.substr(0, 3) == "...") same = ends_with(path, named.substr(3), false);
    return same ? line : 0;
  }
  return 0;
}

std::string scene_file_to_edit(const SceneStatus& s) {
  if (!s.file.empty() || s.error.empty()) return s.file;
  for (size_t i = s.error.find(':'); i != std::string::npos; i = s.error.find(':', i + 1)) {
    size_t j = i + 1;
    while (j < s.error.size() && s.error[j] >= '0' && s.error[j] <= '9') ++j;
    if (j == i + 1 || j >= s.error.size() || s.error[j] != ':') continue;
    const std::string_view named(s.error.data(), i);
    auto ends = [&](std::string_view ext) {
      return named.size() > ext.size() && named.substr(named.size() - ext.size()) == ext;
    };
    if (named.substr(0, 3) != "..." && (ends(".lua") || ends(".xml"))) return std::string(named);
    return {};
  }
  return {};
}

ImU32 accepted_colour(float alpha) { return ImGui::ColorConvertFloat4ToU32({0.1f, 1.0f, 0.2f, alpha}); }

ImU32 fate_colour(Stage s, float alpha) { return s == Stage::accepted ? accepted_colour(alpha) : stage_colour(s, alpha); }

bool chip(const char* label, ImU32 colour, bool on) {
  const ImVec2 text = ImGui::CalcTextSize(label, nullptr, true);
  const ImGuiStyle& style = ImGui::GetStyle();
  const ImVec2 pad{style.FramePadding.x, style.FramePadding.y * 0.5f};
  const ImVec2 size{text.x + pad.x * 2, text.y + pad.y * 2};
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::PushID(label);
  const bool clicked = ImGui::InvisibleButton("##chip", size);
  ImGui::PopID();
  ImVec4 c = ImGui::ColorConvertU32ToFloat4(colour);
  if (!on) c = {c.x * 0.35f + 0.1f, c.y * 0.35f + 0.1f, c.z * 0.35f + 0.1f, c.w};
  if (ImGui::IsItemHovered()) c = {std::min(1.0f, c.x * 1.15f), std::min(1.0f, c.y * 1.15f), std::min(1.0f, c.z * 1.15f), c.w};
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 p1{p0.x + size.x, p0.y + size.y};
  dl->AddRectFilled(p0, p1, ImGui::ColorConvertFloat4ToU32(c), size.y * 0.5f);
  if (!on) dl->AddRect(p0, p1, IM_COL32(150, 150, 150, 200), size.y * 0.5f);
  const ImU32 ink = on ? IM_COL32(10, 10, 10, 255) : IM_COL32(170, 170, 170, 255);
  const char* end = std::strstr(label, "##");
  dl->AddText({p0.x + pad.x, p0.y + pad.y}, ink, label, end ? end : label + std::strlen(label));
  return clicked;
}

ImageMapping image_view(Context& ctx, const char* id, const std::string& key, const cv::Mat& image,
                        uint64_t version, ImageViewState& st, ImVec2 size, ImTextureID texture) {
  ImageMapping m;
  ImVec2 avail = ImGui::GetContentRegionAvail();
  if (size.x <= 0) size.x = std::max(avail.x, 32.0f);
  if (size.y <= 0) size.y = std::max(avail.y, 32.0f);
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton(id, size, ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                                       ImGuiButtonFlags_MouseButtonMiddle);
  m.min = p0;
  m.max = {p0.x + size.x, p0.y + size.y};
  m.hovered = ImGui::IsItemHovered();
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImU32 backdrop = IM_COL32(24, 24, 28, 255);
  if (image.empty()) {
    dl->AddRectFilled(m.min, m.max, backdrop);
    dl->AddText({p0.x + 8, p0.y + 8}, IM_COL32(200, 200, 200, 255), "No frame yet");
    return m;
  }
  const float iw = static_cast<float>(image.cols), ih = static_cast<float>(image.rows);
  const float fit_zoom = std::min(size.x / iw, size.y / ih);
  if (st.fit) {
    st.zoom = fit_zoom;
    st.centre = {iw * 0.5f - 0.5f, ih * 0.5f - 0.5f};
  }
  ImGuiIO& io = ImGui::GetIO();
  const ImVec2 mid{p0.x + size.x * 0.5f, p0.y + size.y * 0.5f};
  auto origin_for = [&](float zoom, ImVec2 centre) {
    return ImVec2{mid.x - (centre.x + 0.5f) * zoom, mid.y - (centre.y + 0.5f) * zoom};
  };
  if (m.hovered && io.MouseWheel != 0) {
    // Zoom about the cursor: the image point under it stays under it.
    const ImVec2 o = origin_for(st.zoom, st.centre);
    const float px = (io.MousePos.x - o.x) / st.zoom, py = (io.MousePos.y - o.y) / st.zoom;
    const float z = std::clamp(st.zoom * std::pow(1.2f, io.MouseWheel), fit_zoom * 0.25f, 64.0f);
    st.zoom = z;
    st.centre = {px - (io.MousePos.x - mid.x) / z - 0.5f, py - (io.MousePos.y - mid.y) / z - 0.5f};
    st.fit = false;
  }
  if (ImGui::IsItemActive() && (ImGui::IsMouseDragging(ImGuiMouseButton_Right) ||
                                ImGui::IsMouseDragging(ImGuiMouseButton_Middle))) {
    st.centre.x -= io.MouseDelta.x / st.zoom;
    st.centre.y -= io.MouseDelta.y / st.zoom;
    st.fit = false;
  }
  if (m.hovered && ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Right)) st.fit = true;
  m.zoom = st.zoom;
  m.origin = origin_for(st.zoom, st.centre);
  const ImTextureID tex = texture ? texture : ctx.texture(key, image, version);
  dl->PushClipRect(m.min, m.max, true);
  // The backdrop only where the picture is not (the bars beside and above it): in a software renderer every pixel
  // drawn twice costs, and the picture is most of the view.
  const ImVec2 i0 = m.origin, i1{m.origin.x + iw * st.zoom, m.origin.y + ih * st.zoom};
  const ImVec2 c0{std::clamp(i0.x, m.min.x, m.max.x), std::clamp(i0.y, m.min.y, m.max.y)};
  const ImVec2 c1{std::clamp(i1.x, m.min.x, m.max.x), std::clamp(i1.y, m.min.y, m.max.y)};
  if (c0.y > m.min.y) dl->AddRectFilled(m.min, {m.max.x, c0.y}, backdrop);
  if (c1.y < m.max.y) dl->AddRectFilled({m.min.x, c1.y}, m.max, backdrop);
  if (c0.x > m.min.x) dl->AddRectFilled({m.min.x, c0.y}, {c0.x, c1.y}, backdrop);
  if (c1.x < m.max.x) dl->AddRectFilled({c1.x, c0.y}, {m.max.x, c1.y}, backdrop);
  dl->AddImage(tex, i0, i1);
  dl->PopClipRect();
  if (m.hovered) {
    const cv::Point2f p = m.to_image(io.MousePos);
    m.mouse_px = {p.x, p.y};
  }
  return m;
}

void draw_quad(ImDrawList* dl, const ImageMapping& m, const Quad& q, ImU32 colour, float thickness, bool mark_corner0) {
  ImVec2 pts[4];
  for (int i = 0; i < 4; ++i) pts[i] = m.to_screen(q[static_cast<size_t>(i)]);
  dl->AddPolyline(pts, 4, colour, ImDrawFlags_Closed, thickness);
  if (mark_corner0) {
    const float r = std::max(3.0f, thickness * 2.0f);
    dl->AddRectFilled({pts[0].x - r, pts[0].y - r}, {pts[0].x + r, pts[0].y + r}, colour);
  }
}

float draw_stage_labels(ImDrawList* dl, const ImageMapping& m, const std::vector<StageLabel>& labels) {
  ImFont* font = ImGui::GetFont();
  const float full = ImGui::GetFontSize();
  const float out = std::max(1.0f, full / 15.0f);   // the outline: 1 px at the normal 15 px type
  float smallest = 0;
  dl->PushClipRect(m.min, m.max, true);
  for (const StageLabel& l : labels) {
    const float size = l.height > 0 ? std::min(full, l.height * m.zoom * 0.95f) : full;
    const ImVec2 ts = font->CalcTextSizeA(size, FLT_MAX, 0, l.text.c_str());
    const ImVec2 c = m.to_screen(l.centre);
    const ImVec2 at{c.x - ts.x * 0.5f, c.y - ts.y * 0.5f};
    const ImU32 ink = IM_COL32(l.colour[2], l.colour[1], l.colour[0], 255);
    for (const ImVec2 d : {ImVec2{-out, 0}, ImVec2{out, 0}, ImVec2{0, -out}, ImVec2{0, out}})
      dl->AddText(font, size, {at.x + d.x, at.y + d.y}, IM_COL32(0, 0, 0, 255), l.text.c_str());
    dl->AddText(font, size, at, ink, l.text.c_str());
    smallest = smallest > 0 ? std::min(smallest, size) : size;
  }
  dl->PopClipRect();
  return smallest;
}

std::string candidate_line(const FrameTrace& t, int index) {
  if (index < 0 || index >= static_cast<int>(t.candidates.size())) return {};
  const CandidateRecord& c = t.candidates[static_cast<size_t>(index)];
  char head[96];
  std::snprintf(head, sizeof head, "#%d %dx%d px: ", index, c.bbox.width, c.bbox.height);
  if (c.fate.stage == Stage::accepted && c.marker >= 0 && c.marker < static_cast<int>(t.markers.size())) {
    const Marker& mk = t.markers[static_cast<size_t>(c.marker)];
    char buf[128];
    std::snprintf(buf, sizeof buf, "id %d (%s), %d bit%s corrected", mk.id, mk.dict.c_str(), mk.hamming,
                  mk.hamming == 1 ? "" : "s");
    return head + std::string(buf);
  }
  return head + std::string(stage_name(c.fate.stage)) + ": " + c.fate.message;
}

void histogram_plot(const CandidateRecord& c, ImVec2 size) {
  if (c.histogram.size() != 256) {
    ImGui::TextDisabled("No histogram (needs the full trace and a frontal view).");
    return;
  }
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::Dummy(size);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(p0, {p0.x + size.x, p0.y + size.y}, IM_COL32(30, 30, 34, 255));
  const int peak = std::max(1, *std::max_element(c.histogram.begin(), c.histogram.end()));
  const float bw = size.x / 256.0f;
  for (int i = 0; i < 256; ++i) {
    const float h = size.y * static_cast<float>(c.histogram[static_cast<size_t>(i)]) / static_cast<float>(peak);
    if (h <= 0) continue;
    const ImU32 col = i <= c.otsu_threshold ? IM_COL32(110, 110, 120, 255) : IM_COL32(220, 220, 220, 255);
    dl->AddRectFilled({p0.x + static_cast<float>(i) * bw, p0.y + size.y - h},
                      {p0.x + static_cast<float>(i + 1) * bw, p0.y + size.y}, col);
  }
  if (c.otsu_threshold >= 0) {
    const float x = p0.x + (static_cast<float>(c.otsu_threshold) + 0.5f) * bw;
    dl->AddLine({x, p0.y}, {x, p0.y + size.y}, IM_COL32(255, 80, 80, 255), 2.0f);
    char buf[48];
    std::snprintf(buf, sizeof buf, "Otsu %d", c.otsu_threshold);
    dl->AddText({x + 4, p0.y + 2}, IM_COL32(255, 120, 120, 255), buf);
  }
  if (ImGui::IsItemHovered()) {
    const int bin = std::clamp(static_cast<int>((ImGui::GetIO().MousePos.x - p0.x) / bw), 0, 255);
    ImGui::SetTooltip("grey %d: %d px", bin, c.histogram[static_cast<size_t>(bin)]);
  }
}

void bit_grid(const CandidateRecord& c, float cell, const cv::Mat& expected) {
  if (c.bits.empty()) {
    ImGui::TextDisabled("No bit grid (the candidate stopped before bit_grid, or the trace is not full).");
    return;
  }
  const int n = c.bits.rows;
  const bool compare = expected.rows == n - 2 && expected.cols == n - 2;
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::Dummy({cell * static_cast<float>(n), cell * static_cast<float>(n)});
  ImDrawList* dl = ImGui::GetWindowDrawList();
  for (int r = 0; r < n; ++r) {
    for (int col = 0; col < n; ++col) {
      const bool white = c.bits.at<uint8_t>(r, col) != 0;
      const ImVec2 a{p0.x + static_cast<float>(col) * cell, p0.y + static_cast<float>(r) * cell};
      const ImVec2 b{a.x + cell, a.y + cell};
      dl->AddRectFilled(a, b, white ? IM_COL32(235, 235, 235, 255) : IM_COL32(20, 20, 20, 255));
      dl->AddRect(a, b, IM_COL32(90, 90, 100, 255));
      const bool border = r == 0 || col == 0 || r == n - 1 || col == n - 1;
      if (border && white) {
        dl->AddRect({a.x + 1, a.y + 1}, {b.x - 1, b.y - 1}, IM_COL32(255, 40, 40, 255), 0, 0, 3.0f);
      } else if (!border && compare && expected.at<uint8_t>(r - 1, col - 1) != (white ? 1 : 0)) {
        const ImU32 red = IM_COL32(255, 40, 40, 255);
        dl->AddLine({a.x + 3, a.y + 3}, {b.x - 3, b.y - 3}, red, 2.5f);
        dl->AddLine({b.x - 3, a.y + 3}, {a.x + 3, b.y - 3}, red, 2.5f);
      }
    }
  }
}

// printf format for a double parameter: its decimals (param_decimals), as presets are written.
const char* format_for(const ParamInfo& info) {
  static constexpr const char* kFormats[] = {"%.0f", "%.1f", "%.2f", "%.3f"};
  return kFormats[std::clamp(param_decimals(info), 0, 3)];
}

std::string value_text(const ParamInfo& info, double v) {
  char buf[64];
  if (info.integer) std::snprintf(buf, sizeof buf, "%d", static_cast<int>(v));
  else std::snprintf(buf, sizeof buf, format_for(info), v);
  return buf;
}

void param_tooltip(const ParamInfo& info) {
  ImGui::BeginTooltip();
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 32.0f);
  ImGui::TextUnformatted(info.name);
  ImGui::Separator();
  ImGui::TextUnformatted(info.help);
  ImGui::TextDisabled("default %s, range %s .. %s %s", value_text(info, info.default_value).c_str(),
                      value_text(info, info.min_value).c_str(), value_text(info, info.max_value).c_str(), info.unit);
  ImGui::TextDisabled("Ctrl+click the slider to type a value.");
  ImGui::PopTextWrapPos();
  ImGui::EndTooltip();
}

// The control for one parameter of the table: a checkbox for an on/off switch, an integer or double slider over
// its range (logarithmic when the range spans more than three decades), Ctrl+click to type; the help, default and
// range as a tooltip.
bool param_slider(DetectorParams& p, const ParamInfo& info, std::string* error) {
  ImGui::PushID(info.name);
  const bool wide = info.max_value - info.min_value > 1000.0;
  const ImGuiSliderFlags flags = ImGuiSliderFlags_AlwaysClamp | (wide ? ImGuiSliderFlags_Logarithmic : 0);
  double next = get_param(p, info);
  bool edited = false;
  if (info.integer && info.min_value == 0 && info.max_value == 1) {
    bool on = next != 0;
    edited = ImGui::Checkbox(on ? "on##v" : "off##v", &on);
    next = on ? 1 : 0;
  } else if (info.integer) {
    int v = static_cast<int>(next);
    edited = ImGui::SliderInt("##v", &v, static_cast<int>(info.min_value), static_cast<int>(info.max_value), "%d",
                              flags);
    next = v;
  } else {
    double v = next;
    edited = ImGui::SliderScalar("##v", ImGuiDataType_Double, &v, &info.min_value, &info.max_value, format_for(info),
                                 flags | (wide ? ImGuiSliderFlags_NoRoundToFormat : 0));
    next = v;
  }
  if (ImGui::IsItemHovered() && !ImGui::IsItemActive()) param_tooltip(info);
  ImGui::PopID();
  if (!edited) return false;
  std::string err;
  if (!set_param(p, info, next, &err) && error) *error = err;
  else if (error) error->clear();
  return true;
}

bool image_button(Context& ctx, const std::string& key, const cv::Mat& image, uint64_t version, ImVec2 size,
                  bool selected) {
  ImGui::PushID(key.c_str());
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  const bool clicked = ImGui::InvisibleButton("##img", size);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(p0, {p0.x + size.x, p0.y + size.y}, IM_COL32(24, 24, 28, 255));
  if (!image.empty()) {
    // Keep the aspect ratio inside the button.
    const float s = std::min(size.x / static_cast<float>(image.cols), size.y / static_cast<float>(image.rows));
    const float w = static_cast<float>(image.cols) * s, h = static_cast<float>(image.rows) * s;
    const ImVec2 a{p0.x + (size.x - w) * 0.5f, p0.y + (size.y - h) * 0.5f};
    dl->AddImage(ctx.texture(key, image, version, false), a, {a.x + w, a.y + h});
  }
  const ImU32 frame = selected ? IM_COL32(255, 200, 60, 255)
                               : (ImGui::IsItemHovered() ? IM_COL32(160, 160, 200, 255) : IM_COL32(70, 70, 80, 255));
  dl->AddRect(p0, {p0.x + size.x, p0.y + size.y}, frame, 0, 0, selected ? 3.0f : 1.0f);
  ImGui::PopID();
  return clicked;
}

void level_filter_bar(const char* const names[3], const ImU32 colours[3], const int counts[3], bool show[3],
                      char* filter, size_t filter_size, float filter_width) {
  // Each item wraps to a new line when the region is too narrow for it (flow); the caller's next item follows
  // on the line when a small button still fits.
  for (int i = 0; i < 3; ++i) {
    char label[48];
    std::snprintf(label, sizeof label, "%s (%d)", names[i], counts[i]);
    if (i > 0) flow(checkbox_width(label));
    ImGui::PushStyleColor(ImGuiCol_Text, colours[i]);
    ImGui::Checkbox(label, &show[i]);
    ImGui::PopStyleColor();
  }
  flow(filter_width);
  ImGui::SetNextItemWidth(std::min(filter_width, ImGui::GetContentRegionAvail().x));
  ImGui::InputTextWithHint("##filter", "filter text", filter, filter_size);
  if (filter[0]) {
    flow(button_width("x"));
    if (ImGui::SmallButton("x")) filter[0] = 0;
  }
  flow(ImGui::GetFontSize() * 5);
}

bool contains_nocase(std::string_view hay, std::string_view needle) {
  if (needle.empty()) return true;
  auto it = std::search(hay.begin(), hay.end(), needle.begin(), needle.end(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
  });
  return it != hay.end();
}

void why_on_marker(View& view, const Quad& corners) {
  const cv::Rect2f box = cv::boundingRect(std::vector<cv::Point2f>(corners.begin(), corners.end()));
  const float pad = 0.15f * std::max(box.width, box.height) + 2;   // the quiet zone and the border's blur
  view.region = cv::Rect2f(box.x - pad, box.y - pad, box.width + 2 * pad, box.height + 2 * pad);
  view.has_region = true;
  view.show_truth = true;
  // The live view zooms in on it: a marker of a few pixels is a speck in the whole frame.
  view.image.fit = false;
  view.image.zoom = std::clamp(160.0f / std::max(view.region.width, view.region.height), 1.0f, 8.0f);
  view.image.centre = {box.x + box.width / 2, box.y + box.height / 2};
  view.show(Panel::why);
}

}  // namespace arwb::ui
