// What the bundle's files share inside src/bundle: digests, the rule for a path inside a bundle, reading a
// whole file under a limit, and the zip (libzip) reading and writing.
#pragma once

#include "base/result.hpp"
#include "base/temp_dir.hpp"

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace arwb::bundle {

// SHA-256 as 64 lowercase hex digits (OpenSSL's EVP_Digest).
std::string sha256_hex(std::string_view bytes);

// "" when `path` may name a file inside a bundle: relative, '/'-separated, no empty, "." or ".." component, no
// backslash, colon or control character, at most 1024 bytes. Else the reason ("absolute path", "has ..", ...).
std::string bundle_path_problem(std::string_view path);

// `name` for a message, in double quotes, cut with base/files' shown_name (a 600-byte entry name would make one
// huge line). Built by appending: GCC 12 warns wrongly (-Wrestrict) on "\"" + a temporary string.
std::string quoted_name(std::string_view name);

// The whole regular file at `path` (symbolic links not followed when `no_follow`), at most max_bytes.
Result<std::string> read_whole_file(const std::filesystem::path& path, std::uint64_t max_bytes, bool no_follow);
// Writes a new file (it must not exist; never through a symbolic link), mode 0644, flushed to disk.
Status write_new_file(const std::filesystem::path& path, std::string_view bytes);

// True when the file's first bytes are a zip's (a local file header or an empty archive's end record).
bool looks_like_zip(const std::filesystem::path& path);

// Writes `entries` (bundle path, bytes) as a new zip at `path` (which must not exist), deflated, each a regular
// file of mode 0644.
Status write_zip(const std::filesystem::path& path, const std::vector<std::pair<std::string, std::string>>& entries);

// One zip entry's name as the reader found it, for the limit checks.
struct ZipLimits {
  std::size_t max_entries = 0;
  std::uint64_t max_file_bytes = 0, max_total_bytes = 0;
  double max_ratio = 0;
  // When given, the only files the zip may hold and the size of each (a bundle's manifest, read first): an entry
  // not among them is refused before anything is inflated, and one is stopped as soon as it inflates past its size.
  const std::map<std::string, std::uint64_t>* listed = nullptr;
};
// Extracts the zip at `zip_path` into the existing empty folder `into`, refusing (naming the entry) absolute
// names, "..", symbolic links, devices and other non-regular entries, duplicates, encrypted entries, and what
// passes the limits, counted on the bytes really inflated. Nothing is written outside `into`.
Status extract_zip(const std::filesystem::path& zip_path, const std::filesystem::path& into, const ZipLimits& limits);
// extract_zip's checks of every entry's name and kind (and of `listed`, when given), inflating nothing.
Status check_zip(const std::filesystem::path& zip_path, const ZipLimits& limits);

}  // namespace arwb::bundle

namespace arwb::bundle {
// The bytes of entry `name` of the zip at `zip_path`, at most max_bytes inflated.
Result<std::string> read_zip_entry(const std::filesystem::path& zip_path, const std::string& name,
                                   std::uint64_t max_bytes);
}  // namespace arwb::bundle
