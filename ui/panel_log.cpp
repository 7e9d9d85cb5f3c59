// Log: the workbench's messages (preset loaded, snapshot written, a source that cannot be opened...), oldest
// first, with the time since start and the level in colour. Filters by level and by text; follows new messages
// while scrolled to the bottom; "Copy all" puts the shown lines on the clipboard.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>
#include <string_view>

namespace arwb::ui {

namespace {

struct LogState : PanelState {
  bool show[3] = {true, true, true};  // info, warning, error
  char filter[128] = "";
  size_t last_count = 0;
};

const char* level_name(LogLevel l) {
  switch (l) {
    case LogLevel::info: return "info";
    case LogLevel::warning: return "warning";
    case LogLevel::error: return "error";
  }
  return "?";
}

ImU32 level_colour(LogLevel l) {
  switch (l) {
    case LogLevel::info: return IM_COL32(170, 170, 170, 255);
    case LogLevel::warning: return IM_COL32(255, 190, 60, 255);
    case LogLevel::error: return IM_COL32(255, 80, 80, 255);
  }
  return IM_COL32(255, 255, 255, 255);
}


bool passes(const LogState& st, const LogEntry& e) {
  return st.show[static_cast<int>(e.level)] && contains_nocase(e.text, st.filter);
}

}  // namespace

void draw_log(Context& ctx) {
  LogState& st = panel_state<LogState>(ctx.view, Panel::log);
  const std::vector<LogEntry>* log = ctx.status.log;
  const size_t total = log ? log->size() : 0;

  // Toolbar: level filters with their counts, text filter, copy.
  int counts[3] = {0, 0, 0};
  if (log)
    for (const LogEntry& e : *log) ++counts[static_cast<int>(e.level)];
  static const char* const kNames[3] = {level_name(LogLevel::info), level_name(LogLevel::warning),
                                        level_name(LogLevel::error)};
  static const ImU32 kColours[3] = {level_colour(LogLevel::info), level_colour(LogLevel::warning),
                                    level_colour(LogLevel::error)};
  level_filter_bar(kNames, kColours, counts, st.show, st.filter, sizeof st.filter, 180.0f * ctx.scale);
  if (ImGui::Button("Copy all") && log) {
    std::string all;
    for (const LogEntry& e : *log) {
      if (!passes(st, e)) continue;
      char head[64];
      std::snprintf(head, sizeof head, "%9.3f %-7s ", e.time_s, level_name(e.level));
      all += head;
      all += e.text;
      all += '\n';
    }
    ImGui::SetClipboardText(all.c_str());
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Copies the lines the filters let through.");
  ImGui::Separator();

  if (total == 0) {
    ImGui::TextDisabled("No messages yet");
    return;
  }

  ImGui::BeginChild("log_lines", {0, 0}, false, ImGuiWindowFlags_HorizontalScrollbar);
  // Follow new lines only when the view was at the bottom before they came.
  const bool at_bottom = ImGui::GetScrollY() >= ImGui::GetScrollMaxY() - 1.0f;
  const float time_w = ImGui::CalcTextSize("00000.000").x;
  const float level_w = ImGui::CalcTextSize("warning ").x;
  int shown = 0;
  for (const LogEntry& e : *log) {
    if (!passes(st, e)) continue;
    ++shown;
    const float x0 = ImGui::GetCursorPosX();
    ImGui::TextDisabled("%9.3f", e.time_s);
    ImGui::SameLine(x0 + time_w + 8.0f * ctx.scale);
    ImGui::PushStyleColor(ImGuiCol_Text, level_colour(e.level));
    ImGui::TextUnformatted(level_name(e.level));
    ImGui::SameLine(x0 + time_w + level_w + 12.0f * ctx.scale);
    if (e.level == LogLevel::info) ImGui::PopStyleColor();
    ImGui::TextUnformatted(e.text.c_str());
    if (e.level != LogLevel::info) ImGui::PopStyleColor();
  }
  if (shown == 0) ImGui::TextDisabled("No message matches the filters (%zu hidden).", total);
  if (total != st.last_count && at_bottom) ImGui::SetScrollHereY(1.0f);
  st.last_count = total;
  ImGui::EndChild();
}

}  // namespace arwb::ui
