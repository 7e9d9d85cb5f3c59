// YAML files a user names (presets, custom dictionaries, calibration files), opened for OpenCV's FileStorage the
// one safe way: base/files' check and UTF-8, the nesting depth checked on the text (OpenCV's parser recurses
// without a limit: 40,000 "[" overflow the stack), then parsed from that same text in memory, so what was checked
// is what is parsed. OpenCV's own error text (its source file, function and error code) never reaches the user.
#pragma once

#include "base/files.hpp"
#include "base/result.hpp"

#include <opencv2/core.hpp>

#include <string>

namespace arwb {

// Opens `path` into *fs. Fails with one line naming the file: read_text_file's messages, check_yaml_depth's
// ("p.yml:3: nested deeper than 32 levels"), or "p.yml:LINE: malformed YAML (<what OpenCV's parser said>)".
// A file without OpenCV's "%YAML:1.0" first line gets one, as plain YAML is written without it; line numbers in
// messages are the file's own.
Status open_yaml_file(const std::string& path, const FileLimit& limit, cv::FileStorage* fs);

}  // namespace arwb
