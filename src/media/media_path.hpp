// Checking what a scene names before anything is opened. Scenes are shared files, so a media path is untrusted:
// it must resolve inside the scene's folder (no "..", no absolute path, no symbolic link leading out), name a
// regular file (no device, FIFO or folder), and be an image or video by its first bytes. Images have their
// dimensions checked from the header before any decoding. URLs must be http or https.
#pragma once

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>

namespace arwb::media {

enum class MediaFileKind { image, video };

// Largest image a scene may use (pixels); beyond it the texture alone would be hundreds of megabytes.
inline constexpr long long kMaxMediaPixels = 40'000'000;

struct CheckedPath {
  std::string path;            // absolute, canonical
  MediaFileKind kind = MediaFileKind::image;
  cv::Size size{};             // images: from the header
  std::string format;          // "PNG", "JPEG", "MP4/MOV", ...
  std::string error;           // empty when usable; else the reason, naming what the author wrote
  bool ok() const { return error.empty(); }
};

// Resolves `relative` (as written in the scene) against `scene_dir`. Errors read, e.g.,
// "media/../../etc/passwd: leaves the scene's folder", "/dev/zero: absolute paths are not allowed",
// "media/x.png: no such file", "media/fifo: not a regular file", "media/notes.txt: not an image or video",
// "media/huge.png: declares 60000x60000 pixels, more than 40000000".
CheckedPath check_media_path(const std::filesystem::path& scene_dir, const std::string& relative);

// Empty when `url` may be opened (http:// or https:// with a host and no control characters or spaces), else
// the reason: "ftp://x: only http and https links are opened".
std::string check_url(const std::string& url);
// The host part of an http(s) URL ("opencv.org" for "https://opencv.org/releases"), "" if none.
std::string url_host(const std::string& url);

}  // namespace arwb::media
