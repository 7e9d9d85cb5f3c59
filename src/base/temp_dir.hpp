// Private temporary folders (a played bundle's copy, an export's unfinished bundle), removed however the process
// ends: by their owner, at exit, on SIGINT, SIGTERM and SIGHUP, or, after a crash or SIGKILL, by the next run that
// makes one beside them.
#pragma once

#include "base/result.hpp"

#include <filesystem>
#include <string>

namespace arwb {

// A new private folder (0700) `stem`-XXXXXX beside `near` (or in the system's temporary folder when `near` is
// empty), removed with everything in it when this is destroyed. While it lives, the
// process holds a lock on it (flock, released by the kernel however the process ends): a folder of this stem that
// nobody locks, owned by this user and older than a minute, is an orphan, and make() removes it first.
class TempDir {
 public:
  static Result<TempDir> make(const std::filesystem::path& near, const std::string& stem);
  TempDir() = default;
  TempDir(TempDir&& o) noexcept;
  TempDir& operator=(TempDir&& o) noexcept;
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir();
  const std::filesystem::path& path() const { return path_; }

 private:
  void release();
  std::filesystem::path path_;
  int lock_ = -1;   // the folder, open and flock'ed
  int slot_ = -1;   // its place among the folders removed on a signal and at exit, -1 when not there
};

// From here on, SIGINT, SIGTERM and SIGHUP first remove every TempDir alive, then take their usual course (the
// process ends with that signal), and so does a normal exit while a thread still holds one. A signal the process
// was started ignoring stays ignored. Called once, from main.
void remove_temp_dirs_on_exit_and_signals();

// The orphans of `stem` in `folder` (see TempDir), removed; how many. make() calls it.
int remove_orphan_temp_dirs(const std::filesystem::path& folder, const std::string& stem);

}  // namespace arwb
