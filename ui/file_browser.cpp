#include "ui/file_browser.hpp"

#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace arwb::ui {

namespace {

void set_path(FileBrowser& b, const std::string& p) { std::snprintf(b.path, sizeof b.path, "%s", p.c_str()); }

std::string join(const std::string& dir, const std::string& name) {
  if (dir.empty()) return name;
  return dir.back() == '/' ? dir + name : dir + "/" + name;
}

std::string base_name(const std::string& p) {
  const size_t slash = p.find_last_of('/');
  return slash == std::string::npos ? p : p.substr(slash + 1);
}

// The left column: recent files of this kind, favourite folders.
void places(Context& ctx, FileBrowser& b) {
  const RecentFiles& r = ctx.status.recent;
  ImGui::TextDisabled("Recent %s files", file_kind_name(b.kind));
  const auto& recent = r.of(b.kind);
  if (recent.empty()) ImGui::TextDisabled("  none yet");
  for (const std::string& p : recent) {
    ImGui::PushID(p.c_str());
    if (ImGui::Selectable(base_name(p).c_str())) {
      if (b.saving) set_path(b, p);
      else ctx.request(OpenFile{p, b.kind});
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", p.c_str());
    ImGui::PopID();
  }
  ImGui::Spacing();
  ImGui::TextDisabled("Favourite folders");
  if (r.favourites.empty()) ImGui::TextDisabled("  star a folder to keep it here");
  for (const std::string& f : r.favourites) {
    ImGui::PushID(f.c_str());
    if (ImGui::Selectable(base_name(f).empty() ? f.c_str() : base_name(f).c_str())) ctx.request(ListDir{f});
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", f.c_str());
    ImGui::PopID();
  }
}

// The right column: the folder's entries, folders first, then the files of this kind.
void entries(Context& ctx, FileBrowser& b) {
  const DirListing& l = ctx.status.listing;
  // Saving: the files with the proposed name's extension (a sheet among the other sheets).
  const std::string name = base_name(b.path);
  const size_t dot = name.find_last_of('.');
  const std::string ext = b.saving && dot != std::string::npos ? name.substr(dot) : std::string();
  auto shown = [&](const std::string& n) {
    if (b.saving) return ext.empty() || (n.size() >= ext.size() && n.compare(n.size() - ext.size(), ext.size(), ext) == 0);
    return listed_for(b.kind, n);
  };
  int others = 0;
  for (const DirEntry& e : l.entries) {
    if (!e.folder && !shown(e.name)) {
      ++others;
      continue;
    }
    const std::string full = join(l.dir, e.name);
    const std::string label = e.folder ? e.name + "/" : e.name;
    ImGui::PushID(e.name.c_str());
    if (ImGui::Selectable(label.c_str(), full == b.path, ImGuiSelectableFlags_AllowDoubleClick)) {
      if (e.folder && (ImGui::IsMouseDoubleClicked(0) || !b.saving)) ctx.request(ListDir{full});
      else if (!e.folder && ImGui::IsMouseDoubleClicked(0) && !b.saving) {
        ctx.request(OpenFile{full, b.kind});
      } else {
        set_path(b, full);
      }
    }
    ImGui::PopID();
  }
  if (l.entries.empty() && l.error.empty()) ImGui::TextDisabled("(empty folder)");
  if (others > 0) ImGui::TextDisabled("%d other file%s not shown (not %s)", others, others == 1 ? "" : "s",
                                      b.saving ? ("*" + ext).c_str() : (std::string("a ") + file_kind_name(b.kind)).c_str());
}

// While the path field is active: a new listing's path replaces the field's text, and after Enter the cursor goes
// to the end; when the browser has just opened, all of it is selected, so typing replaces it.
int path_callback(ImGuiInputTextCallbackData* d) {
  auto* b = static_cast<FileBrowser*>(d->UserData);
  if (b->replace) {
    const std::string text = b->path;
    d->DeleteChars(0, d->BufTextLen);
    d->InsertChars(0, text.c_str());
    b->replace = false;
  }
  if (b->cursor_end > 0) d->CursorPos = d->SelectionStart = d->SelectionEnd = d->BufTextLen;
  if (b->select_all) {   // the first time it is active after the browser opened: typing replaces the folder
    d->SelectionStart = 0;
    d->CursorPos = d->SelectionEnd = d->BufTextLen;
    b->select_all = false;
  }
  return 0;
}

}  // namespace

void open_browser(Context& ctx, FileBrowser& b, FileKind kind, const std::string& title, const std::string& folder,
                  bool saving, const std::string& name) {
  b.kind = kind;
  b.title = title;
  b.saving = saving;
  b.opening = true;
  b.opened = ctx.status.opened;
  b.listed = ctx.status.listing.version;
  set_path(b, saving ? join(folder, name) : folder);
  ctx.request(ListDir{folder.empty() ? std::string(".") : folder});
}

bool draw_file_browser(Context& ctx, FileBrowser& b, std::string* chosen) {
  // One popup (and so one ImGui window) per browser: the window has several (File > Open, the marker sheet's and
  // the Calibrate panel's Save...), and two sharing an id would draw into one window, each taking the other's keys.
  char tag[40];
  std::snprintf(tag, sizeof tag, "###file_browser_%p", static_cast<const void*>(&b));
  const std::string id = b.title + tag;
  bool focus = false;
  if (b.opening) {
    ImGui::OpenPopup(id.c_str());
    b.opening = false;
    focus = true;   // typing goes to the path field at once, as in a desktop's file dialog
  }
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  ImGui::SetNextWindowPos(vp->GetCenter(), ImGuiCond_Appearing, {0.5f, 0.5f});
  ImGui::SetNextWindowSize({std::min(vp->Size.x * 0.8f, 900 * ctx.scale), vp->Size.y * 0.7f}, ImGuiCond_Appearing);
  b.visible = ImGui::BeginPopupModal(id.c_str(), nullptr, ImGuiWindowFlags_NoSavedSettings);
  if (!b.visible) return false;
  const DirListing& l = ctx.status.listing;
  // A new listing (a folder clicked, Enter on a folder): the path field follows it; when saving, the name stays.
  if (l.version != b.listed) {
    b.listed = l.version;
    if (!l.dir.empty()) {
      set_path(b, b.saving ? join(l.dir, base_name(b.path)) : l.dir);
      b.replace = true;   // an active field keeps its own copy of the text: the callback replaces it
    }
  }
  if (ctx.status.opened != b.opened) {   // the window opened what was picked
    ImGui::CloseCurrentPopup();
    ImGui::EndPopup();
    b.visible = false;
    return false;
  }
  bool done = false, picked = false;
  const char* act = b.saving ? "Save" : "Open";
  const float act_w = ImGui::CalcTextSize(act).x + ImGui::GetStyle().FramePadding.x * 2 + ImGui::GetStyle().ItemSpacing.x;
  // The path field takes the keyboard when the browser opens, all selected: typing replaces it.
  if (focus) {
    ImGui::SetKeyboardFocusHere();
    b.select_all = true;
  }
  ImGui::SetNextItemWidth(-act_w);
  const bool enter = ImGui::InputTextWithHint(
      "##browser_path", "a path: Enter opens it", b.path, sizeof b.path,
      ImGuiInputTextFlags_EnterReturnsTrue | ImGuiInputTextFlags_CallbackAlways, path_callback, &b);
  if (!ImGui::IsItemActive()) b.replace = false;   // an inactive field shows b.path as it is
  if (enter) {
    // Typing goes on in the field after Enter listed a folder, at the end of the folder's path.
    ImGui::SetKeyboardFocusHere(-1);
    b.cursor_end = 3;
  }
  if (b.cursor_end > 0) --b.cursor_end;
  ImGui::SameLine();
  if ((ImGui::Button(act) || enter) && b.path[0] != 0) {
    if (b.saving && chosen) {
      *chosen = b.path;
      done = picked = true;
    } else {
      ctx.request(OpenFile{b.path, b.kind});
    }
  }
  ImGui::BeginDisabled(l.parent.empty());
  if (ImGui::Button("Up")) ctx.request(ListDir{l.parent});
  ImGui::EndDisabled();
  ImGui::SameLine();
  const bool fav = ctx.status.recent.is_favourite(l.dir);
  ImGui::BeginDisabled(l.dir.empty());
  if (ImGui::Button(fav ? "Unstar folder" : "Star folder")) ctx.request(ToggleFavourite{l.dir});
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::TextDisabled("%s", l.dir.c_str());
  if (!l.error.empty()) ImGui::TextColored({1, 0.45f, 0.4f, 1}, "%s", l.error.c_str());
  if (b.kind == FileKind::source && !b.saving) {
    if (ImGui::SmallButton("Use this folder")) ctx.request(OpenFile{l.dir, b.kind, true});
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Its images, one after another, as the source.");
    ImGui::SameLine();
    if (ImGui::SmallButton("Synthetic source")) ctx.request(OpenFile{"synthetic", b.kind});
    for (int cam : ctx.status.cameras) {
      const std::string spec = "camera:" + std::to_string(cam);
      ImGui::SameLine();
      if (ImGui::SmallButton(spec.c_str())) ctx.request(OpenFile{spec, b.kind});
    }
    if (ctx.status.cameras.empty()) {
      ImGui::SameLine();
      ImGui::TextDisabled("(no camera found)");
    }
  }
  if (b.kind == FileKind::bundle && !b.saving) {
    // An exported bundle is a folder as often as a zip: the folder listed is the one played.
    if (ImGui::SmallButton("Play this folder")) ctx.request(OpenFile{l.dir, b.kind, true});
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("The folder shown, as a bundle (it holds manifest.json).");
  }
  const float bottom = ImGui::GetFrameHeightWithSpacing() + ImGui::GetStyle().ItemSpacing.y;
  const float left_w = std::min(260 * ctx.scale, ImGui::GetContentRegionAvail().x * 0.35f);
  ImGui::BeginChild("##places", {left_w, -bottom}, true);
  places(ctx, b);
  ImGui::EndChild();
  ImGui::SameLine();
  ImGui::BeginChild("##entries", {0, -bottom}, true);
  entries(ctx, b);
  ImGui::EndChild();
  if (ImGui::Button("Cancel") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) done = true;
  if (done) {
    ImGui::CloseCurrentPopup();
    b.visible = false;
  }
  ImGui::EndPopup();
  return picked;
}

}  // namespace arwb::ui
