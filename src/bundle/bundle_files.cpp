#include "bundle/bundle_files.hpp"

#include "base/files.hpp"

#include <openssl/evp.h>
#include <zip.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <set>

namespace arwb::bundle {

namespace fs = std::filesystem;

std::string sha256_hex(std::string_view bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &n, EVP_sha256(), nullptr) != 1 || n != 32) return {};
  static const char* hex = "0123456789abcdef";
  std::string out;
  out.reserve(64);
  for (unsigned i = 0; i < n; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

std::string quoted_name(std::string_view name) {
  std::string out = "\"";
  out += shown_name(name);
  out += '"';
  return out;
}

std::string bundle_path_problem(std::string_view path) {
  if (path.empty()) return "empty path";
  if (path.size() > 1024) return "path longer than 1024 bytes";
  if (path.front() == '/') return "absolute path";
  for (const char c : path) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "control character in the path";
    if (c == '\\') return "backslash in the path";
    if (c == ':') return "colon in the path (a drive or stream name)";
  }
  size_t start = 0;
  while (start <= path.size()) {
    const size_t end = std::min(path.find('/', start), path.size());
    const std::string_view part = path.substr(start, end - start);
    if (part == "..") return "has \"..\"";
    if (part == ".") return "has \".\"";
    if (part.empty()) return end == path.size() ? "ends with '/'" : "has an empty component (\"//\")";
    start = end + 1;
  }
  return "";
}

namespace {

std::string errno_text(int e) { return std::strerror(e); }

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  int release() {
    const int f = fd_;
    fd_ = -1;
    return f;
  }

 private:
  int fd_;
};

}  // namespace

Result<std::string> read_whole_file(const fs::path& path, std::uint64_t max_bytes, bool no_follow) {
  const Fd fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | (no_follow ? O_NOFOLLOW : 0)));
  if (fd.get() < 0) {
    const int e = errno;
    if (e == ELOOP) return fail(path.string() + ": is a symbolic link");
    if (e == ENOENT) return fail(path.string() + ": no such file");
    return fail(path.string() + ": cannot be read (" + errno_text(e) + ")");
  }
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0) return fail(path.string() + ": cannot be read (" + errno_text(errno) + ")");
  if (!S_ISREG(st.st_mode)) return fail(path.string() + ": not a regular file");
  if (std::uint64_t(st.st_size) > max_bytes)
    return fail(path.string() + ": larger than " + std::to_string(max_bytes) + " bytes");
  std::string out;
  out.resize(size_t(st.st_size));
  size_t got = 0;
  while (got < out.size()) {
    const ssize_t r = ::read(fd.get(), out.data() + got, out.size() - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) return fail(path.string() + ": cannot be read (" + errno_text(errno) + ")");
    if (r == 0) break;
    got += size_t(r);
  }
  // A file that grew or shrank while read is read as it was at fstat's size, or refused when short.
  if (got != out.size()) return fail(path.string() + ": changed while it was read");
  return out;
}

Status write_new_file(const fs::path& path, std::string_view bytes) {
  Fd fd(::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644));
  if (fd.get() < 0) return fail(path.string() + ": cannot be created (" + errno_text(errno) + ")");
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t w = ::write(fd.get(), bytes.data() + done, bytes.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return fail(path.string() + ": cannot be written (" + errno_text(errno) + ")");
    done += size_t(w);
  }
  if (::fsync(fd.get()) != 0) return fail(path.string() + ": cannot be written (" + errno_text(errno) + ")");
  if (::close(fd.release()) != 0) return fail(path.string() + ": cannot be written (" + errno_text(errno) + ")");
  return {};
}

bool looks_like_zip(const fs::path& path) {
  const Fd fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) return false;
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0 || !S_ISREG(st.st_mode)) return false;
  std::array<char, 4> head{};
  if (::read(fd.get(), head.data(), head.size()) != 4) return false;
  return std::memcmp(head.data(), "PK\x03\x04", 4) == 0 || std::memcmp(head.data(), "PK\x05\x06", 4) == 0;
}

