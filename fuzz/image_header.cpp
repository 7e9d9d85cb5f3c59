// Fuzz target: image headers and loading (src/capture/image_io.cpp), what `arwb detect`, the workbench's sources
// and scene media go through for any file a user names. The bytes are read as an image file three ways that must
// agree: parse_image_header in memory, read_image_header from a file (the parsers over the small windowed reads
// of a file, a separate code path), and, for headers of small images, decode_image (completeness checks and
// OpenCV's decoders). A header the parsers accept has positive dimensions; a failure always has a reason.
#include "capture/image_io.hpp"
#include "fuzz_files.hpp"

#include <opencv2/core/utils/logger.hpp>

#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    return true;
  }();
  (void)quiet;
  const std::span<const uint8_t> bytes(data, size);

  std::string error;
  const std::optional<arwb::ImageHeader> header = arwb::parse_image_header(bytes, &error);
  if (header ? header->width <= 0 || header->height <= 0 || !error.empty() : error.empty()) std::abort();

  // The same bytes as a file: the same answer (an empty file is refused before any parser, in both).
  const std::string path = arwb::fuzz::write_scratch("image", data, size);
  std::string file_error;
  const std::optional<arwb::ImageHeader> from_file = arwb::read_image_header(path, &file_error);
  if (from_file.has_value() != header.has_value() || file_error != error) std::abort();
  if (header && (from_file->format != header->format || from_file->width != header->width ||
                 from_file->height != header->height))
    std::abort();

  // Decoding is bounded by the header's size: small images only, so each input stays fast.
  constexpr int64_t kMaxPixels = 1 << 16;
  if (header && int64_t{header->width} * header->height <= kMaxPixels) {
    const arwb::LoadedImage img = arwb::decode_image(bytes, "fuzz", cv::IMREAD_COLOR, kMaxPixels);
    if (img.ok() == img.image.empty()) std::abort();
  }
  return 0;
}
