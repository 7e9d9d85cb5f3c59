#include "base/files.hpp"

#include "base/text.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

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

Result<std::string> read_text_file(const std::string& path, const FileLimit& limit) {
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
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
  if (Status st = check_utf8_text(text, path); !st) return fail(st.error());
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
