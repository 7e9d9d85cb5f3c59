// Script editor: the text of the scene file in use, with line numbers, its load error's line and the lines of
// its runtime errors and skipped mappings (the Scene panel's rows that are not ok) marked in red and
// the message under it. Save (or Ctrl+S) asks the workbench to write the file, atomically; the scene then reloads
// by itself. The editor never drops the user's edits silently: when the file changes on disk while there are
// unsaved edits, or the scene switches to another file, it asks. The window reads and watches the file (a
// watch_file request; Status::script_file, limited to 1 MB) and writes it (save_script); the editor only compares
// texts.
//
// The text is one InputTextMultiline as tall and wide as its text, so it never scrolls itself, inside a child
// window that scrolls; the line numbers and the error line's red band are drawn in that child, behind and beside
// the text, so they stay aligned with it.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <imgui_stdlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>
#include <utility>

namespace arwb::ui {

namespace {

constexpr double kSaveTimeoutS = 3.0;   // a save not seen on disk by then is reported
// ImGui 1.86's GLFW backend indexes io.KeysDown by GLFW key code, and GLFW_KEY_S is 'S'.
constexpr int kKeyS = 'S';


struct ScriptState : PanelState {
  std::string followed;      // the scene file (SceneStatus::file) the editor last took
  std::string path;          // the file in the buffer ("" when none)
  bool open = false;         // the buffer holds the file's text
  std::string open_error;    // why it could not be read
  std::string buffer;        // what the user edits
  std::string base;          // the text on disk as last read, or as acknowledged with "Keep mine"
  bool dirty = false;        // buffer != base
  bool reading = false;      // asked the window for the file's text, not come yet
  uint64_t seen = 0;         // the Status::script_file version last looked at
  bool conflict = false;     // the file changed on disk while the buffer had edits
  std::string disk_text;     // its text then
  bool gone = false;         // the file is no longer on disk
  std::string disk_error;    // it is there but cannot be read (too large, permissions)
  bool save_pending = false; // sent to be saved, not seen on disk yet
  std::string saved;         // the text sent
  double save_time = 0;
  int serial = 0;            // part of the text widget's id: a new one when the buffer is replaced from outside
  // Layout of the text, recomputed when it changes.
  int lines = 1;
  float text_w = 0;
  // The text cursor, from the widget's callback while it is active.
  int cursor = -1;
  bool cursor_moved = false;
  int cursor_line = 0;       // 0-based
  float cursor_x = 0;        // from the start of its line
  int goto_line = 0;         // scroll there on the next draw
  bool take_focus = false;   // the text takes the keyboard at the next draw
};

void relayout(ScriptState& st) {
  st.lines = 1 + static_cast<int>(std::count(st.buffer.begin(), st.buffer.end(), '\n'));
  st.text_w = ImGui::CalcTextSize(st.buffer.data(), st.buffer.data() + st.buffer.size()).x;
}

// Replaces the buffer with `text` (from disk): the widget gets a new id so an active one lets go of its copy.
void set_buffer(ScriptState& st, const std::string& text) {
  st.buffer = text;
  st.base = text;
  st.dirty = false;
  st.conflict = false;
  st.disk_text.clear();
  ++st.serial;
  st.cursor = -1;
  relayout(st);
}

// Takes `path` into the editor, dropping what was there (the caller made sure there were no edits to keep); its
// text comes when the window has read it.
void open_file(Context& ctx, ScriptState& st, const std::string& path) {
  st.path = path;
  st.open = false;
  st.open_error.clear();
  st.gone = false;
  st.disk_error.clear();
  st.save_pending = false;
  st.saved.clear();
  set_buffer(st, std::string());
  st.reading = !path.empty();
  ctx.request(WatchFile{path, true});
}

// A new reading of the file from the window: the text asked for, or the file changed on disk. Without edits the
// editor follows it; with edits that differ from the new text it asks (conflict) rather than overwrite either.
// True when it was the first reading of a file opened.
bool take_reading(Context& ctx, ScriptState& st) {
  const WatchedFile& file = ctx.status.script_file;
  if (st.path.empty() || file.path != st.path || file.version == st.seen) return false;
  st.seen = file.version;
  if (st.reading || !st.open) {
    // The first reading, or the file could not be read before (too large, missing) and changed since.
    st.reading = false;
    st.open = file.read;
    st.open_error = file.read ? std::string() : file.error;
    set_buffer(st, file.read ? file.text : std::string());
    return st.open;
  }
  st.gone = !file.exists;
  st.disk_error.clear();
  if (st.gone) return false;
  if (!file.read) {
    st.disk_error = file.error;
    return false;
  }
  const std::string& text = file.text;
  if (st.save_pending && text == st.saved) {
    // Our save landed; it replaced whatever the disk had (saving during a conflict is keeping mine).
    st.save_pending = false;
    st.base = text;
    st.dirty = st.buffer != st.base;
    st.conflict = false;
    st.disk_text.clear();
    return false;
  }
  if (text == st.base) return false;   // touched, not changed
  if (!st.dirty) {
    set_buffer(st, text);        // nothing of the user's to keep: follow the file
  } else if (text == st.buffer) {
    st.base = text;              // it now says what the buffer says
    st.dirty = false;
    st.conflict = false;
  } else {
    st.conflict = true;
    st.disk_text = text;
  }
  return false;
}

void save(Context& ctx, ScriptState& st) {
  if (st.path.empty()) return;
  ctx.request(SaveScript{st.path, st.buffer});
  st.save_pending = true;
  st.saved = st.buffer;
  st.save_time = ImGui::GetTime();   // the window reads the file again right after writing it
}

// The widget's callback (ImGuiInputTextFlags_CallbackAlways, while it is active): where the text cursor is.
int on_text_event(ImGuiInputTextCallbackData* d) {
  auto* st = static_cast<ScriptState*>(d->UserData);
  if (d->EventFlag != ImGuiInputTextFlags_CallbackAlways || d->CursorPos == st->cursor) return 0;
  st->cursor = d->CursorPos;
  st->cursor_moved = true;
  const char* begin = d->Buf;
  const char* at = d->Buf + std::clamp(d->CursorPos, 0, d->BufTextLen);
  const char* line_start = begin;
  int line = 0;
  for (const char* p = begin; p < at; ++p) {
    if (*p == '\n') {
      ++line;
      line_start = p + 1;
    }
  }
  st->cursor_line = line;
  st->cursor_x = ImGui::CalcTextSize(line_start, at).x;
  return 0;
}

// The text with its line numbers in a scrolling child of `size`; the `marks` (1-based lines) in red.
void editor(ScriptState& st, const std::vector<int>& marks, ImVec2 size) {
  const ImGuiStyle& style = ImGui::GetStyle();
  ImGui::BeginChild("##editor", size, true, ImGuiWindowFlags_HorizontalScrollbar);
  const float lh = ImGui::GetTextLineHeight();   // InputText's line height: the font size
  const ImVec2 pad = style.FramePadding;
  char widest[16];
  std::snprintf(widest, sizeof widest, "%d", std::max(st.lines, 999));
  const float gutter = ImGui::CalcTextSize(widest).x + pad.x * 2;
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const ImVec2 at{origin.x + gutter, origin.y};
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  // As wide and tall as the text (and a line and a few characters more, for what is typed before the next
  // relayout), and at least the child's size so a click anywhere in it edits.
  const ImVec2 input_size{std::max(avail.x - gutter, st.text_w + pad.x * 2 + lh * 4),
                          std::max(avail.y, static_cast<float>(st.lines + 1) * lh + pad.y * 4)};
  const float text_top = at.y + pad.y;           // where the widget draws its first line
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(at, {at.x + input_size.x, at.y + input_size.y}, ImGui::GetColorU32(ImGuiCol_FrameBg, 0.4f));
  for (const int mark_line : marks) {
    if (mark_line < 1 || mark_line > st.lines) continue;
    const float y = text_top + static_cast<float>(mark_line - 1) * lh;
    dl->AddRectFilled({origin.x, y}, {at.x + input_size.x, y + lh}, IM_COL32(210, 40, 40, 110));
  }
  // The line numbers in view.
  const ImVec2 win = ImGui::GetWindowPos();
  const float win_h = ImGui::GetWindowHeight();
  const int first = std::max(0, static_cast<int>((win.y - text_top) / lh));
  const int last = std::min(st.lines, static_cast<int>((win.y + win_h - text_top) / lh) + 1);
  const ImU32 number_colour = ImGui::GetColorU32(ImGuiCol_TextDisabled);
  for (int i = first; i < last; ++i) {
    char num[16];
    std::snprintf(num, sizeof num, "%d", i + 1);
    const float w = ImGui::CalcTextSize(num).x;
    dl->AddText({at.x - pad.x - w, text_top + static_cast<float>(i) * lh},
                std::find(marks.begin(), marks.end(), i + 1) != marks.end() ? IM_COL32(255, 120, 120, 255)
                                                                            : number_colour,
                num);
  }

  ImGui::SetCursorScreenPos(at);
  ImGui::PushStyleColor(ImGuiCol_FrameBg, IM_COL32(0, 0, 0, 0));   // the background is drawn above
  ImGui::PushID(st.serial);
  st.cursor_moved = false;
  const ImGuiInputTextFlags flags = ImGuiInputTextFlags_AllowTabInput | ImGuiInputTextFlags_NoHorizontalScroll |
                                    ImGuiInputTextFlags_CallbackAlways;
  if (std::exchange(st.take_focus, false)) ImGui::SetKeyboardFocusHere();   // --actions focus=script
  const bool edited = ImGui::InputTextMultiline("##text", &st.buffer, input_size, flags, on_text_event, &st);
  ImGui::PopID();
  ImGui::PopStyleColor();
  if (edited) {
    st.dirty = st.buffer != st.base;
    relayout(st);
  }

  // The widget never scrolls: this child follows the text cursor when it moves...
  const ImVec2 cmin = ImGui::GetWindowContentRegionMin(), cmax = ImGui::GetWindowContentRegionMax();
  if (st.cursor_moved) {
    const float cy = text_top + static_cast<float>(st.cursor_line) * lh;
    if (cy < win.y + cmin.y) ImGui::SetScrollFromPosY(cy - win.y - pad.y, 0.0f);
    else if (cy + lh > win.y + cmax.y) ImGui::SetScrollFromPosY(cy + lh - win.y + pad.y, 1.0f);
    const float cx = at.x + pad.x + st.cursor_x;
    if (cx < win.x + cmin.x + gutter) ImGui::SetScrollFromPosX(cx - win.x - gutter - pad.x, 0.0f);
    else if (cx + lh > win.x + cmax.x) ImGui::SetScrollFromPosX(cx - win.x + lh * 2, 1.0f);
  }
  // ...and goes to a line when asked.
  if (st.goto_line > 0) {
    const int line = std::min(st.goto_line, st.lines);
    ImGui::SetScrollFromPosY(text_top + static_cast<float>(line - 1) * lh - win.y, 0.3f);
    ImGui::SetScrollX(0);
    st.goto_line = 0;
  }
  ImGui::EndChild();
}

std::string file_name(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  return name.empty() ? path : name;
}

// The file's name, a mark when it has unsaved edits, Save and Revert (which asks before dropping edits).
void title_buttons(Context& ctx, ScriptState& st) {
  ImGui::TextUnformatted(file_name(st.path).c_str());
  if (st.dirty) {
    ImGui::SameLine(0, 2);
    ImGui::TextColored(kYellow, "*");
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Unsaved edits");
  }
  ImGui::SameLine();
  ImGui::BeginDisabled(!st.open);
  if (ImGui::Button("Save")) save(ctx, st);
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
    ImGui::SetTooltip("Ctrl+S. Writes the file; the scene reloads by itself.");
  }
  ImGui::SameLine();
  if (ImGui::Button("Revert")) {
    if (st.dirty) ImGui::OpenPopup("revert?");
    else open_file(ctx, st, st.path);
  }
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("Read the file from disk again.");
  ImGui::EndDisabled();
  if (ImGui::BeginPopup("revert?")) {
    ImGui::Text("Drop your unsaved edits to %s?", file_name(st.path).c_str());
    if (ImGui::Button("Drop them and read the file")) {
      open_file(ctx, st, st.path);
      ImGui::CloseCurrentPopup();
    }
    ImGui::SameLine();
    if (ImGui::Button("Cancel")) ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
  }
}

// The load error's line, else the first line of a mapping that is not ok (a runtime error, a callback disabled, a
// marker() skipped) when `path` is the scene that runs; `problems` the first such reason and how many more.
std::vector<int> marked_lines(const SceneStatus& scene, const std::string& path, std::string* problems) {
  std::vector<int> marks;
  if (scene.error_line > 0 && message_line_in(scene.error, path) > 0) marks.push_back(scene.error_line);
  if (path != scene.file) return marks;
  int n = 0;
  for (const MappingRow& r : scene.mappings) {
    if (r.health == MappingHealth::ok) continue;
    if (r.reason_line > 0 && std::find(marks.begin(), marks.end(), r.reason_line) == marks.end())
      marks.push_back(r.reason_line);
    if (n++ == 0) *problems = r.reason;
  }
  if (n > 1) *problems += " (and " + std::to_string(n - 1) + " more in the Scene panel)";
  return marks;
}

}  // namespace

