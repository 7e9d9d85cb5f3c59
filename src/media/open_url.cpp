#include "media/open_url.hpp"

#include "media/media_path.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdlib>
#include <system_error>
#include <thread>

extern char** environ;

namespace arwb::media {

std::string open_url(const std::string& url) {
  if (std::string reason = check_url(url); !reason.empty()) return reason;

  const char* env = std::getenv("ARWB_URL_OPENER");
  const std::string program = env && *env ? env : "xdg-open";

  // The opener must not read the workbench's terminal.
  posix_spawn_file_actions_t actions;
  if (const int rc = posix_spawn_file_actions_init(&actions); rc != 0)
    return "cannot start " + program + ": " + std::generic_category().message(rc);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);

  // An argument vector, no shell: every character of the URL reaches the opener as written.
  std::string arg0 = program, arg1 = url;
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return "cannot start " + program + ": " + std::generic_category().message(rc);

  // Not waited for here (a browser may stay), but reaped when it ends so it leaves no zombie.
  try {
    std::thread([pid] {
      int status = 0;
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
    }).detach();
  } catch (const std::system_error&) {
    // No thread to spare: the opener was started all the same; it stays a zombie until the workbench exits.
  }
  return {};
}

}  // namespace arwb::media
