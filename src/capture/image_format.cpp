// What an image file's bytes say before it is decoded (image_format.hpp): signatures, headers, completeness.
// [SECTION] Index
//   Bytes         big- and little-endian reads, saturating sizes, ByteSource
//   Signatures    the format by its first bytes
//   Headers       each format's dimensions, read as far as the header goes and no further
//   Completeness  whether the whole file holds the data its header declares
#include "capture/image_format.hpp"

#include <algorithm>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <string_view>

namespace arwb::image_format {
namespace {

// [SECTION] Bytes

uint16_t be16(const uint8_t* p) { return static_cast<uint16_t>(p[0] << 8 | p[1]); }
uint16_t le16(const uint8_t* p) { return static_cast<uint16_t>(p[1] << 8 | p[0]); }
uint32_t be32(const uint8_t* p) { return uint32_t{p[0]} << 24 | uint32_t{p[1]} << 16 | uint32_t{p[2]} << 8 | p[3]; }
uint32_t le32(const uint8_t* p) { return uint32_t{p[3]} << 24 | uint32_t{p[2]} << 16 | uint32_t{p[1]} << 8 | p[0]; }
uint32_t le24(const uint8_t* p) { return uint32_t{p[2]} << 16 | uint32_t{p[1]} << 8 | p[0]; }
uint64_t be64(const uint8_t* p) { return uint64_t{be32(p)} << 32 | be32(p + 4); }
uint64_t le64(const uint8_t* p) { return uint64_t{le32(p + 4)} << 32 | le32(p); }

}  // namespace

uint64_t mul_sat(uint64_t a, uint64_t b) {
  if (a != 0 && b > std::numeric_limits<uint64_t>::max() / a) return std::numeric_limits<uint64_t>::max();
  return a * b;
}
uint64_t add_sat(uint64_t a, uint64_t b) {
  return b > std::numeric_limits<uint64_t>::max() - a ? std::numeric_limits<uint64_t>::max() : a + b;
}

const uint8_t* ByteSource::at(uint64_t offset, size_t n) {
  if (offset > size_ || n > size_ - offset) return nullptr;
  if (!file_) return mem_.data() + offset;
  if (offset >= window_offset_ && offset + n <= window_offset_ + window_.size())
    return window_.data() + (offset - window_offset_);
  if (n > kMaxRead) return nullptr;  // parsers only ask for small pieces
  // Read a little ahead, as parsers go on from where they were, but not much: classifying a folder of large
  // files should not read 64 KiB of each.
  const size_t len = static_cast<size_t>(std::min<uint64_t>(std::max(n, kMinRead), size_ - offset));
  window_.resize(len);
  if (file_->read_at(offset, window_.data(), len) != static_cast<long long>(len)) {  // it shrank since opened
    window_.clear();
    return nullptr;
  }
  window_offset_ = offset;
  return window_.data();
}

// [SECTION] Signatures

PathKind kind_of(Format f) {
  switch (f) {
    case Format::png: case Format::jpeg: case Format::bmp: case Format::tiff: case Format::webp:
    case Format::pbm: case Format::pgm: case Format::ppm:
      return PathKind::image;
    case Format::mp4: case Format::avi: case Format::mkv: case Format::mpeg_ts: case Format::mpeg_ps:
      return PathKind::video;
    default:
      return PathKind::other;
  }
}

const char* name_of(Format f) {
  switch (f) {
    case Format::png: return "PNG";
    case Format::jpeg: return "JPEG";
    case Format::bmp: return "BMP";
    case Format::tiff: return "TIFF";
    case Format::webp: return "WebP";
    case Format::pbm: return "PBM";
    case Format::pgm: return "PGM";
    case Format::ppm: return "PPM";
    case Format::gif: return "GIF";
    case Format::heif: return "HEIF/AVIF";
    case Format::jpeg2000: return "JPEG 2000";
    case Format::openexr: return "OpenEXR";
    case Format::mp4: return "MP4/MOV";
    case Format::avi: return "AVI";
    case Format::mkv: return "MKV/WebM";
    case Format::mpeg_ts: return "MPEG-TS";
    case Format::mpeg_ps: return "MPEG-PS";
    case Format::unknown: break;
  }
  return "unknown";
}

std::string describe_unreadable(Format f) {
  switch (kind_of(f)) {
    case PathKind::video: return std::string("not an image (video: ") + name_of(f) + ")";
    case PathKind::image: return {};
    default: break;
  }
  // OpenCV may decode some of these (JPEG 2000, OpenEXR), but without a header check of our own its allocation
  // is not bounded, and GIF/HEIF it cannot decode at all in 4.6.
  if (f != Format::unknown) return std::string("unsupported image format (") + name_of(f) + ")";
  return "not an image (unknown signature)";
}

namespace {

bool has_bytes(std::span<const uint8_t> b, size_t offset, std::initializer_list<uint8_t> sig) {
  if (b.size() < offset + sig.size()) return false;
  return std::equal(sig.begin(), sig.end(), b.begin() + static_cast<std::ptrdiff_t>(offset));
}
bool has_text(std::span<const uint8_t> b, size_t offset, std::string_view text) {
  if (b.size() < offset + text.size()) return false;
  return std::memcmp(b.data() + offset, text.data(), text.size()) == 0;
}
bool is_pnm_space(uint8_t c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

// Enough bytes to tell every format apart (MPEG-TS needs three 188-byte packets).
constexpr size_t kSniffBytes = 512;

}  // namespace

Format sniff(std::span<const uint8_t> b) {
  if (has_bytes(b, 0, {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'})) return Format::png;
  if (has_bytes(b, 0, {0xFF, 0xD8, 0xFF})) return Format::jpeg;
  // "BM" alone is too weak (text can start with it): also require a known info header size.
  if (has_text(b, 0, "BM") && b.size() >= 18) {
    const uint32_t info = le32(b.data() + 14);
    if (info == 12 || info == 16 || info == 40 || info == 52 || info == 56 || info == 64 || info == 108 || info == 124)
      return Format::bmp;
  }
  if (has_bytes(b, 0, {'I', 'I', 42, 0}) || has_bytes(b, 0, {'M', 'M', 0, 42}) ||  // TIFF
      has_bytes(b, 0, {'I', 'I', 43, 0}) || has_bytes(b, 0, {'M', 'M', 0, 43}))    // BigTIFF
    return Format::tiff;
  if (has_text(b, 0, "RIFF") && has_text(b, 8, "WEBP")) return Format::webp;
  if (has_text(b, 0, "RIFF") && has_text(b, 8, "AVI ")) return Format::avi;
  if (b.size() >= 3 && b[0] == 'P' && b[1] >= '1' && b[1] <= '6' && is_pnm_space(b[2])) {
    if (b[1] == '1' || b[1] == '4') return Format::pbm;
    if (b[1] == '2' || b[1] == '5') return Format::pgm;
    return Format::ppm;
  }
  if (has_text(b, 0, "GIF87a") || has_text(b, 0, "GIF89a")) return Format::gif;
  if (has_text(b, 4, "ftyp")) {
    // HEIF and AVIF stills use the same ISO box structure as MP4; their brand tells them apart.
    for (std::string_view brand : {"heic", "heix", "heim", "heis", "hevc", "hevx", "mif1", "msf1", "avif", "avis"})
      if (has_text(b, 8, brand)) return Format::heif;
    return Format::mp4;
  }
  if (has_text(b, 4, "moov") || has_text(b, 4, "mdat") || has_text(b, 4, "wide")) return Format::mp4;  // QuickTime
  if (has_bytes(b, 0, {0x1A, 0x45, 0xDF, 0xA3})) return Format::mkv;
  if (b.size() > 376 && b[0] == 0x47 && b[188] == 0x47 && b[376] == 0x47) return Format::mpeg_ts;
  if (b.size() > 388 && b[4] == 0x47 && b[196] == 0x47 && b[388] == 0x47) return Format::mpeg_ts;  // M2TS (.mts)
  if (has_bytes(b, 0, {0x00, 0x00, 0x01, 0xBA})) return Format::mpeg_ps;
  if (has_bytes(b, 0, {0x00, 0x00, 0x00, 0x0C, 'j', 'P', ' ', ' ', '\r', '\n', 0x87, '\n'}) ||
      has_bytes(b, 0, {0xFF, 0x4F, 0xFF, 0x51}))
    return Format::jpeg2000;
  if (has_bytes(b, 0, {0x76, 0x2F, 0x31, 0x01})) return Format::openexr;
  return Format::unknown;
}

Format sniff(ByteSource& src) {
  const size_t n = static_cast<size_t>(std::min<uint64_t>(src.size(), kSniffBytes));
  const uint8_t* p = src.at(0, n);
  return p ? sniff(std::span<const uint8_t>(p, n)) : Format::unknown;
}

// [SECTION] Headers

namespace {

ParsedHeader named(const char* format) {
  ParsedHeader h;
  h.header.format = format;
  return h;
}

ParseResult fail(std::string* error, std::string reason) {
  *error = std::move(reason);
  return std::nullopt;
}

ParseResult truncated_header(std::string* error) { return fail(error, "truncated header"); }

// Fills the header's dimensions, rejecting values no decoder accepts (zero, negative, beyond int).
ParseResult with_size(ParsedHeader h, int64_t width, int64_t height, std::string* error) {
  if (width <= 0 || height <= 0 || width > std::numeric_limits<int>::max() || height > std::numeric_limits<int>::max())
    return fail(error, "invalid header (declares " + std::to_string(width) + "x" + std::to_string(height) + " pixels)");
  h.header.width = static_cast<int>(width);
  h.header.height = static_cast<int>(height);
  return h;
}

ParseResult parse_png(ByteSource& src, std::string* error) {
  // The 8-byte signature, then the IHDR chunk, which must come first: length 13, "IHDR", width, height, ...
  const uint8_t* p = src.at(8, 16);
  if (!p) return truncated_header(error);
  if (be32(p) != 13 || std::memcmp(p + 4, "IHDR", 4) != 0) return fail(error, "invalid header (no IHDR chunk)");
  return with_size(named("PNG"), be32(p + 8), be32(p + 12), error);
}

bool is_jpeg_sof(uint8_t marker) {
  // SOF0..SOF15 are C0..CF, but C4 (DHT), C8 (JPG, reserved) and CC (DAC) sit in that range and are not frames.
  return marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
}
bool is_jpeg_standalone(uint8_t marker) {  // markers without a length field
  return marker == 0x01 || (marker >= 0xD0 && marker <= 0xD8);
}

// How far into a JPEG its frame header may be. Metadata segments (EXIF with its thumbnail, ICC profiles, XMP)
// put it a few hundred kilobytes in at most; without a bound, a file of stray bytes (a sparse file of terabytes
// costs nothing to make) would be walked byte by byte to its end.
constexpr uint64_t kMaxJpegHeaderBytes = 64u << 20;

ParseResult parse_jpeg(ByteSource& src, std::string* error) {
  // Walk the marker segments after SOI up to the first frame header. Stray bytes before a marker are skipped as
  // libjpeg does (it only warns about them); FF fill bytes may precede any marker.
  uint64_t pos = 2;
  for (;;) {
    if (pos > kMaxJpegHeaderBytes) return fail(error, "invalid header (no frame header in the first 64 MiB)");
    const uint8_t* p = src.at(pos, 1);
    if (!p) return truncated_header(error);
    if (*p != 0xFF) {
      ++pos;
      continue;
    }
    while ((p = src.at(pos, 1)) && *p == 0xFF && pos <= kMaxJpegHeaderBytes) ++pos;
    if (!p) return truncated_header(error);
    const uint8_t marker = *p;
    ++pos;
    if (marker == 0x00 || is_jpeg_standalone(marker)) continue;
    if (marker == 0xDA || marker == 0xD9)  // scan data or the end before any frame header
      return fail(error, "invalid header (no frame header before the image data)");
    if (!(p = src.at(pos, 2))) return truncated_header(error);
    const uint16_t length = be16(p);  // counts itself but not the marker
    if (length < 2) return fail(error, "invalid header (bad segment length)");
    if (is_jpeg_sof(marker)) {
      // precision (1), height (2), width (2), components (1)
      if (length < 8) return fail(error, "invalid header (short frame header)");
      if (!(p = src.at(pos + 2, 5))) return truncated_header(error);
      // A zero height would be defined later by a DNL marker, which libjpeg does not support.
      return with_size(named("JPEG"), be16(p + 3), be16(p + 1), error);
    }
    pos += length;
  }
}

ParseResult parse_bmp(ByteSource& src, std::string* error) {
  // BITMAPFILEHEADER (14 bytes: "BM", file size, reserved, pixel data offset), then an info header whose first
  // field is its own size: 12 for the OS/2 1.x BITMAPCOREHEADER (16-bit sizes), 16..124 for the 32-bit variants.
  const uint8_t* p = src.at(0, 18);
  if (!p) return truncated_header(error);
  const uint32_t info_size = le32(p + 14);
  const size_t need = info_size == 12 ? 26 : info_size == 16 ? 30 : 34;
  if (!(p = src.at(0, need))) return truncated_header(error);
  const uint64_t data_offset = le32(p + 10);
  int64_t width = 0, height = 0;
  uint32_t bits = 0, compression = 0;
  if (info_size == 12) {
    width = le16(p + 18);
    height = le16(p + 20);
    bits = le16(p + 24);
  } else {
    width = static_cast<int32_t>(le32(p + 18));
    height = static_cast<int32_t>(le32(p + 22));
    bits = le16(p + 28);
    if (need >= 34) compression = le32(p + 30);
    if (height < 0) height = -height;  // negative: rows stored top-down
  }
  ParsedHeader h = named("BMP");
  // Uncompressed rows (BI_RGB, BI_BITFIELDS, BI_ALPHABITFIELDS) are padded to 4 bytes; their total is known.
  const bool uncompressed = compression == 0 || compression == 3 || compression == 6;
  if (uncompressed && (bits == 1 || bits == 4 || bits == 8 || bits == 16 || bits == 24 || bits == 32) && width > 0) {
    const uint64_t row = (mul_sat(static_cast<uint64_t>(width), bits) + 31) / 32 * 4;
    h.min_file_size = add_sat(data_offset, mul_sat(row, static_cast<uint64_t>(height)));
  }
  return with_size(std::move(h), width, height, error);
}

ParseResult parse_pnm(ByteSource& src, std::string* error) {
  // "P<n>", then width, height and (except for bitmaps) maxval as decimal tokens separated by whitespace, where
  // '#' starts a comment up to the end of the line; one whitespace byte ends the header of the binary variants.
  constexpr size_t kMaxHeader = 4096;  // comments could be longer, but no real writer produces that
  const size_t n = static_cast<size_t>(std::min<uint64_t>(src.size(), kMaxHeader));
  const uint8_t* p = src.at(0, n);
  if (!p) return truncated_header(error);
  const char kind = static_cast<char>(p[1]);
  const bool bitmap = kind == '1' || kind == '4';
  const int tokens = bitmap ? 2 : 3;
  const auto ran_out = [&] {
    return n == src.size() ? truncated_header(error) : fail(error, "invalid header (longer than 4096 bytes)");
  };
  int64_t values[3] = {0, 0, 1};
  size_t pos = 2;
  for (int t = 0; t < tokens; ++t) {
    for (;;) {  // whitespace and comments
      if (pos >= n) return ran_out();
      if (p[pos] == '#') {
        while (pos < n && p[pos] != '\n' && p[pos] != '\r') ++pos;
      } else if (is_pnm_space(p[pos])) {
        ++pos;
      } else {
        break;
      }
    }
    if (p[pos] < '0' || p[pos] > '9') return fail(error, "invalid header (expected a number)");
    int64_t v = 0;
    for (; pos < n && p[pos] >= '0' && p[pos] <= '9'; ++pos) {
      v = v * 10 + (p[pos] - '0');
      if (v > std::numeric_limits<int>::max()) return fail(error, "invalid header (number out of range)");
    }
    if (pos >= n) return ran_out();
    values[t] = v;
  }
  if (!is_pnm_space(p[pos])) return fail(error, "invalid header (expected whitespace)");
  const uint64_t data_offset = pos + 1;
  const int64_t maxval = values[2];
  if (maxval < 1 || maxval > 65535) return fail(error, "invalid header (maxval " + std::to_string(maxval) + ")");

  ParsedHeader h = named(bitmap ? "PBM" : kind == '2' || kind == '5' ? "PGM" : "PPM");
  if (kind >= '4') {  // binary: the pixel data size follows from the header (ASCII variants vary)
    const auto w = static_cast<uint64_t>(values[0]), rows = static_cast<uint64_t>(values[1]);
    const uint64_t sample = maxval > 255 ? 2 : 1;
    const uint64_t row = kind == '4' ? (w + 7) / 8 : mul_sat(w, kind == '5' ? sample : 3 * sample);
    h.min_file_size = add_sat(data_offset, mul_sat(row, rows));
  }
  return with_size(std::move(h), values[0], values[1], error);
}

ParseResult parse_tiff(ByteSource& src, std::string* error) {
  // Header: byte order, 42 (classic) or 43 (BigTIFF), offset of the first IFD. The dimensions are the
  // ImageWidth (256) and ImageLength (257) entries of that IFD, which writers often put at the end of the file.
  const uint8_t* p = src.at(0, 16);
  if (!p && !(p = src.at(0, 8))) return truncated_header(error);
  const bool le = p[0] == 'I';
  const auto u16 = [le](const uint8_t* q) { return le ? le16(q) : be16(q); };
  const auto u32 = [le](const uint8_t* q) { return le ? le32(q) : be32(q); };
  const auto u64 = [le](const uint8_t* q) { return le ? le64(q) : be64(q); };
  const bool big = u16(p + 2) == 43;
  uint64_t ifd = 0;
  if (big) {
    if (src.size() < 16) return truncated_header(error);
    if (u16(p + 4) != 8 || u16(p + 6) != 0) return fail(error, "invalid header (BigTIFF offset size)");
    ifd = u64(p + 8);
  } else {
    ifd = u32(p + 4);
  }
  const size_t count_size = big ? 8 : 2, entry_size = big ? 20 : 12, value_at = big ? 12 : 8;
  if (!(p = src.at(ifd, count_size))) return truncated_header(error);
  const uint64_t entries = big ? u64(p) : u16(p);
  if (entries > 4096) return fail(error, "invalid header (" + std::to_string(entries) + " IFD entries)");
  int64_t width = -1, height = -1;
  for (uint64_t i = 0; i < entries && (width < 0 || height < 0); ++i) {
    const uint8_t* e = src.at(ifd + count_size + i * entry_size, entry_size);
    if (!e) return truncated_header(error);
    const uint16_t tag = u16(e), type = u16(e + 2);
    if (tag != 256 && tag != 257) continue;
    int64_t v = 0;
    if (type == 3) v = u16(e + value_at);                                          // SHORT
    else if (type == 4) v = u32(e + value_at);                                     // LONG
    // LONG8 exists only in BigTIFF, whose entries hold 8 value bytes; a classic entry holds 4, so reading 8 there
    // would read past the entry (past the file, when the entry is its last bytes).
    else if (type == 16 && big) v = static_cast<int64_t>(std::min<uint64_t>(u64(e + value_at), std::numeric_limits<int64_t>::max()));
    else return fail(error, "invalid header (TIFF size of type " + std::to_string(type) + ")");
    (tag == 256 ? width : height) = v;
  }
  if (width < 0 || height < 0) return fail(error, "invalid header (TIFF without image width or length)");
  return with_size(named("TIFF"), width, height, error);
}

ParseResult parse_webp(ByteSource& src, std::string* error) {
  // "RIFF" size "WEBP", then the first chunk: "VP8 " (lossy), "VP8L" (lossless) or "VP8X" (extended).
  const uint8_t* p = src.at(0, 30);
  if (!p) return truncated_header(error);
  ParsedHeader h = named("WebP");
  h.min_file_size = 8 + uint64_t{le32(p + 4)};
  if (std::memcmp(p + 12, "VP8 ", 4) == 0) {
    // Frame tag (3 bytes), start code 9D 01 2A, then 14-bit width and height (the top 2 bits are scaling).
    if (p[23] != 0x9D || p[24] != 0x01 || p[25] != 0x2A) return fail(error, "invalid header (VP8 start code)");
    return with_size(std::move(h), le16(p + 26) & 0x3FFF, le16(p + 28) & 0x3FFF, error);
  }
  if (std::memcmp(p + 12, "VP8L", 4) == 0) {
    // Signature 0x2F, then width-1 and height-1 as two 14-bit fields.
    if (p[20] != 0x2F) return fail(error, "invalid header (VP8L signature)");
    const uint32_t bits = le32(p + 21);
    return with_size(std::move(h), (bits & 0x3FFF) + 1, (bits >> 14 & 0x3FFF) + 1, error);
  }
  if (std::memcmp(p + 12, "VP8X", 4) == 0) {
    // Flags (1 byte, bit 1 = animation), 3 reserved, canvas width-1 and height-1 as 24-bit fields.
    if (p[20] & 0x02) return fail(error, "unsupported image format (animated WebP)");  // OpenCV 4.6 cannot decode it
    return with_size(std::move(h), int64_t{le24(p + 24)} + 1, int64_t{le24(p + 27)} + 1, error);
  }
  return fail(error, "invalid header (unknown WebP chunk)");
}

}  // namespace

ParseResult parse_header(Format f, ByteSource& src, std::string* error) {
  switch (f) {
    case Format::png: return parse_png(src, error);
    case Format::jpeg: return parse_jpeg(src, error);
    case Format::bmp: return parse_bmp(src, error);
    case Format::pbm: case Format::pgm: case Format::ppm: return parse_pnm(src, error);
    case Format::tiff: return parse_tiff(src, error);
    case Format::webp: return parse_webp(src, error);
    default: return fail(error, describe_unreadable(f));
  }
}

// [SECTION] Completeness

namespace {

// Whether a JPEG reaches its EOI marker. Walks the segments and, after each SOS, the entropy-coded data (which
// ends at the first marker other than RSTn; FF 00 is an escaped data byte) instead of looking at the last bytes,
// because cameras append data after EOI (thumbnails, MPF images, the video of a "motion photo").
bool jpeg_has_eoi(std::span<const uint8_t> b) {
  const size_t n = b.size();
  size_t pos = 2;
  while (pos < n) {
    if (b[pos] != 0xFF) {  // stray byte, skipped as libjpeg does
      ++pos;
      continue;
    }
    while (pos < n && b[pos] == 0xFF) ++pos;
    if (pos >= n) return false;
    const uint8_t marker = b[pos++];
    if (marker == 0xD9) return true;
    if (marker == 0x00 || is_jpeg_standalone(marker)) continue;
    if (n - pos < 2) return false;
    const size_t length = be16(&b[pos]);
    if (length < 2 || length > n - pos) return false;
    pos += length;
    if (marker == 0xDA) {
      while (pos + 1 < n && !(b[pos] == 0xFF && b[pos + 1] != 0x00 && (b[pos + 1] < 0xD0 || b[pos + 1] > 0xD7))) ++pos;
      if (pos + 1 >= n) return false;
    }
  }
  return false;
}

// Whether a PNG's chunks lead to IEND (data after IEND is ignored, as libpng does).
bool png_has_iend(std::span<const uint8_t> b) {
  uint64_t pos = 8;
  while (pos + 8 <= b.size()) {
    const uint32_t length = be32(&b[pos]);
    if (length > 0x7FFFFFFFu) return false;  // not a valid chunk length
    if (std::memcmp(&b[pos + 4], "IEND", 4) == 0) return true;
    pos += 12 + uint64_t{length};  // length, type, data, CRC
  }
  return false;
}

}  // namespace

std::string check_complete(Format f, const ParsedHeader& h, std::span<const uint8_t> b) {
  if (f == Format::jpeg && !jpeg_has_eoi(b)) return "truncated image data (no end-of-image marker)";
  if (f == Format::png && !png_has_iend(b)) return "truncated image data (no IEND chunk)";
  if (h.min_file_size > b.size())
    return "truncated image data (" + std::to_string(b.size()) + " bytes, the header needs " +
           std::to_string(h.min_file_size) + ")";
  return {};
}

}  // namespace arwb::image_format
