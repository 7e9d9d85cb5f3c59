// Files as whole texts: read one (with a size limit) and replace one atomically.
#pragma once

#include <string>

namespace arwb {

// Replaces `path` with `text`: the new text goes to a temporary file beside the old one and replaces it in one
// rename, so a full disk or a crash never leaves half a script (and the watcher never reads one).
bool write_file_atomically(const std::string& path, const std::string& text, std::string* error);

}  // namespace arwb
