// Reading images from paths a user names (image_io.hpp): files opened by base/files' check, headers and limits
// before any pixel is allocated (image_format.hpp), then decoding with the decoders' own lines kept off the
// terminal (library_output.hpp).
#include "capture/image_io.hpp"

#include "base/files.hpp"
#include "capture/image_format.hpp"
#include "capture/library_output.hpp"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <span>
#include <string_view>
#include <system_error>

namespace arwb {

using image_format::add_sat;
using image_format::ByteSource;
using image_format::check_complete;
using image_format::describe_unreadable;
using image_format::Format;
using image_format::kind_of;
using image_format::mul_sat;
using image_format::parse_header;
using image_format::ParseResult;
using image_format::sniff;

namespace {

namespace fs = std::filesystem;

// Whether a line on stderr is a decoder library's: libpng's default handlers ("libpng warning: iCCP: known
// incorrect sRGB profile", "libpng error: IDAT: CRC error") and libjpeg's warnings (jerror.h's JWRN_ texts; its
// errors go to OpenCV's handler, which prints nothing).
bool is_decoder_line(std::string_view line) {
  for (std::string_view start : {"libpng ", "Corrupt JPEG data", "Premature end of JPEG file", "Invalid SOS parameters",
                                 "Inconsistent progression sequence", "Unknown Adobe color transform",
                                 "Warning: unknown JFIF revision", "Application transferred too"})
    if (line.substr(0, start.size()) == start) return true;
  return false;
}

// cv::imdecode without the decoder libraries' own lines on the terminal (libpng and libjpeg print straight to
// stderr); the first such line is returned in *said, "IDAT: CRC error", for our own message.
cv::Mat decode_quietly(std::span<const uint8_t> bytes, int flags, std::string* said) {
  cv::Mat image;
  const std::string first = without_library_lines(
      [&] {
        try {
          // The Mat only wraps the caller's bytes (checked by the caller to fit an int); imdecode does not write
          // to them.
          const cv::Mat buf(1, static_cast<int>(bytes.size()), CV_8U, const_cast<uint8_t*>(bytes.data()));
          image = cv::imdecode(buf, flags);
        } catch (const cv::Exception&) {
          image.release();
        } catch (const std::exception&) {  // std::bad_alloc from a decoder library
          image.release();
        }
      },
      is_decoder_line);
  std::string_view what = first;
  for (std::string_view prefix : {"libpng error: ", "libpng warning: "})
    if (what.substr(0, prefix.size()) == prefix) what.remove_prefix(prefix.size());
  *said = std::string(what.substr(0, 200));
  return image;
}

}  // namespace

LoadedImage load_image(const std::string& path, int flags, int64_t max_pixels) {
  keep_opencv_quiet();
  LoadedImage out;
  const auto failed = [&](const std::string& reason) {
    out.image.release();
    out.error = path + ": " + reason;
    return out;
  };
  std::string reason;
  InputFile in;
  if (!(reason = image_format::open_image_file(path, in)).empty()) return failed(reason);
  const uint64_t size = in.size();

  // Everything that bounds memory is decided from the header, read straight from the file.
  ByteSource file(in);
  const Format format = sniff(file);
  ParseResult header = parse_header(format, file, &reason);
  if (!header) return failed(reason);
  if (!(reason = image_limit_error(header->header, max_pixels)).empty()) return failed(reason);
  // A valid header followed by gigabytes of anything must not be read into memory either. The bound is generous:
  // 24 bytes a pixel covers 4 float channels and 16-bit ASCII PPM, 64 MiB covers metadata and appended data.
  const uint64_t pixels = static_cast<uint64_t>(header->header.width) * static_cast<uint64_t>(header->header.height);
  if (size > add_sat(mul_sat(pixels, 24), uint64_t{64} << 20))
    return failed("file is " + std::to_string(size) + " bytes, too large for its declared " +
                  std::to_string(header->header.width) + "x" + std::to_string(header->header.height) + " pixels");

  // Read the file once and decode exactly those bytes. The header is checked again on them, as the file may
  // have been replaced since: whatever OpenCV allocates follows from these bytes, not from the earlier reads.
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  if (in.read_at(0, bytes.data(), bytes.size()) != static_cast<long long>(size))
    return failed("read error (the file changed while being read)");
  return decode_image(bytes, path, flags, max_pixels);
}

LoadedImage decode_image(std::span<const uint8_t> bytes, const std::string& name, int flags, int64_t max_pixels) {
  keep_opencv_quiet();
  LoadedImage out;
  const auto failed = [&](const std::string& reason) {
    out.image.release();
    out.error = name + ": " + reason;
    return out;
  };
  if (bytes.empty()) return failed("empty file (0 bytes)");
  std::string reason;
  ByteSource memory(bytes);
  const Format format = sniff(memory);
  ParseResult header = parse_header(format, memory, &reason);
  if (!header) return failed(reason);
  if (!(reason = image_limit_error(header->header, max_pixels)).empty()) return failed(reason);
  if (!(reason = check_complete(format, *header, bytes)).empty()) return failed(reason);

  // cv::imdecode takes the bytes as one Mat row, whose length is an int.
  if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max()))
    return failed("file is " + std::to_string(bytes.size()) + " bytes, more than the decoder takes");
  std::string decoder_said;
  out.image = decode_quietly(bytes, flags, &decoder_said);
  if (out.image.empty())
    return failed("corrupt or truncated image data" + (decoder_said.empty() ? "" : " (" + decoder_said + ")"));
  return out;
}

std::vector<std::string> list_images(const std::string& folder, std::vector<std::string>* skipped,
                                     std::string* error) {
  if (error) error->clear();
  const auto failed = [&](const std::string& reason) {
    if (error) *error = folder + ": " + reason;
    return std::vector<std::string>{};
  };
  std::error_code ec;
  const fs::file_status st = fs::status(folder, ec);
  if (st.type() == fs::file_type::not_found) return failed("no such folder");
  if (ec) return failed("cannot access (" + ec.message() + ")");
  if (st.type() != fs::file_type::directory) return failed("not a folder");

  std::vector<std::pair<std::string, std::string>> entries;  // (name, path)
  fs::directory_iterator it(folder, ec);
  if (ec) return failed("cannot list (" + ec.message() + ")");
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    std::string name = it->path().filename().string();
    if (name.empty() || name[0] == '.') continue;
    entries.emplace_back(std::move(name), it->path().string());
  }
  if (ec) return failed("cannot list (" + ec.message() + ")");
  std::sort(entries.begin(), entries.end());

  std::vector<std::string> images;
  for (const auto& [name, path] : entries) {
    std::error_code type_ec;
    if (fs::is_directory(path, type_ec)) continue;  // not recursive
    std::string reason;
    const Format f = image_format::sniff_file(path, &reason);
    if (reason.empty() && kind_of(f) == PathKind::image) {
      images.push_back(path);
    } else if (skipped) {
      // Say why when it is more than "not an image": unreadable, empty, a video, a format we do not read.
      const std::string why = !reason.empty() ? reason : f == Format::unknown ? "not an image" : describe_unreadable(f);
      skipped->push_back(path + ": skipped, " + why);
    }
  }
  return images;
}

}  // namespace arwb