void draw_script(Context& ctx) {
  ScriptState& st = panel_state<ScriptState>(ctx.view, Panel::script);
  if (ctx.view.script_goto_line > 0) {
    st.goto_line = ctx.view.script_goto_line;
    ctx.view.script_goto_line = 0;
  }
  if (waiting_for_frame(ctx)) return;
  const SceneStatus& scene = ctx.frame->scene;

  // Follow the scene's file (or the one whose first load failed), unless that would drop edits.
  const std::string target = scene_file_to_edit(scene);
  bool switch_waiting = false;
  if (target != st.followed) {
    if (!st.dirty || !st.open) {
      st.followed = target;
      open_file(ctx, st, target);
    } else {
      switch_waiting = true;
    }
  }
  const bool opened = take_reading(ctx, st);
  // The window's "save, discard or cancel" question (ui/dialogs.cpp) reads the first and answers with the others.
  ctx.view.script_unsaved = st.dirty && st.open;
  if (std::exchange(ctx.view.script_save_now, false) && st.dirty) save(ctx, st);
  if (std::exchange(ctx.view.script_discard, false)) set_buffer(st, st.base);
  if (ctx.view.focus_field == TextField::script) {
    st.take_focus = true;
    ctx.view.focus_field = TextField::none;
  }

  if (st.path.empty()) {
    ImGui::TextDisabled("No scene loaded: the editor shows the scene file in use (see the Scene panel).");
    return;
  }

  // Title line: name, dirty mark, Save, Revert, the path.
  const bool focused = ImGui::IsWindowFocused(ImGuiFocusedFlags_RootAndChildWindows);
  title_buttons(ctx, st);
  std::string problems;
  const std::vector<int> marks = marked_lines(scene, st.path, &problems);
  const int mark_line = marks.empty() ? 0 : marks.front();
  if (opened && mark_line > 0 && st.goto_line == 0) st.goto_line = mark_line;   // a file opened with an error
  if (mark_line > 0) {
    ImGui::SameLine();
    char label[48];
    std::snprintf(label, sizeof label, "Go to line %d", mark_line);
    if (ImGui::Button(label)) st.goto_line = mark_line;
  }
  if (st.save_pending) {
    ImGui::SameLine();
    if (ImGui::GetTime() - st.save_time < kSaveTimeoutS) ImGui::TextDisabled("saving...");
    else ImGui::TextColored(kYellow, "not saved yet: see the Log");
  }
  ImGui::TextDisabled("%s", st.path.c_str());
  if (st.open && focused && ImGui::GetIO().KeyCtrl && ImGui::IsKeyPressed(kKeyS, false)) save(ctx, st);

  // What needs the user's word before anything is dropped.
  if (switch_waiting) {
    ImGui::PushStyleColor(ImGuiCol_Text, kYellow);
    if (target.empty()) ImGui::TextWrapped("The scene was unloaded. Your unsaved edits are still here.");
    else ImGui::TextWrapped("The scene now runs %s. Your unsaved edits to %s are still here.", target.c_str(),
                            file_name(st.path).c_str());
    ImGui::PopStyleColor();
    if (ImGui::Button("Save my edits")) save(ctx, st);
    ImGui::SameLine();
    if (ImGui::Button(target.empty() ? "Drop my edits" : "Drop my edits and open the new file")) {
      st.followed = target;
      open_file(ctx, st, target);
      return;
    }
  }
  if (st.conflict) {
    ImGui::PushStyleColor(ImGuiCol_Text, kYellow);
    ImGui::TextWrapped("%s changed on disk while you were editing it.", file_name(st.path).c_str());
    ImGui::PopStyleColor();
    if (ImGui::Button("Reload from disk")) set_buffer(st, st.disk_text);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Drops your edits and shows the file as it is now.");
    ImGui::SameLine();
    if (ImGui::Button("Keep mine")) {
      st.base = st.disk_text;
      st.conflict = false;
      st.dirty = st.buffer != st.base;
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Keeps your text; Save then replaces the file's.");
  }
  if (st.gone) ImGui::TextColored(kYellow, "The file is no longer on disk; Save writes it again.");
  if (!st.disk_error.empty()) ImGui::TextColored(kYellow, "%s", st.disk_error.c_str());
  if (st.reading) {
    ImGui::TextDisabled("reading...");
    return;
  }
  if (!st.open) {
    ImGui::TextColored(kRed, "%s", st.open_error.c_str());
    return;
  }

  // The editor, then the error under it and where the cursor is.
  const float line_h = ImGui::GetTextLineHeightWithSpacing();
  const std::string& shown = !scene.error.empty() ? scene.error : problems;
  const bool has_error = !shown.empty();
  float below = line_h;
  if (has_error) {
    const float wrap = ImGui::GetContentRegionAvail().x;
    below += ImGui::CalcTextSize(shown.c_str(), nullptr, false, wrap).y + ImGui::GetStyle().ItemSpacing.y;
  }
  const float editor_h = std::max(ImGui::GetContentRegionAvail().y - below, line_h * 3);
  editor(st, marks, {0, editor_h});
  if (has_error) {
    ImGui::PushStyleColor(ImGuiCol_Text, kRed);
    ImGui::TextWrapped("%s", shown.c_str());
    ImGui::PopStyleColor();
  }
  if (st.cursor >= 0) ImGui::TextDisabled("line %d of %d", st.cursor_line + 1, st.lines);
  else ImGui::TextDisabled("%d lines", st.lines);
  if (scene.ok && scene.error.empty() && st.path == scene.file) {
    ImGui::SameLine();
    ImGui::TextDisabled("  loaded, generation %llu", static_cast<unsigned long long>(scene.generation));
  }
}

}  // namespace arwb::ui