namespace {

std::string zip_error_text(int code) {
  zip_error_t e;
  zip_error_init_with_code(&e, code);
  std::string s = zip_error_strerror(&e);
  zip_error_fini(&e);
  return s;
}

struct ZipCloser {
  void operator()(zip_t* z) const {
    if (z) zip_discard(z);
  }
};
using ZipPtr = std::unique_ptr<zip_t, ZipCloser>;

// A file whose format compresses its own content (deflating it again gains nothing and costs time).
bool already_compressed(const std::string& name) {
  std::string ext = fs::path(name).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  static const std::set<std::string> packed = {".png", ".jpg", ".jpeg", ".webp", ".gif", ".mp4", ".m4v", ".mov",
                                                ".webm", ".mkv", ".avi", ".ogv", ".zip", ".arwb"};
  return packed.count(ext) > 0;
}

}  // namespace

Status write_zip(const fs::path& path, const std::vector<std::pair<std::string, std::string>>& entries) {
  int code = 0;
  ZipPtr z(zip_open(path.c_str(), ZIP_CREATE | ZIP_EXCL, &code));
  if (!z) return fail(path.string() + ": cannot be created (" + zip_error_text(code) + ")");
  for (const auto& [name, bytes] : entries) {
    // The bytes stay alive in `entries` until zip_close has written them.
    zip_source_t* src = zip_source_buffer(z.get(), bytes.data(), bytes.size(), 0);
    if (!src) return fail(path.string() + ": " + name + ": " + zip_strerror(z.get()));
    const zip_int64_t idx = zip_file_add(z.get(), name.c_str(), src, ZIP_FL_ENC_UTF_8);
    if (idx < 0) {
      zip_source_free(src);
      return fail(path.string() + ": " + name + ": " + zip_strerror(z.get()));
    }
    // libzip deflates at level 9 unless told: 13 s for a 36 MB OBJ, where level 1 takes 0.4 s for a third more
    // bytes. Pictures and videos are compressed already and are stored as they are.
    const bool packed = already_compressed(name);
    if (zip_set_file_compression(z.get(), zip_uint64_t(idx), packed ? ZIP_CM_STORE : ZIP_CM_DEFLATE, packed ? 0 : 1) != 0)
      return fail(path.string() + ": " + name + ": " + zip_strerror(z.get()));
    const zip_uint32_t attributes = zip_uint32_t(S_IFREG | 0644) << 16;
    if (zip_file_set_external_attributes(z.get(), zip_uint64_t(idx), 0, ZIP_OPSYS_UNIX, attributes) != 0)
      return fail(path.string() + ": " + name + ": " + zip_strerror(z.get()));
  }
  zip_t* raw = z.release();
  if (zip_close(raw) != 0) {
    const std::string why = zip_strerror(raw);
    zip_discard(raw);
    std::error_code ec;
    fs::remove(path, ec);
    return fail(path.string() + ": cannot be written (" + why + ")");
  }
  return {};
}

