#include "base/temp_dir.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <mutex>
#include <system_error>

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

namespace arwb {

namespace fs = std::filesystem;

namespace {

// The folders alive, for the signal handler, which may neither lock a mutex nor allocate: fixed slots of paths,
// each published by its state (0 free, 1 being written, 2 alive). A folder that finds no free slot is still
// removed by its owner, or as an orphan by a later run.
constexpr int kSlots = 64;
struct Slot {
  std::atomic<int> state{0};
  char path[4096];
};
Slot g_slots[kSlots];

int enrol(const fs::path& path) {
  const std::string& p = path.native();
  if (p.size() >= sizeof Slot::path) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int free = 0;
    if (!g_slots[i].state.compare_exchange_strong(free, 1)) continue;
    std::memcpy(g_slots[i].path, p.c_str(), p.size() + 1);
    g_slots[i].state.store(2);
    return i;
  }
  return -1;
}

// Everything under the open folder `dir`, removed with system calls only (async-signal-safe: no allocation, no
// lock), `depth` folders deep at most; what lies deeper is left for the next run's orphan search. Entries removed
// while the folder is listed may hide others from that listing, so it is listed again until a pass removes none.
void remove_under(int dir, int depth) {
  alignas(struct dirent64) char buf[1024];
  for (bool removed = true; removed;) {
    removed = false;
    if (::lseek(dir, 0, SEEK_SET) < 0) return;
    for (;;) {
      const ssize_t n = ::getdents64(dir, buf, sizeof buf);
      if (n <= 0) break;
      for (ssize_t at = 0; at < n;) {
        const auto* d = reinterpret_cast<const struct dirent64*>(buf + at);
        at += d->d_reclen;
        const char* name = d->d_name;
        if (name[0] == '.' && (name[1] == 0 || (name[1] == '.' && name[2] == 0))) continue;
        if (::unlinkat(dir, name, 0) == 0) {
          removed = true;
          continue;
        }
        if (errno != EISDIR) continue;
        if (depth > 0) {
          const int sub = ::openat(dir, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
          if (sub >= 0) {
            remove_under(sub, depth - 1);
            ::close(sub);
          }
        }
        if (::unlinkat(dir, name, AT_REMOVEDIR) == 0) removed = true;
      }
    }
  }
}

void remove_enrolled() {
  for (Slot& s : g_slots) {
    if (s.state.load() != 2) continue;
    const int dir = ::open(s.path, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (dir < 0) continue;
    remove_under(dir, 48);
    ::close(dir);
    ::rmdir(s.path);
  }
}

extern "C" void on_ending_signal(int sig) {
  const int saved = errno;
  remove_enrolled();
  // The handler was installed with SA_RESETHAND: the signal, raised again, takes its default course once this
  // handler returns, and the process ends as the sender meant.
  ::raise(sig);
  errno = saved;
}

extern "C" void at_exit() { remove_enrolled(); }

// The age of a folder's last change of contents, in seconds.
double age_seconds(const struct stat& st) {
  struct timespec now {};
  ::clock_gettime(CLOCK_REALTIME, &now);
  return double(now.tv_sec - st.st_mtim.tv_sec) + 1e-9 * double(now.tv_nsec - st.st_mtim.tv_nsec);
}

}  // namespace

void remove_temp_dirs_on_exit_and_signals() {
  static std::once_flag once;
  std::call_once(once, [] {
    std::atexit(at_exit);
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      if (::sigaction(sig, nullptr, &old) != 0 || old.sa_handler == SIG_IGN) continue;   // nohup's SIGHUP, say
      struct sigaction sa {};
      sa.sa_handler = on_ending_signal;
      sa.sa_flags = SA_RESETHAND;
      sigemptyset(&sa.sa_mask);
      ::sigaction(sig, &sa, nullptr);
    }
  });
}

int remove_orphan_temp_dirs(const fs::path& folder, const std::string& stem) {
  std::error_code ec;
  int removed = 0;
  const std::string prefix = stem + "-";
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() != prefix.size() + 6 || name.compare(0, prefix.size(), prefix) != 0) continue;
    struct stat st {};
    if (::lstat(it->path().c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != ::geteuid()) continue;
    // A folder made a moment ago may not be locked yet by its maker.
    if (age_seconds(st) < 60) continue;
    const int dir = ::open(it->path().c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (dir < 0) continue;
    if (::flock(dir, LOCK_EX | LOCK_NB) == 0) {
      std::error_code rm;
      fs::remove_all(it->path(), rm);
      if (!rm) ++removed;
    }
    ::close(dir);
  }
  return removed;
}

Result<TempDir> TempDir::make(const fs::path& near, const std::string& stem) {
  std::error_code ec;
  const fs::path base = fs::absolute(near.empty() ? fs::temp_directory_path(ec) : near, ec);
  if (ec) return fail("no temporary folder (" + ec.message() + ")");
  remove_orphan_temp_dirs(base, stem);
  std::string templ = (base / (stem + "-XXXXXX")).string();
  if (!::mkdtemp(templ.data()))
    return fail("cannot create a folder in " + base.string() + " (" + std::strerror(errno) + ")");
  TempDir t;
  t.path_ = templ;
  t.lock_ = ::open(templ.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (t.lock_ >= 0) ::flock(t.lock_, LOCK_EX | LOCK_NB);
  t.slot_ = enrol(t.path_);
  return t;
}

TempDir::TempDir(TempDir&& o) noexcept : path_(std::move(o.path_)), lock_(o.lock_), slot_(o.slot_) {
  o.path_.clear();
  o.lock_ = o.slot_ = -1;
}

TempDir& TempDir::operator=(TempDir&& o) noexcept {
  if (this != &o) {
    release();
    path_ = std::move(o.path_);
    lock_ = o.lock_;
    slot_ = o.slot_;
    o.path_.clear();
    o.lock_ = o.slot_ = -1;
  }
  return *this;
}

TempDir::~TempDir() { release(); }

void TempDir::release() {
  std::error_code ec;
  if (!path_.empty()) fs::remove_all(path_, ec);
  path_.clear();
  if (slot_ >= 0) g_slots[slot_].state.store(0);
  if (lock_ >= 0) ::close(lock_);
  slot_ = lock_ = -1;
}

}  // namespace arwb
