#include "base/files.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

namespace arwb {

namespace {

// "16 MiB", "64 KiB" or "1000 bytes": limits are round numbers, said the way they were written.
std::string byte_size(std::uintmax_t n) {
  if (n >= (1u << 20) && n % (1u << 20) == 0) return std::to_string(n >> 20) + " MiB";
  if (n >= (1u << 10) && n % (1u << 10) == 0) return std::to_string(n >> 10) + " KiB";
  return std::to_string(n) + " bytes";
}

}  // namespace

Result<std::string> read_text_file(const std::string& path, std::uintmax_t max_bytes) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(st)) return fail(path + ": no such file");
  if (!std::filesystem::is_regular_file(st)) return fail(path + ": not a regular file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > max_bytes) return fail(path + ": larger than " + byte_size(max_bytes));
  const std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) return fail(path + ": cannot be read (" + std::strerror(errno) + ")");
  // Read to the end rather than trusting the size: the file may grow or shrink meanwhile, and never past the cap.
  std::string text;
  char buf[1 << 16];
  for (;;) {
    const size_t n = std::fread(buf, 1, sizeof buf, f.get());
    text.append(buf, n);
    if (text.size() > max_bytes) return fail(path + ": larger than " + byte_size(max_bytes));
    if (n < sizeof buf) break;
  }
  if (std::ferror(f.get())) return fail(path + ": cannot be read (read error)");
  return text;
}

bool write_file_atomically(const std::string& path, const std::string& text, std::string* error) {
  const std::string tmp = path + ".arwb-saving";
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) {
    *error = std::strerror(errno);
    return false;
  }
  const bool wrote = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const bool closed = std::fclose(f) == 0;
  if (!wrote || !closed) {
    *error = "write failed (disk full?)";
    std::remove(tmp.c_str());
    return false;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    *error = std::strerror(errno);
    std::remove(tmp.c_str());
    return false;
  }
  return true;
}

}  // namespace arwb
