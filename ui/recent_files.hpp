// What the file browser remembers between runs (the last files opened of each kind, folders starred), and what
// kind of thing a file name is for when it is opened or dropped on the window. Pure logic: the window reads and
// writes the file (config_dir/recent.txt) and lists folders.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace arwb::ui {

// What is being opened: decides the browser's filter and where a chosen file goes.
enum class FileKind { source, scene, preset, calibration, bundle, count };
constexpr int kFileKindCount = static_cast<int>(FileKind::count);
const char* file_kind_name(FileKind k);   // "source", "scene", "preset", "calibration", "bundle"

// A file or folder dropped on the window, by its name: a scene (.lua, .xml), a preset (.yml, .yaml), or a
// source when it is a folder or an image or video (is_media: the caller read its first bytes, see
// capture/image_io.hpp classify_path); anything else is none.
enum class DropKind { scene, preset, source, none };
DropKind drop_kind(const std::string& path, bool is_folder, bool is_media);

// Whether the browser lists a file of this name for `kind` (folders are always listed). Sources: images and
// videos by extension; scenes: .lua, .xml; presets: .yml, .yaml; calibrations: .yml, .yaml, .xml, .json; bundles (`arwb export`): .arwb, .zip.
bool listed_for(FileKind kind, const std::string& name);

struct RecentFiles {
  static constexpr size_t kMax = 10;
  std::array<std::vector<std::string>, kFileKindCount> recent;   // newest first, at most kMax each
  std::vector<std::string> favourites;                           // folders, in the order starred
  // Lines this version does not understand (a kind a later version writes, a line edited by hand), written back as
  // they were: saving never loses what the file held.
  std::vector<std::string> kept;
  // The file could not be read and could not be set aside either: it must not be written over.
  bool unsaved = false;

  // `path` opened as `kind`: moves to the front (once), the oldest beyond kMax dropped.
  void add(FileKind kind, const std::string& path);
  const std::vector<std::string>& of(FileKind kind) const { return recent[static_cast<size_t>(kind)]; }
  bool is_favourite(const std::string& folder) const;
  void toggle_favourite(const std::string& folder);
};

// The file's text: one "kind<TAB>path" line each ("source", "scene", "preset", "calibration", "favourite").
std::string recent_text(const RecentFiles& r);
// Reads it back; lines it cannot read are kept as they are (RecentFiles::kept) and named in `problems`
// ("line 3: unknown kind 'x'").
RecentFiles parse_recent(const std::string& text, std::vector<std::string>* problems);

}  // namespace arwb::ui
