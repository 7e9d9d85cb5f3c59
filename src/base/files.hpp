// Files a user names: the one check every reader makes before opening one, reading a whole text file, and
// replacing one atomically.
#pragma once

#include "base/result.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace arwb {

// A kind of file the project reads and the largest one it accepts. The kind is named in the size message
// ("larger than 1 MiB, the limit for a preset").
struct FileLimit {
  const char* kind;          // with its article: "a preset", "a dictionary", "a scene", "an image" ...
  std::uintmax_t max_bytes;  // a round number: it is printed as written ("16 MiB")
};

// Whether `path` may be read as a file of this kind, decided from stat() alone, so that it cannot block or read
// anything: it exists ("no such file"), is a regular file, symbolic links followed ("not a regular file (a FIFO)",
// "(a folder)", "(a character device)", "(a block device)", "(a socket)"), and is not larger than the limit
// ("larger than 1 MiB, the limit for a preset"). A FIFO would block the opener until a writer comes, and
// /dev/zero or /dev/urandom would never end. On failure the message is "<path>: <reason>", the path as given.
// Every reader of a user's path goes through this (or through open_input_file / read_text_file, which call it).
Status check_input_file(const std::string& path, const FileLimit& limit);

// What an author wrote, fit for one line of a message: control characters shown as '?', long text cut with "…".
std::string shown_name(std::string_view written);

// A file named inside a shared folder (a scene's media, a model's textures, a lab's clips), resolved and checked:
// `relative` against `folder`, or against `from` inside it (a model's own references are relative to the
// model's folder; `from` is then checked already). Absolute paths and any ".." component are refused from the
// text alone, before the file system is asked; then the path is resolved (symbolic links followed) and must still
// lie inside the canonical folder, and name a regular file. Nothing is read. Errors name `relative` and call the
// folder `folder_name`: "../x.png: leaves the scene's folder" (also for a link leading out), "/dev/zero: absolute
// paths are not allowed", "x.png: no such file", "fifo: not a regular file (FIFO)", "(folder)", ...
struct ResolvedPath {
  std::string path;    // absolute, canonical; empty on failure
  std::string error;   // empty when usable
  bool ok() const { return error.empty(); }
};
ResolvedPath resolve_inside(const std::filesystem::path& folder, const std::string& relative,
                            const std::filesystem::path& from, const std::string& folder_name);

// A regular file open for reading: a descriptor that is closed with the object.
class InputFile {
 public:
  InputFile() = default;
  InputFile(InputFile&& o) noexcept : fd_(o.fd_), size_(o.size_) { o.fd_ = -1; }
  InputFile& operator=(InputFile&& o) noexcept;
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;
  ~InputFile();

  // The size of what was opened (not of what the path named a moment earlier).
  std::uint64_t size() const { return size_; }
  // Reads up to n bytes at offset; the number read (less at the end of the file), or -1 on a read error.
  long long read_at(std::uint64_t offset, void* buf, std::size_t n) const;

 private:
  friend Result<InputFile> open_input_file(const std::string& path, const FileLimit& limit);
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// check_input_file, then opens the path without blocking (O_NONBLOCK: if the path was swapped for a FIFO after the
// check, the open returns at once) and checks the opened descriptor again the same way (fstat), so what is read is
// what was checked. Messages as check_input_file's, plus "cannot be read (<system reason>)".
Result<InputFile> open_input_file(const std::string& path, const FileLimit& limit);

// The whole of the text file at `path`, which must be UTF-8 (see check_utf8_text in base/text.hpp): the bytes as
// they are, no newline conversion, except that a UTF-8 byte order mark at the start is dropped (some Windows
// editors write one; it carries nothing in UTF-8, and Lua, OpenCV's YAML reader and our line numbers would trip
// on it). The one way the project reads a text file a user names (scenes, tours, presets, dictionaries, truth
// sets, the script editor's file). Messages as open_input_file's, and check_utf8_text's.
Result<std::string> read_text_file(const std::string& path, const FileLimit& limit);
// The same bytes without the text checks, for files of ours that may end inside a character (a line cut short by
// an interruption).
Result<std::string> read_file_bytes(const std::string& path, const FileLimit& limit);

// Replaces `path` with `text`: the new text goes to a temporary file beside the old one and replaces it in one
// rename, so a full disk or a crash never leaves half a script (and the watcher never reads one).
bool write_file_atomically(const std::string& path, const std::string& text, std::string* error);
// The same for files that belong together (a calibration and the paper's two files): every text goes to its
// temporary file first, and only when all are written are they renamed into place, so a folder that cannot be
// written or a full disk replaces none of them. A rename that fails after others (rare: each temporary file is
// already beside its file) leaves those before it replaced. *failed is the path the error is about.
bool write_files_atomically(const std::vector<std::pair<std::string, std::string>>& path_and_text,
                            std::string* failed, std::string* error);

// A file of ours that cannot be read (too large, not UTF-8, malformed) is never written over: set_aside renames
// it to PATH.bad, or PATH.bad.2, PATH.bad.3 ... when that is taken (never replacing an older one), and returns the
// new path for the message that tells the user where it went. An error when it cannot be renamed ("<path>: cannot
// be set aside (reason)"), or is not a regular file ("<path>: not a regular file, left as it is": a FIFO, a device
// or a folder is not ours to move); the caller must then not write PATH either.
Result<std::string> set_aside(const std::string& path);

}  // namespace arwb
