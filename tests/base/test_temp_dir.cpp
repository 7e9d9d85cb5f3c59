#include "base/temp_dir.hpp"

#include "support/support.hpp"

#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <future>
#include <thread>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace arwb {
namespace {

namespace fs = std::filesystem;

// Sets a folder's time of last change `seconds` back, as if it had been made then.
void age(const fs::path& p, int seconds) {
  fs::last_write_time(p, fs::last_write_time(p) - std::chrono::seconds(seconds));
}

TEST(TempDir, IsPrivateAndGoesWithItsOwnerWithEverythingInIt) {
  test::TempDir in;
  fs::path made;
  {
    Result<TempDir> t = TempDir::make(in.path(), "arwb-x");
    ASSERT_TRUE(t) << t.error();
    made = t->path();
    EXPECT_EQ(made.parent_path(), in.path());
    EXPECT_EQ(made.filename().string().rfind("arwb-x-", 0), 0u);
    EXPECT_EQ(fs::status(made).permissions(), fs::perms::owner_all);
    fs::create_directories(made / "a/b");
    std::ofstream(made / "a/b/c.txt") << "c";
    TempDir moved = std::move(*t);
    EXPECT_EQ(moved.path(), made);
    EXPECT_TRUE(t->path().empty());
  }
  EXPECT_FALSE(fs::exists(made));
}

TEST(TempDir, AnOrphanOlderThanAMinuteIsRemovedAndALiveOneIsNot) {
  test::TempDir in;
  Result<TempDir> alive = TempDir::make(in.path(), "arwb-x");
  ASSERT_TRUE(alive) << alive.error();
  age(alive->path(), 3600);   // old, but locked by this process
  const fs::path orphan = in.path() / "arwb-x-AbC123", young = in.path() / "arwb-x-Young1";
  const fs::path other_stem = in.path() / "arwb-y-AbC123", longer = in.path() / "arwb-x-AbC1234";
  for (const fs::path& p : {orphan, young, other_stem, longer}) fs::create_directories(p / "inside");
  std::ofstream(orphan / "inside/file") << "left by a process killed with SIGKILL";
  for (const fs::path& p : {orphan, other_stem, longer}) age(p, 120);
  const fs::path link = in.path() / "arwb-x-Link01";
  fs::create_directory_symlink(other_stem, link);

  EXPECT_EQ(remove_orphan_temp_dirs(in.path(), "arwb-x"), 1);
  EXPECT_FALSE(fs::exists(orphan));
  for (const fs::path& p : {alive->path(), young, other_stem, longer, link}) EXPECT_TRUE(fs::exists(p)) << p;

  // make() looks for orphans of its stem first.
  age(young, 120);
  Result<TempDir> another = TempDir::make(in.path(), "arwb-x");
  ASSERT_TRUE(another) << another.error();
  EXPECT_FALSE(fs::exists(young));
  EXPECT_TRUE(fs::exists(alive->path()));
}

// A child process makes a folder, takes the handlers and is sent the signal: it ends by that signal, as without
// them, and its folder is gone. A signal it was started ignoring stays ignored.
int folder_left_by_child(int sig, bool ignored_at_start, const fs::path& in, int* status) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (ignored_at_start) std::signal(sig, SIG_IGN);
    remove_temp_dirs_on_exit_and_signals();
    Result<TempDir> t = TempDir::make(in, "arwb-sig");
    if (!t) ::_exit(90);
    fs::create_directories(t->path() / "deep/er");
    std::ofstream(t->path() / "deep/er/file") << "x";
    ::raise(sig);
    ::_exit(ignored_at_start ? 91 : 92);
  }
  ::waitpid(pid, status, 0);
  int left = 0;
  for (const auto& e : fs::directory_iterator(in)) {
    ++left;
    fs::remove_all(e.path());
  }
  return left;
}

TEST(TempDir, SigintSigtermAndSighupRemoveTheFoldersThenEndTheProcess) {
  test::TempDir in;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    int status = 0;
    EXPECT_EQ(folder_left_by_child(sig, false, in.path(), &status), 0) << sig;
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << sig << " " << status;
  }
  int status = 0;
  // Ignored (nohup): the child goes on to exit normally through _exit, which runs no clean-up.
  EXPECT_EQ(folder_left_by_child(SIGHUP, true, in.path(), &status), 1);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 91) << status;
}

TEST(TempDir, ANormalExitWhileAThreadHoldsOneRemovesIt) {
  test::TempDir in;
  const pid_t pid = ::fork();
  if (pid == 0) {
    remove_temp_dirs_on_exit_and_signals();
    // A thread makes the folder and never ends, as the workbench's Play bundle does while it verifies: nothing
    // destroys the folder's owner, so only the exit's clean-up can remove it.
    std::promise<bool> made;
    std::thread([&made, &in] {
      Result<TempDir> t = TempDir::make(in.path(), "arwb-exit");
      made.set_value(bool(t));
      for (;;) ::pause();
    }).detach();
    if (!made.get_future().get()) ::_exit(90);
    std::exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << status;
  EXPECT_TRUE(fs::is_empty(in.path()));
}

}  // namespace
}  // namespace arwb
