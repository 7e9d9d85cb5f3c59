#include "base/files.hpp"

#include "base/text.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <system_error>

namespace arwb {

namespace {

// "16 MiB", "64 KiB" or "1000 bytes": limits are round numbers, said the way they were written.
std::string byte_size(std::uintmax_t n) {
  if (n >= (std::uintmax_t{1} << 40) && n % (std::uintmax_t{1} << 40) == 0) return std::to_string(n >> 40) + " TiB";
  if (n >= (std::uintmax_t{1} << 30) && n % (std::uintmax_t{1} << 30) == 0) return std::to_string(n >> 30) + " GiB";
  if (n >= (1u << 20) && n % (1u << 20) == 0) return std::to_string(n >> 20) + " MiB";
  if (n >= (1u << 10) && n % (1u << 10) == 0) return std::to_string(n >> 10) + " KiB";
  return std::to_string(n) + " bytes";
}

// What a file that is not a regular one is, for "not a regular file (a FIFO)".
const char* type_name(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "a special file";
}

// The check shared by the path (stat) and the opened descriptor (fstat).
Status check_stat(const std::string& path, const struct stat& st, const FileLimit& limit) {
  if (!S_ISREG(st.st_mode)) return fail(path + ": not a regular file (" + type_name(st.st_mode) + ")");
  if (static_cast<std::uintmax_t>(st.st_size) > limit.max_bytes)
    return fail(path + ": larger than " + byte_size(limit.max_bytes) + ", the limit for " + limit.kind);
  return {};
}

std::string system_reason(int err) { return std::string("cannot be read (") + std::strerror(err) + ")"; }

}  // namespace

std::string shown_name(std::string_view s) {
  constexpr size_t kMaxShown = 120;
  std::string out;
  size_t n = std::min(s.size(), kMaxShown);
  while (n < s.size() && n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;  // whole characters
  for (const char c : s.substr(0, n)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u < 0x20 || u == 0x7f) ? '?' : c;
  }
  if (s.size() > kMaxShown) out += "\u2026";
  return out;
}

namespace {

bool is_inside(const std::filesystem::path& inner, const std::filesystem::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator yields an empty last component
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

}  // namespace

ResolvedPath resolve_inside(const std::filesystem::path& folder, const std::string& relative,
                            const std::filesystem::path& from, const std::string& folder_name) {
  namespace fs = std::filesystem;
  ResolvedPath out;
  const auto fail = [&](const std::string& reason) {
    out.path.clear();
    out.error = shown_name(relative) + ": " + reason;
    return out;
  };
  // Everything that can be decided from the text is decided before the file system is asked anything.
  if (relative.empty()) return fail("empty path");
  if (relative.find('\0') != std::string::npos) return fail("contains a NUL character");
  const fs::path rel(relative);
  if (rel.is_absolute() || rel.has_root_path()) return fail("absolute paths are not allowed");
  for (const fs::path& part : rel)
    if (part == "..") return fail("leaves " + folder_name);

  std::error_code ec;
  // A scene named without a folder ("scene.lua") lies in the current one: its parent_path() is empty.
  const fs::path base = fs::canonical(folder.empty() ? fs::path(".") : folder, ec);
  if (ec) return fail(folder_name + " " + folder.string() + " cannot be resolved (" + ec.message() + ")");
  // Symbolic links are resolved, so one inside the folder that leads out is caught by the containment test
  // (and so is a `from` that is itself a link leading out).
  const fs::path resolved = fs::weakly_canonical(base / from / rel, ec);
  if (ec) return fail("cannot resolve (" + ec.message() + ")");
  if (!is_inside(resolved, base)) return fail("leaves " + folder_name);

  struct stat st {};
  if (::stat(resolved.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) return fail("no such file");
    return fail(std::string("cannot access (") + std::generic_category().message(errno) + ")");
  }
  // A FIFO or device would block or never end when read; a folder is not a file. ("a FIFO" without its article.)
  if (!S_ISREG(st.st_mode)) return fail(std::string("not a regular file (") + (type_name(st.st_mode) + 2) + ")");
  out.path = resolved.string();
  return out;
}

Status check_input_file(const std::string& path, const FileLimit& limit) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) return fail(path + ": no such file");
    return fail(path + ": " + system_reason(errno));
  }
  return check_stat(path, st, limit);
}

InputFile& InputFile::operator=(InputFile&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = o.fd_;
    size_ = o.size_;
    o.fd_ = -1;
  }
  return *this;
}

InputFile::~InputFile() {
  if (fd_ >= 0) ::close(fd_);
}

