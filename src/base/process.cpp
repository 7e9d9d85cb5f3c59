#include "base/process.hpp"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace arwb {

Result<ProcessResult> run_program(const std::vector<std::string>& argv) {
  if (argv.empty()) return fail("no program named");
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) return fail(argv[0] + ": " + std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 1);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int err = posix_spawnp(&pid, argv[0].c_str(), &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(pipe_fds[1]);
  if (err != 0) {
    ::close(pipe_fds[0]);
    if (err == ENOENT) return fail(argv[0] + " is not installed (not found on PATH)");
    return fail(argv[0] + ": " + std::strerror(err));
  }
  ProcessResult r;
  constexpr std::size_t kKeep = 64 * 1024;
  char block[4096];
  for (;;) {
    const ssize_t n = ::read(pipe_fds[0], block, sizeof block);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    r.output.append(block, std::size_t(n));
    if (r.output.size() > 2 * kKeep) r.output.erase(0, r.output.size() - kKeep);
  }
  ::close(pipe_fds[0]);
  if (r.output.size() > kKeep) r.output.erase(0, r.output.size() - kKeep);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return fail(argv[0] + ": " + std::strerror(errno));
  r.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

}  // namespace arwb