namespace {

// An entry of a zip, as its name pass found it.
struct ZipEntry {
  zip_uint64_t index;
  std::string name;
  bool folder;
  zip_uint64_t comp_size;
};

// Opens the zip and checks every entry's name and kind, before anything is inflated.
Result<std::vector<ZipEntry>> zip_entries(const fs::path& zip_path, const ZipLimits& limits, ZipPtr* opened) {
  const std::string where = zip_path.string() + ": ";
  int code = 0;
  ZipPtr z(zip_open(zip_path.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &code));
  // libzip refuses a zip with two entries of one name as it opens it, before any name can be asked for.
  if (!z && code == ZIP_ER_EXISTS) return fail(where + "two entries have the same name");
  if (!z) return fail(where + "not a readable zip (" + zip_error_text(code) + ")");
  const zip_int64_t count = zip_get_num_entries(z.get(), 0);
  if (count < 0) return fail(where + "not a readable zip");
  if (std::uint64_t(count) > limits.max_entries)
    return fail(where + std::to_string(count) + " entries, more than the limit of " + std::to_string(limits.max_entries));
  std::vector<ZipEntry> list;
  std::set<std::string> seen;
  for (zip_uint64_t i = 0; i < zip_uint64_t(count); ++i) {
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_stat_index(z.get(), i, ZIP_FL_ENC_RAW, &st) != 0 || !(st.valid & ZIP_STAT_NAME))
      return fail(where + "entry " + std::to_string(i) + ": unreadable (" + zip_strerror(z.get()) + ")");
    std::string name = st.name;
    const std::string shown = "entry " + quoted_name(name) + ": ";   // a long name cut
    if (name.size() != std::strlen(st.name)) return fail(where + shown + "has a NUL byte in its name");
    bool folder = !name.empty() && name.back() == '/';
    if (folder) name.pop_back();
    if (const std::string problem = bundle_path_problem(name); !problem.empty())
      return fail(where + shown + problem);
    zip_uint8_t opsys = 0;
    zip_uint32_t attributes = 0;
    if (zip_file_get_external_attributes(z.get(), i, 0, &opsys, &attributes) != 0)
      return fail(where + shown + "unreadable attributes");
    if (opsys == ZIP_OPSYS_UNIX) {
      const mode_t mode = mode_t(attributes >> 16);
      const mode_t type = mode & S_IFMT;
      if (type == S_IFLNK) return fail(where + shown + "is a symbolic link");
      if (type == S_IFCHR || type == S_IFBLK) return fail(where + shown + "is a device");
      if (type == S_IFIFO || type == S_IFSOCK) return fail(where + shown + "is not a regular file");
      if (type == S_IFDIR) folder = true;
      else if (type != 0 && type != S_IFREG) return fail(where + shown + "is not a regular file");
    }
    if ((st.valid & ZIP_STAT_ENCRYPTION_METHOD) && st.encryption_method != ZIP_EM_NONE)
      return fail(where + shown + "is encrypted");
    if (!seen.insert(name).second) return fail(where + shown + "appears twice");
    if (limits.listed && !folder && !limits.listed->count(name)) return fail(where + shown + "not in the manifest");
    list.push_back({i, name, folder, (st.valid & ZIP_STAT_COMP_SIZE) ? st.comp_size : 0});
  }
  // A file and a folder of the same name ("a" and "a/b") cannot both be extracted.
  std::set<std::string> files;
  for (const ZipEntry& e : list)
    if (!e.folder) files.insert(e.name);
  for (const ZipEntry& e : list)
    for (size_t slash = e.name.find('/'); slash != std::string::npos; slash = e.name.find('/', slash + 1))
      if (files.count(e.name.substr(0, slash))) return fail(where + "entry " + quoted_name(e.name) + ": its folder is a file");

  *opened = std::move(z);
  return list;
}

}  // namespace

Status check_zip(const fs::path& zip_path, const ZipLimits& limits) {
  ZipPtr z;
  Result<std::vector<ZipEntry>> list = zip_entries(zip_path, limits, &z);
  if (!list) return fail(list.error());
  return {};
}

