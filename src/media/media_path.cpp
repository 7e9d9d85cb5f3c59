#include "media/media_path.hpp"

#include "capture/image_header.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cctype>
#include <string_view>
#include <system_error>

namespace fs = std::filesystem;

namespace arwb::media {

namespace {

constexpr size_t kMaxUrlLength = 2048;

// The video container's name from read_image_header's documented refusal, "not an image (video: MP4/MOV)".
std::string video_format(const std::string& path) {
  std::string reason;
  (void)read_image_header(path, &reason);
  const std::string_view prefix = "not an image (video: ";
  if (reason.starts_with(prefix) && reason.ends_with(")"))
    return reason.substr(prefix.size(), reason.size() - prefix.size() - 1);
  return "video";
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

// The scheme of `url` in lower case when it is followed by "//" (http://, https://), else "".
// A URL is split as scheme "://" authority [path] [?query] [#fragment]; authority is [userinfo@]host[:port].
// A backslash ends the authority too, as browsers read http(s) URLs (WHATWG URL standard): otherwise
// "https://evil.example\@good.example/" would show good.example on its card and open evil.example.
std::string_view authority_of(std::string_view url, std::string* scheme) {
  const size_t colon = url.find(':');
  if (colon == std::string_view::npos) return {};
  *scheme = lower(url.substr(0, colon));
  if (url.substr(colon + 1, 2) != "//") return {};
  std::string_view rest = url.substr(colon + 3);
  return rest.substr(0, rest.find_first_of("/\\?#"));
}

}  // namespace

namespace {
thread_local ResolvedFilesRecorder* t_recorder = nullptr;
}

ResolvedFilesRecorder::ResolvedFilesRecorder() : outer_(t_recorder) { t_recorder = this; }
ResolvedFilesRecorder::~ResolvedFilesRecorder() { t_recorder = outer_; }

ResolvedFile resolve_scene_file(const fs::path& scene_dir, const std::string& relative, const fs::path& from_folder) {
  ResolvedFile file = resolve_inside(scene_dir, relative, from_folder, "the scene's folder");
  if (t_recorder && file.ok()) t_recorder->files_.insert(file.path);
  return file;
}

CheckedPath check_media_path(const fs::path& scene_dir, const std::string& relative) {
  CheckedPath out;
  const std::string name = shown_name(relative);
  const auto fail = [&](const std::string& reason) {
    out.path.clear();
    out.error = name + ": " + reason;
    return out;
  };

  const ResolvedFile file = resolve_scene_file(scene_dir, relative);
  if (!file.ok()) {
    out.error = file.error;
    return out;
  }
  out.path = file.path;
  switch (classify_path(out.path)) {
    case PathKind::image: {
      std::string reason;
      const std::optional<ImageHeader> header = read_image_header(out.path, &reason);
      if (!header) return fail(reason);
      const std::string declared =
          "declares " + std::to_string(header->width) + "x" + std::to_string(header->height) + " pixels, ";
      if (static_cast<long long>(header->width) * header->height > kMaxMediaPixels)
        return fail(declared + "more than " + std::to_string(kMaxMediaPixels));
      if (header->width > kMaxImageSide || header->height > kMaxImageSide)
        return fail(declared + "a side longer than " + std::to_string(kMaxImageSide));
      out.kind = MediaFileKind::image;
      out.size = cv::Size(header->width, header->height);
      out.format = header->format;
      return out;
    }
    case PathKind::video:
      out.kind = MediaFileKind::video;
      out.format = video_format(out.path);
      return out;
    case PathKind::missing: return fail("no such file");  // removed since the stat above
    case PathKind::folder: return fail("not a regular file (folder)");
    case PathKind::other: break;
  }
  // Say more than "not an image or video" where image_io knows more (empty, GIF, unreadable).
  std::string reason;
  (void)read_image_header(out.path, &reason);
  if (reason.starts_with("empty file") || reason.starts_with("unsupported image format") ||
      reason.starts_with("cannot be read"))
    return fail(reason);
  return fail("not an image or video");
}

std::string check_url(const std::string& url) {
  const std::string name = shown_name(url);
  if (url.empty()) return "(empty link): only http and https links are opened";
  if (url.size() > kMaxUrlLength)
    return name + ": longer than " + std::to_string(kMaxUrlLength) + " characters";
  for (const char c : url) {
    const auto u = static_cast<unsigned char>(c);
    // Spaces must be written %20; control characters have no place in a link and could confuse an opener.
    if (u <= 0x20 || u == 0x7f) return name + ": contains spaces or control characters";
  }
  std::string scheme;
  const std::string_view authority = authority_of(url, &scheme);
  if ((scheme != "http" && scheme != "https") || url.find("://") == std::string::npos)
    return name + ": only http and https links are opened";
  if (url_host(url).empty()) return name + ": no host";
  const size_t at = authority.rfind('@');
  const std::string_view host_port = at == std::string_view::npos ? authority : authority.substr(at + 1);
  const size_t bracket = host_port.rfind(']');
  const size_t colon = host_port.rfind(':');
  if (colon != std::string_view::npos && (bracket == std::string_view::npos || colon > bracket)) {
    const std::string_view port = host_port.substr(colon + 1);
    if (port.size() > 5 || !std::all_of(port.begin(), port.end(), [](char c) { return c >= '0' && c <= '9'; }))
      return name + ": invalid port";
  }
  return {};
}

std::string url_host(const std::string& url) {
  std::string scheme;
  std::string_view authority = authority_of(url, &scheme);
  if (scheme != "http" && scheme != "https") return {};
  const size_t at = authority.rfind('@');  // userinfo is not the host ("https://bank.com@evil.example")
  if (at != std::string_view::npos) authority = authority.substr(at + 1);
  if (authority.starts_with('[')) {  // IPv6 literal, brackets kept
    const size_t close = authority.find(']');
    return close == std::string_view::npos ? std::string() : std::string(authority.substr(0, close + 1));
  }
  return std::string(authority.substr(0, authority.find(':')));
}

}  // namespace arwb::media
