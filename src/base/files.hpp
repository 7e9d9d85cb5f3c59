// Files as whole texts: read one (with a size limit) and replace one atomically.
#pragma once

#include "base/result.hpp"

#include <cstdint>
#include <string>

namespace arwb {

// The whole of the text file at `path` (bytes as they are: no newline or encoding conversion). The one way the
// project reads a file a user names (scenes, tours, presets, truth sets). On failure the message is
// "<path>: <reason>", the path first and as given, so a caller may swap it for a display name:
// "no such file", "not a regular file" (a folder, a device), "larger than 16 MiB" (max_bytes), or
// "cannot be read (<system reason>)".
Result<std::string> read_text_file(const std::string& path, std::uintmax_t max_bytes);

// Replaces `path` with `text`: the new text goes to a temporary file beside the old one and replaces it in one
// rename, so a full disk or a crash never leaves half a script (and the watcher never reads one).
bool write_file_atomically(const std::string& path, const std::string& text, std::string* error);

}  // namespace arwb
