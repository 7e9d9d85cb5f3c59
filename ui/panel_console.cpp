// Console: what the scene printed (white), its warnings (yellow) and errors (red, "file:line: message"), oldest
// first, a line repeated in a row shown once with "xN". Filters by level and text; follows new lines while
// scrolled to the bottom; Clear hides the lines there are now (the lines are the worker's: only this view
// forgets them). Clicking a warning or error at a line of the scene file shows that line in the Script editor.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>
#include <string_view>

namespace arwb::ui {

namespace {

struct ConsoleState : PanelState {
  bool show[3] = {true, true, true};  // print, warning, error
  char filter[128] = "";
  uint64_t last_serial = 0;
  // Clear: the serial then, how many lines there were and the last one (with its repeats), to find where the
  // lines added since begin (the worker keeps only the newest lines, without a serial per line).
  bool cleared = false;
  uint64_t cleared_serial = 0;
  size_t cleared_count = 0;
  ConsoleLine cleared_last;
  std::string cleared_file;
};

const char* level_name(int level) {
  switch (level) {
    case 1: return "warning";
    case 2: return "error";
    default: return "print";
  }
}

ImU32 level_colour(int level) {
  switch (level) {
    case 1: return IM_COL32(255, 200, 70, 255);
    case 2: return IM_COL32(255, 85, 85, 255);
    default: return IM_COL32(235, 235, 235, 255);
  }
}

int level_index(int level) { return std::clamp(level, 0, 2); }


bool same_line(const ConsoleLine& a, const ConsoleLine& b) { return a.level == b.level && a.text == b.text; }

// The first line to show after a Clear, and how many repeats of the line before it came since (shown as that
// line again, "xN" the new repeats). Exact while the console is not full; once the worker drops old lines the
// anchor (the last line at Clear) is looked for where it can be, erring towards showing a line twice rather than
// hiding a new one.
size_t first_new(const ConsoleState& st, const SceneStatus& s, int* anchor_repeats) {
  *anchor_repeats = 0;
  const std::vector<ConsoleLine>& c = s.console;
  if (!st.cleared) return 0;
  const uint64_t delta = s.console_serial - st.cleared_serial;
  if (delta == 0) return c.size();
  if (st.cleared_count == 0) return 0;
  auto anchored = [&](size_t i) {
    if (!same_line(c[i], st.cleared_last) || c[i].repeats < st.cleared_last.repeats) return false;
    *anchor_repeats = c[i].repeats - st.cleared_last.repeats;
    return true;
  };
  // Not full: the lines at Clear are still the first ones.
  const size_t at = st.cleared_count - 1;
  if (at < c.size() && c.size() - st.cleared_count <= delta && anchored(at)) return at + 1;
  // Full: each new line or repeat moved the serial by one, so the anchor is at most `delta` lines from the end.
  const size_t from = c.size() > delta + 1 ? c.size() - 1 - static_cast<size_t>(delta) : 0;
  for (size_t i = from; i < c.size(); ++i) {
    if (anchored(i)) return i + 1;
  }
  // Not found: the `delta` newest lines at most.
  return c.size() > delta ? c.size() - static_cast<size_t>(delta) : 0;
}

void draw_line(Context& ctx, const ConsoleLine& l, int repeats, const std::string& file) {
  ImGui::PushStyleColor(ImGuiCol_Text, level_colour(l.level));
  ImGui::TextUnformatted(l.text.c_str());
  ImGui::PopStyleColor();
  if (l.level > 0) {
    const int line = message_line_in(l.text, file);
    if (line > 0 && ImGui::IsItemHovered()) {
      ImGui::SetMouseCursor(ImGuiMouseCursor_Hand);
      ImGui::SetTooltip("Show line %d in the Script editor", line);
    }
    if (line > 0 && ImGui::IsItemClicked(ImGuiMouseButton_Left)) {
      show_script_line(ctx, line);
    }
  }
  if (repeats > 1) {
    ImGui::SameLine();
    ImGui::TextDisabled("\xC3\x97%d", repeats);  // U+00D7 MULTIPLICATION SIGN
  }
}

}  // namespace

void draw_console(Context& ctx) {
  ConsoleState& st = panel_state<ConsoleState>(ctx.view, Panel::console);
  const SceneStatus* s = ctx.frame ? &ctx.frame->scene : nullptr;
  // A Clear applies to the scene it was made on; another scene's lines all show.
  if (s && st.cleared && (s->file != st.cleared_file || s->console_serial < st.cleared_serial)) st.cleared = false;
  int anchor_repeats = 0;
  const size_t first = s ? first_new(st, *s, &anchor_repeats) : 0;

  // Toolbar: level toggles with their counts (of the lines not cleared), text filter, clear, copy.
  int counts[3] = {0, 0, 0};
  if (s) {
    for (size_t i = first; i < s->console.size(); ++i) ++counts[level_index(s->console[i].level)];
    if (first > 0 && anchor_repeats > 0) ++counts[level_index(s->console[first - 1].level)];
  }
  static const char* const kNames[3] = {level_name(0), level_name(1), level_name(2)};
  static const ImU32 kColours[3] = {level_colour(0), level_colour(1), level_colour(2)};
  level_filter_bar(kNames, kColours, counts, st.show, st.filter, sizeof st.filter, 160.0f * ctx.scale);
  ImGui::BeginDisabled(!s || first >= s->console.size());
  if (ImGui::Button("Clear") && s) {
    st.cleared = true;
    st.cleared_serial = s->console_serial;
    st.cleared_count = s->console.size();
    st.cleared_last = s->console.empty() ? ConsoleLine{} : s->console.back();
    st.cleared_file = s->file;
  }
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("Hides the lines shown now.");
  ImGui::SameLine();
  auto passes = [&](const ConsoleLine& l) {
    return st.show[level_index(l.level)] && contains_nocase(l.text, st.filter);
  };
  if (ImGui::Button("Copy") && s) {
    std::string all;
    for (size_t i = first; i < s->console.size(); ++i) {
      const ConsoleLine& l = s->console[i];
      if (!passes(l)) continue;
      all += l.text;
      if (l.repeats > 1) all += " (x" + std::to_string(l.repeats) + ")";
      all += '\n';
    }
    ImGui::SetClipboardText(all.c_str());
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Copies the lines the filters let through.");
  ImGui::Separator();

  if (waiting_for_frame(ctx)) return;
  if (s->file.empty() && s->console.empty()) {
    ImGui::TextDisabled("No scene loaded: the console shows what a scene prints, and its warnings and errors.");
    return;
  }

  const std::string file = scene_file_to_edit(*s);   // errors at its lines open the Script editor there
  ImGui::BeginChild("console_lines", {0, 0}, false, ImGuiWindowFlags_HorizontalScrollbar);
  // Follow new lines only when the view was at the bottom before they came.
  const bool at_bottom = ImGui::GetScrollY() >= ImGui::GetScrollMaxY() - 1.0f;
  int shown = 0;
  // After a Clear, the last line then comes back when it repeated since, counted from the Clear.
  if (first > 0 && anchor_repeats > 0 && passes(s->console[first - 1])) {
    draw_line(ctx, s->console[first - 1], anchor_repeats, file);
    ++shown;
  }
  for (size_t i = first; i < s->console.size(); ++i) {
    const ConsoleLine& l = s->console[i];
    if (!passes(l)) continue;
    ImGui::PushID(static_cast<int>(i));
    draw_line(ctx, l, l.repeats, file);
    ImGui::PopID();
    ++shown;
  }
  if (shown == 0) {
    const size_t total = s->console.size() - first;
    if (total == 0) ImGui::TextDisabled(st.cleared ? "Nothing new since Clear." : "The scene has printed nothing.");
    else ImGui::TextDisabled("No line matches the filters (%zu hidden).", total);
  }
  if (s->console_serial != st.last_serial && at_bottom) ImGui::SetScrollHereY(1.0f);
  st.last_serial = s->console_serial;
  ImGui::EndChild();
}

}  // namespace arwb::ui
