// What an image file is, from its first bytes and its header, without decoding it and without OpenCV: the
// phone player's core (web/core) checks scenes' pictures with these too. image_io.hpp decodes.
//
// Input is untrusted (image_io.hpp says how): nothing here throws or crashes on a hostile file, and a header is
// read in small windows, however large the file or the size it declares.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace arwb {

// Longest side load_image accepts, whatever max_pixels says: beyond it rows alone get unreasonably long.
inline constexpr int kMaxImageSide = 32768;
// Default pixel budget of load_image (100 megapixels, about 300 MB once decoded as 8-bit BGR).
inline constexpr int64_t kDefaultMaxPixels = 100'000'000;

enum class PathKind { missing, image, video, folder, other };
const char* to_string(PathKind kind);

// What a path is, decided by the file system and, for regular files, by their first bytes:
//   image:  PNG, JPEG, BMP, TIFF (also BigTIFF), WebP, PBM/PGM/PPM (P1..P6);
//   video:  MP4/MOV (ISO base media "ftyp", QuickTime "moov"/"mdat"/"wide"), AVI, MKV/WebM, MPEG-TS, MPEG-PS;
//   folder: a directory (symbolic links are followed);
//   other:  anything else, including GIF, HEIF/AVIF, JPEG 2000 and OpenEXR (load_image does not read those),
//           unreadable files and device files;
//   missing: nothing at that path.
PathKind classify_path(const std::string& path);

struct ImageHeader {
  std::string format;  // "PNG", "JPEG", "BMP", "TIFF", "WebP", "PBM", "PGM" or "PPM"
  int width = 0;       // always > 0 in a header read_image_header returns
  int height = 0;
};

// Reads only the header of an image file (after the same file check as load_image): its format and dimensions (PNG IHDR; JPEG's first SOFn frame header;
// BMP info header, a negative height meaning top-down; PNM header tokens and comments; TIFF's first IFD;
// WebP's VP8/VP8L/VP8X chunk). Reads only as far as the header goes, typically a few kilobytes, and holds at
// most 64 KiB of the file at a time, however large the file or the size it declares.
// On failure returns nullopt and, if error is given, sets it to the reason without the path, e.g.
// "no such file", "not an image (unknown signature)", "truncated header", "invalid header (...)".
// The dimensions are not checked against any limit here.
std::optional<ImageHeader> read_image_header(const std::string& path, std::string* error = nullptr);

// read_image_header on bytes in memory (a whole file, or as much of its beginning as the caller has): the same
// sniffing and parsers, the same reasons ("truncated header" when the bytes end inside the header). The fuzz target
// fuzz/image_header.cpp reads headers this way.
std::optional<ImageHeader> parse_image_header(std::span<const uint8_t> bytes, std::string* error = nullptr);

// "" when a picture of header `h` may be decoded within `max_pixels` (and kMaxImageSide a side), else why not:
// "declares 9000x9000 pixels, more than the limit of 40000000". load_image's check, and the phone player's.
std::string image_limit_error(const ImageHeader& h, int64_t max_pixels);

// Pictures larger than this a side are more than many phones' WebGL draws (4096 is the common texture limit).
inline constexpr int kPhoneMaxImageSide = 4096;

// "" when phones' browsers show a picture of header `h` as it is, else why not: "a TIFF picture: phones' browsers
// show PNG, JPEG and WebP", "a 5000x300 picture: many phones draw at most 4096 pixels a side". Export's check of
// a scene's pictures (bundle/bundle.hpp's phone_problem), and the phone player core's of a model's textures.
std::string phone_picture_problem(const ImageHeader& h);

}  // namespace arwb
