// Reading images from paths a user names (`arwb detect PATH...`, the workbench's file dialogs).
//
// Input is untrusted: a path may be missing, a folder, a video, a renamed text file, a truncated download or a
// crafted header declaring billions of pixels. Nothing here throws or crashes on such input, and nothing
// allocates for pixels before the header's dimensions have been checked against limits. Each problem becomes
// one message naming the file and the reason, so a caller can report it and go on with its other paths.
//
// Formats are recognised by their first bytes (magic), never by the file name's extension.
#pragma once

#include "capture/image_header.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <string>
#include <vector>

namespace arwb {

struct LoadedImage {
  cv::Mat image;      // empty on failure
  std::string error;  // "<path>: <reason>" on failure, empty on success
  bool ok() const { return error.empty(); }
};

// Loads an image for processing. In order, each failure giving error "<path>: <reason>":
//   the path passes base/files' check_input_file ("no such file", "not a regular file (a folder)", "(a FIFO)",
//   "(a character device)" ..., "larger than 1 GiB, the limit for an image"; a FIFO never blocks), is not empty
//   ("empty file (0 bytes)"), has a supported image signature ("not an image (unknown signature)",
//   "not an image (video: MP4/MOV)", "unsupported image format (GIF)"), a readable header ("truncated header",
//   "invalid header (...)") whose dimensions are within limits ("declares 60000x60000 pixels, more than the
//   limit of 100000000", "declares 40000x16 pixels, a side longer than the limit of 32768"), a file size
//   plausible for those dimensions; then the whole file is read once into memory and checked to be complete
//   ("truncated image data (...)": a JPEG must reach its end-of-image marker, a PNG its IEND chunk, binary
//   PNM/uncompressed BMP/WebP must hold the bytes their headers declare), and decoded with cv::imdecode
//   ("corrupt or truncated image data" when OpenCV fails or returns an empty image).
// flags are those of cv::imread. max_pixels bounds width*height before any pixel memory is allocated.
// Never throws for bad input; decoder libraries may still print warnings on stderr.
LoadedImage load_image(const std::string& path, int flags = cv::IMREAD_COLOR, int64_t max_pixels = kDefaultMaxPixels);
// What load_image does once the file is in memory (signature, header, limits, completeness, decoding) on the bytes
// of a whole file, with errors "<name>: <reason>" ("empty file (0 bytes)" for no bytes). Used by load_image and the
// fuzz target fuzz/image_header.cpp.
LoadedImage decode_image(std::span<const uint8_t> bytes, const std::string& name, int flags = cv::IMREAD_COLOR,
                         int64_t max_pixels = kDefaultMaxPixels);

// The images directly in a folder (not in its subfolders), recognised by signature as classify_path does,
// as paths "<folder>/<name>" sorted by name (plain std::string comparison, so "B.png" before "a.png").
// Names starting with '.' are ignored, and so are subfolders. Other files are appended to *skipped, in name
// order, as "<path>: skipped, not an image", or with a more specific reason where there is one
// ("skipped, not an image (video: MP4/MOV)", "skipped, unsupported image format (GIF)", "skipped, empty file
// (0 bytes)", "skipped, not a regular file (a FIFO)", "skipped, cannot be read (...)"); they are not errors. If the folder itself cannot be listed, returns an empty list
// and sets *error to "<folder>: <reason>" ("no such folder", "not a folder", "cannot list (...)"); otherwise
// *error is cleared.
std::vector<std::string> list_images(const std::string& folder, std::vector<std::string>* skipped = nullptr,
                                     std::string* error = nullptr);

}  // namespace arwb
