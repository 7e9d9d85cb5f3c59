// What an image file's bytes say before it is decoded (internal to src/capture): its format by its signature,
// its header's dimensions, and whether its data is complete. image_io.cpp reads files and decodes through these;
// the parsers read through a ByteSource, so a header is read the same way from a file or from memory.
#pragma once

#include "base/files.hpp"
#include "capture/image_header.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace arwb::image_format {

// a * b, or the largest uint64_t when that overflows: sizes computed from hostile headers must not wrap around.
uint64_t mul_sat(uint64_t a, uint64_t b);
uint64_t add_sat(uint64_t a, uint64_t b);

// Random access to the bytes of a file or of a buffer. Header parsers go through it so that the same code reads
// a header straight from a file (a few small reads, whatever the file's size) or from the bytes load_image holds.
class ByteSource {
 public:
  explicit ByteSource(std::span<const uint8_t> bytes) : mem_(bytes), size_(bytes.size()) {}
  explicit ByteSource(const InputFile& file) : file_(&file), size_(file.size()) {}

  uint64_t size() const { return size_; }

  // The n bytes at offset, valid until the next call; nullptr when the source ends before them.
  const uint8_t* at(uint64_t offset, size_t n);

 private:
  static constexpr size_t kMinRead = 4096;
  static constexpr size_t kMaxRead = 64 * 1024;
  std::span<const uint8_t> mem_;
  const InputFile* file_ = nullptr;
  uint64_t size_ = 0;
  std::vector<uint8_t> window_;
  uint64_t window_offset_ = 0;
};

enum class Format {
  unknown,
  png, jpeg, bmp, tiff, webp, pbm, pgm, ppm,  // images we read
  gif, heif, jpeg2000, openexr,               // images we recognise but do not read (see describe_unreadable)
  mp4, avi, mkv, mpeg_ts, mpeg_ps,            // videos
};

PathKind kind_of(Format f);
const char* name_of(Format f);
// Why a file of this format is not loaded, for formats load_image does not read.
std::string describe_unreadable(Format f);

// The format from a file's first bytes (as many as there are, up to the 512 that tell every format apart).
Format sniff(std::span<const uint8_t> b);
Format sniff(ByteSource& src);

struct ParsedHeader {
  ImageHeader header;
  // Bytes the file must have for the pixel data its header declares, where that is known from the header alone
  // (binary PNM, uncompressed BMP, WebP's RIFF size); 0 when unknown.
  uint64_t min_file_size = 0;
};

using ParseResult = std::optional<ParsedHeader>;

// The header of a file of format f; nullopt and *error the reason ("truncated header", "invalid header (...)",
// or describe_unreadable's for a format load_image does not read).
ParseResult parse_header(Format f, ByteSource& src, std::string* error);

// Opens a path that must be a non-empty regular file of at most 1 GiB (base/files' check, so a FIFO or device
// never blocks or streams); on failure returns the reason without the path ("empty file (0 bytes)").
std::string open_image_file(const std::string& path, InputFile& in);
// The format of a file from its first bytes, or unknown and *reason why it cannot be read.
Format sniff_file(const std::string& path, std::string* reason);

// Why the data of a file whose header parsed is incomplete, or empty when it seems complete.
std::string check_complete(Format f, const ParsedHeader& h, std::span<const uint8_t> b);

}  // namespace arwb::image_format