long long InputFile::read_at(std::uint64_t offset, void* buf, std::size_t n) const {
  auto* out = static_cast<char*>(buf);
  std::size_t done = 0;
  while (done < n) {
    const ssize_t got = ::pread(fd_, out + done, n - done, static_cast<off_t>(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return -1;
    if (got == 0) break;
    done += static_cast<std::size_t>(got);
  }
  return static_cast<long long>(done);
}

Result<InputFile> open_input_file(const std::string& path, const FileLimit& limit) {
  if (Status st = check_input_file(path, limit); !st) return fail(st.error());
  // O_NONBLOCK: should the path have become a FIFO since the check, open() returns instead of waiting for a writer
  // (and the fstat below refuses it). It changes nothing for reading a regular file.
  InputFile f;
  f.fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (f.fd_ < 0) {
    if (errno == ENOENT) return fail(path + ": no such file");
    return fail(path + ": " + system_reason(errno));
  }
  struct stat st {};
  if (::fstat(f.fd_, &st) != 0) return fail(path + ": " + system_reason(errno));
  if (Status s = check_stat(path, st, limit); !s) return fail(s.error());
  f.size_ = static_cast<std::uint64_t>(st.st_size);
  return f;
}

Result<std::string> read_file_bytes(const std::string& path, const FileLimit& limit) {
  Result<InputFile> f = open_input_file(path, limit);
  if (!f) return fail(f.error());
  // Read to the end rather than trusting the size: the file may grow or shrink meanwhile, and never past the cap.
  std::string text;
  char buf[1 << 16];
  for (;;) {
    const long long n = f->read_at(text.size(), buf, sizeof buf);
    if (n < 0) return fail(path + ": cannot be read (read error)");
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > limit.max_bytes)
      return fail(path + ": larger than " + byte_size(limit.max_bytes) + ", the limit for " + limit.kind);
    if (n == 0) break;
  }
  return text;
}

Result<std::string> read_text_file(const std::string& path, const FileLimit& limit) {
  Result<std::string> bytes = read_file_bytes(path, limit);
  if (!bytes) return bytes;
  std::string text = std::move(*bytes);
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
  if (Status st = check_utf8_text(text, path); !st) return fail(st.error());
  return text;
}

bool write_file_atomically(const std::string& path, const std::string& text, std::string* error) {
  std::string failed;
  return write_files_atomically({{path, text}}, &failed, error);
}

bool write_files_atomically(const std::vector<std::pair<std::string, std::string>>& path_and_text,
                            std::string* failed, std::string* error) {
  std::vector<std::string> temps;
  const auto give_up = [&](const std::string& path, std::string why, size_t from) {
    *failed = path;
    *error = std::move(why);
    for (size_t i = from; i < temps.size(); ++i) std::remove(temps[i].c_str());
    return false;
  };
  for (const auto& [path, text] : path_and_text) {
    const std::string tmp = path + ".arwb-saving";
    FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) return give_up(path, std::strerror(errno), 0);
    temps.push_back(tmp);
    const bool wrote = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    const bool closed = std::fclose(f) == 0;
    if (!wrote || !closed) return give_up(path, "write failed (disk full?)", 0);
  }
  for (size_t i = 0; i < temps.size(); ++i) {
    if (std::rename(temps[i].c_str(), path_and_text[i].first.c_str()) != 0)
      return give_up(path_and_text[i].first, std::strerror(errno), i);
  }
  return true;
}

Result<std::string> set_aside(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode))
    return fail(path + ": not a regular file, left as it is");
  for (int n = 1; n <= 1000; ++n) {
    // Appended: GCC 12 warns of a false out-of-bounds copy on path + ".bad" + ... here.
    std::string to = path;
    to.append(".bad");
    if (n > 1) to.append(".").append(std::to_string(n));
    // RENAME_NOREPLACE: an older .bad that appears between a check and the rename is still not replaced.
#if defined(RENAME_NOREPLACE)
    if (renameat2(AT_FDCWD, path.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return to;
#else
    errno = EINVAL;   // a C library without renameat2 (emscripten's, for web/core): as such a file system
#endif
    if (errno == EEXIST) continue;
    if (errno == EINVAL) {   // a file system without RENAME_NOREPLACE: check, then rename
      std::error_code ec;
      if (std::filesystem::exists(to, ec) || ec) continue;
      if (std::rename(path.c_str(), to.c_str()) == 0) return to;
    }
    return fail(path + ": cannot be set aside (" + std::strerror(errno) + ")");
  }
  return fail(path + ": cannot be set aside (1000 older .bad files beside it)");
}

}  // namespace arwb
