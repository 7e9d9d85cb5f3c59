// What an image file is without decoding it (image_header.hpp): base/files' check, then image_format's sniffing
// and header parsers.
#include "capture/image_header.hpp"

#include "base/files.hpp"
#include "capture/image_format.hpp"

#include <algorithm>
#include <filesystem>
#include <system_error>

namespace arwb {

using image_format::ByteSource;
using image_format::Format;
using image_format::kind_of;
using image_format::parse_header;
using image_format::ParseResult;
using image_format::sniff;

namespace image_format {

namespace {
// The largest image file read at all; load_image also bounds it by the pixels its header declares.
constexpr FileLimit kImageFile{"an image", std::uintmax_t{1} << 30};
}  // namespace

std::string open_image_file(const std::string& path, InputFile& in) {
  Result<InputFile> f = open_input_file(path, kImageFile);
  if (!f) return f.error().substr(std::min(f.error().size(), path.size() + 2));
  in = std::move(*f);
  if (in.size() == 0) return "empty file (0 bytes)";
  return {};
}

Format sniff_file(const std::string& path, std::string* reason) {
  InputFile in;
  *reason = open_image_file(path, in);
  if (!reason->empty()) return Format::unknown;
  ByteSource src(in);
  return sniff(src);
}

}  // namespace image_format

namespace fs = std::filesystem;

const char* to_string(PathKind kind) {
  switch (kind) {
    case PathKind::missing: return "missing";
    case PathKind::image: return "image";
    case PathKind::video: return "video";
    case PathKind::folder: return "folder";
    case PathKind::other: break;
  }
  return "other";
}

PathKind classify_path(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  switch (st.type()) {
    case fs::file_type::not_found: return PathKind::missing;
    case fs::file_type::directory: return PathKind::folder;
    case fs::file_type::regular: break;
    default: return PathKind::other;  // devices, sockets, pipes, or no access to the path
  }
  std::string reason;
  return kind_of(image_format::sniff_file(path, &reason));
}

std::optional<ImageHeader> read_image_header(const std::string& path, std::string* error) {
  std::string local;
  std::string& reason = error ? *error : local;
  reason.clear();
  InputFile in;
  reason = image_format::open_image_file(path, in);
  if (!reason.empty()) return std::nullopt;
  ByteSource src(in);
  ParseResult parsed = parse_header(sniff(src), src, &reason);
  if (!parsed) return std::nullopt;
  return parsed->header;
}

std::optional<ImageHeader> parse_image_header(std::span<const uint8_t> bytes, std::string* error) {
  std::string local;
  std::string& reason = error ? *error : local;
  reason.clear();
  if (bytes.empty()) {
    reason = "empty file (0 bytes)";
    return std::nullopt;
  }
  ByteSource src(bytes);
  ParseResult parsed = parse_header(sniff(src), src, &reason);
  if (!parsed) return std::nullopt;
  return parsed->header;
}

std::string image_limit_error(const ImageHeader& h, int64_t max_pixels) {
  const std::string declared = "declares " + std::to_string(h.width) + "x" + std::to_string(h.height) + " pixels, ";
  if (int64_t{h.width} * h.height > max_pixels)
    return declared + "more than the limit of " + std::to_string(max_pixels);
  if (h.width > kMaxImageSide || h.height > kMaxImageSide)
    return declared + "a side longer than the limit of " + std::to_string(kMaxImageSide);
  return {};
}

std::string phone_picture_problem(const ImageHeader& h) {
  if (h.format != "PNG" && h.format != "JPEG" && h.format != "WebP" && h.format != "BMP")
    return "a " + h.format + " picture: phones' browsers show PNG, JPEG and WebP";
  if (std::max(h.width, h.height) > kPhoneMaxImageSide)
    return "a " + std::to_string(h.width) + "x" + std::to_string(h.height) + " picture: many phones draw " +
           "at most " + std::to_string(kPhoneMaxImageSide) + " pixels a side";
  return "";
}

}  // namespace arwb
