// Bytes written by hand for the tests: big-endian numbers, the CRC-32 that PNG chunks and zip entries carry, PNG
// chunks, and a PNG that is little more than its header.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace arwb::test {

// CRC-32 (polynomial 0xEDB88320, reflected, as zlib's crc32), as PNG chunks and zip entries carry it.
uint32_t crc32(std::string_view bytes);

// v as four bytes, the most significant first.
std::string be32(uint32_t v);

// A PNG chunk: the data's length, the type, the data, and the CRC-32 of type and data.
std::string png_chunk(const std::string& type, const std::string& data);

// A well-formed PNG whose IHDR declares width x height 8-bit RGB pixels. Its IDAT holds a valid zlib stream (of
// one zero byte) so that libpng accepts the header and OpenCV would go on to allocate the image.
std::string png_declaring(uint32_t width, uint32_t height);

}  // namespace arwb::test
