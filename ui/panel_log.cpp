// Log: the workbench's messages (preset loaded, snapshot written, a source that cannot be opened...), oldest
// first, with the time since start and the level in colour. Filters by level and by text; follows new messages
// while scrolled to the bottom; "Copy all" puts the shown lines on the clipboard.
#include "ui/panels.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>
#include <string_view>

namespace arwb::ui {

namespace {

struct LogState {
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

// Case-insensitive substring test; an empty needle matches everything.
bool contains_nocase(std::string_view hay, std::string_view needle) {
  if (needle.empty()) return true;
  auto it = std::search(hay.begin(), hay.end(), needle.begin(), needle.end(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
  });
  return it != hay.end();
}

bool passes(const LogState& st, const LogEntry& e) {
  return st.show[static_cast<int>(e.level)] && contains_nocase(e.text, st.filter);
}

}  // namespace

void draw_log(Context& ctx) {
  static LogState st;
  const std::vector<LogEntry>* log = ctx.status.log;
  const size_t total = log ? log->size() : 0;

  // Toolbar: level filters with their counts, text filter, copy.
  int counts[3] = {0, 0, 0};
  if (log)
    for (const LogEntry& e : *log) ++counts[static_cast<int>(e.level)];
  for (int i = 0; i < 3; ++i) {
    const LogLevel l = static_cast<LogLevel>(i);
    char label[48];
    std::snprintf(label, sizeof label, "%s (%d)", level_name(l), counts[i]);
    ImGui::PushStyleColor(ImGuiCol_Text, level_colour(l));
    ImGui::Checkbox(label, &st.show[i]);
    ImGui::PopStyleColor();
    ImGui::SameLine();
  }
  ImGui::SetNextItemWidth(180.0f * ctx.scale);
  ImGui::InputTextWithHint("##filter", "filter text", st.filter, sizeof st.filter);
  ImGui::SameLine();
  if (st.filter[0]) {
    if (ImGui::SmallButton("x")) st.filter[0] = 0;
    ImGui::SameLine();
  }
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