Status extract_zip(const fs::path& zip_path, const fs::path& into, const ZipLimits& limits) {
  const std::string where = zip_path.string() + ": ";
  ZipPtr z;
  Result<std::vector<ZipEntry>> entries = zip_entries(zip_path, limits, &z);
  if (!entries) return fail(entries.error());
  const std::vector<ZipEntry>& list = *entries;
  std::uint64_t total = 0;
  std::vector<char> buf(1 << 16);
  for (const ZipEntry& e : list) {
    const std::string shown = "entry " + quoted_name(e.name) + ": ";
    const fs::path target = into / e.name;
    std::error_code ec;
    // Folders are made by us, one by one, never through a link: the names were checked and nothing but this
    // function writes in `into`.
    const fs::path folder = e.folder ? target : target.parent_path();
    fs::create_directories(folder, ec);
    if (ec) return fail(where + shown + "cannot be extracted (" + ec.message() + ")");
    if (e.folder) continue;
    zip_file_t* f = zip_fopen_index(z.get(), e.index, 0);
    if (!f) return fail(where + shown + "cannot be read (" + zip_strerror(z.get()) + ")");
    struct FileCloser {
      zip_file_t* f;
      ~FileCloser() { zip_fclose(f); }
    } closer{f};
    Fd out(::open(target.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600));
    if (out.get() < 0) return fail(where + shown + "cannot be extracted (" + errno_text(errno) + ")");
    std::uint64_t inflated = 0;
    for (;;) {
      const zip_int64_t r = zip_fread(f, buf.data(), buf.size());
      if (r < 0) return fail(where + shown + "cannot be read (" + zip_file_strerror(f) + ")");
      if (r == 0) break;
      // The bytes really inflated are counted, whatever the entry declares.
      inflated += std::uint64_t(r);
      total += std::uint64_t(r);
      if (inflated > limits.max_file_bytes)
        return fail(where + shown + "inflates past " + std::to_string(limits.max_file_bytes) +
                    " bytes, the limit for one file");
      if (limits.listed && inflated > limits.listed->at(e.name))
        return fail(where + shown + "inflates past its " + std::to_string(limits.listed->at(e.name)) +
                    " bytes in the manifest");
      if (total > limits.max_total_bytes)
        return fail(where + shown + "the bundle inflates past " + std::to_string(limits.max_total_bytes) +
                    " bytes, the limit for all files");
      if (double(inflated) > limits.max_ratio * double(std::max<zip_uint64_t>(e.comp_size, 1)))
        return fail(where + shown + "inflates more than " + std::to_string(int(limits.max_ratio)) +
                    " times its compressed size (a zip bomb?)");
      size_t done = 0;
      while (done < size_t(r)) {
        const ssize_t w = ::write(out.get(), buf.data() + done, size_t(r) - done);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return fail(where + shown + "cannot be extracted (" + errno_text(errno) + ")");
        done += size_t(w);
      }
    }
  }
  return {};
}

Result<std::string> read_zip_entry(const fs::path& zip_path, const std::string& name, std::uint64_t max_bytes) {
  int code = 0;
  ZipPtr z(zip_open(zip_path.c_str(), ZIP_RDONLY, &code));
  if (!z) return fail(zip_path.string() + ": not a readable zip (" + zip_error_text(code) + ")");
  const zip_int64_t idx = zip_name_locate(z.get(), name.c_str(), ZIP_FL_ENC_RAW);
  if (idx < 0) return fail(zip_path.string() + ": has no " + name);
  zip_file_t* f = zip_fopen_index(z.get(), zip_uint64_t(idx), 0);
  if (!f) return fail(zip_path.string() + ": " + name + ": cannot be read (" + zip_strerror(z.get()) + ")");
  std::string out;
  char buf[1 << 14];
  for (;;) {
    const zip_int64_t r = zip_fread(f, buf, sizeof buf);
    if (r < 0) {
      const std::string why = zip_file_strerror(f);
      zip_fclose(f);
      return fail(zip_path.string() + ": " + name + ": cannot be read (" + why + ")");
    }
    if (r == 0) break;
    out.append(buf, size_t(r));
    if (out.size() > max_bytes) {
      zip_fclose(f);
      return fail(zip_path.string() + ": " + name + ": larger than " + std::to_string(max_bytes) + " bytes");
    }
  }
  zip_fclose(f);
  return out;
}

}  // namespace arwb::bundle
