// The in-window file browser: a modal with a path field (Enter opens what is typed: a file opens, a folder is
// listed), the folder's entries (folders first, then the files of the kind being opened), up one folder, the
// recent files of that kind (newest first) and the favourite folders (a star toggles the one shown). Like a panel
// it does no I/O: listing a folder and opening a path are requests (list_dir, open_file) that the window carries
// out, with the results in Status (listing, recent, opened). Used by File > Open source / Open scene / Load
// preset, by the marker sheet dialog to choose where to save, and ready for calibration files.
#pragma once

#include "ui/context.hpp"
#include "ui/recent_files.hpp"

#include <string>

namespace arwb::ui {

struct FileBrowser {
  FileKind kind = FileKind::source;
  bool saving = false;      // choosing where to write: the path is handed back, not opened
  std::string title;        // the modal's title, "Open source"
  char path[1024] = "";     // the path field
  bool opening = false;     // open the modal at the next draw
  bool visible = false;     // the modal is open
  bool replace = false;     // the active path field's text is to be replaced by `path` (a new listing)
  int cursor_end = 0;       // frames left in which the path field's cursor goes to the end
  bool select_all = false;  // the path field, at its first activation after opening, selects all
  uint64_t listed = 0;      // the Status::listing version shown in the path field
  uint64_t opened = 0;      // Status::opened when the modal opened: a change closes it
};

// Asks `b` to open at its next draw for `kind`, listing `folder` (the working folder when ""). When saving,
// `name` is the file name proposed in the path field.
void open_browser(Context& ctx, FileBrowser& b, FileKind kind, const std::string& title, const std::string& folder,
                  bool saving = false, const std::string& name = "");
// Draws the modal while it is open; when saving, returns true with the path chosen in *chosen. Call it inside
// another modal to open over it.
bool draw_file_browser(Context& ctx, FileBrowser& b, std::string* chosen = nullptr);

}  // namespace arwb::ui
