// Checking what a scene names before anything is opened. Scenes are shared files, so a media path is untrusted:
// it must resolve inside the scene's folder (no "..", no absolute path, no symbolic link leading out), name a
// regular file (no device, FIFO or folder), and be an image or video by its first bytes. Images have their
// dimensions checked from the header before any decoding. URLs must be http or https.
#pragma once

#include "base/files.hpp"

#include <opencv2/core.hpp>

#include <filesystem>
#include <set>
#include <string>
#include <string_view>

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

// A file a scene names (an image, a video, a 3D model, a model's material library, buffer or texture), resolved
// inside the scene's folder by base/files.hpp's resolve_inside, or against `from_folder` inside it (a model's own
// references are relative to the model's folder): "../x.png: leaves the scene's folder", "x.png: no such file".
using ResolvedFile = ResolvedPath;
ResolvedFile resolve_scene_file(const std::filesystem::path& scene_dir, const std::string& relative,
                                const std::filesystem::path& from_folder = {});

// Every file resolve_scene_file resolved on this thread while the recorder lives (canonical absolute paths):
// `arwb export` loads and runs a scene under one to learn which files it reads (media, cube faces, models and
// what each model reads), whatever part of the scene asked. Recorders nest: an inner one hides the outer one
// until it ends. A thread's own list, since media are resolved on the thread that runs the scene (the offline
// store decodes nothing in the background).
class ResolvedFilesRecorder {
 public:
  ResolvedFilesRecorder();
  ~ResolvedFilesRecorder();
  ResolvedFilesRecorder(const ResolvedFilesRecorder&) = delete;
  ResolvedFilesRecorder& operator=(const ResolvedFilesRecorder&) = delete;
  const std::set<std::string>& files() const { return files_; }

 private:
  friend ResolvedFile resolve_scene_file(const std::filesystem::path&, const std::string&,
                                         const std::filesystem::path&);
  std::set<std::string> files_;
  ResolvedFilesRecorder* outer_ = nullptr;
};

// Resolves `relative` (as written in the scene) against `scene_dir` by resolve_scene_file's rules. Absolute paths and any ".." component are
// refused from the text alone, before the file system is asked; then the path is resolved (symbolic links
// followed) and must still lie inside the canonical scene folder. Only the first bytes and the image header are
// read, and only from a regular file. Errors name what the author wrote (control characters shown as '?'):
// "media/../../etc/passwd: leaves the scene's folder" (also for a link leading out),
// "/dev/zero: absolute paths are not allowed", "media/x.png: no such file",
// "media/fifo: not a regular file (FIFO)" (or "(folder)", "(character device)", ...),
// "media/notes.txt: not an image or video", "media/empty.png: empty file (0 bytes)",
// "anim.gif: unsupported image format (GIF)", a header problem ("media/bad.png: truncated header"),
// "media/huge.png: declares 60000x60000 pixels, more than 40000000",
// "media/long.png: declares 40000x16 pixels, a side longer than 32768".
CheckedPath check_media_path(const std::filesystem::path& scene_dir, const std::string& relative);

// Empty when `url` may be opened: http:// or https:// (scheme in any case), a host, a numeric port if any, no
// spaces or control characters (write them %20, ...), at most 2048 characters. Else the reason, naming the
// URL: "ftp://x: only http and https links are opened", "https://: no host", "https://a b: contains spaces
// or control characters", "https://h:8x/: invalid port", "https://...: longer than 2048 characters".
std::string check_url(const std::string& url);
// The host part of an http(s) URL ("opencv.org" for "https://opencv.org/releases"; without user and port;
// IPv6 literals keep their brackets), "" if none or if the URL is not http(s).
std::string url_host(const std::string& url);

}  // namespace arwb::media
