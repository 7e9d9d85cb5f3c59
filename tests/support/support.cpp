#include "support/support.hpp"

#include <fstream>
#include <random>
#include <sstream>
#include <sys/wait.h>

namespace arwb::test {

TempDir::TempDir() {
  std::random_device rd;
  path_ = std::filesystem::temp_directory_path() / ("arwb_test_" + std::to_string(rd()) + std::to_string(rd()));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

namespace {
RunResult run_arwb_with_prefix(const std::string& prefix, const std::string& args) {
  TempDir tmp;
  std::string out = tmp.str("out.txt"), err = tmp.str("err.txt");
  std::string cmd = prefix + "'" + ARWB_BINARY + "' " + args + " >'" + out + "' 2>'" + err + "' </dev/null";
  int raw = std::system(cmd.c_str());
  RunResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  r.out = read_file(out);
  r.err = read_file(err);
  return r;
}
}  // namespace

RunResult run_arwb(const std::string& args) { return run_arwb_with_prefix("", args); }

RunResult run_arwb_window(const std::string& args) {
  // -a picks a free display number, so GUI tests can run in parallel. The screen holds the largest window the
  // tests open (--size 1920x1080); the default window is 1600x900.
  const std::string prefix = "xvfb-run -a -s '-screen 0 1920x1080x24' ";
  // A run that says nothing about arwb is run again, up to twice:
  // - Xvfb resets when its last client leaves; a window that closes at once (the player's error window) can race
  //   xvfb-run's own clean-up of its folder, and xvfb-run then exits 5 with the line below instead of arwb's status
  //   (4 in 60 runs here; arwb itself never exits 5). Xvfb's -noreset avoids the race, but under the sanitizers
  //   LeakSanitizer's tracer then crashed at arwb's exit in 3 of 3 runs of a workbench test, against 1 of 3 without.
  // - In the sanitizer tree, LeakSanitizer's own tracer can crash as it stops the world at arwb's exit while a
  //   thread of the window (Mesa's, GLFW's) is ending: it says so and exits 1 without having checked for leaks (1 run
  //   in 3 of Workbench.KeepsTheLayoutBetweenRuns on 2026-11-27). A leak found ("detected memory leaks") is not
  //   retried.
  auto says_nothing = [](const RunResult& r) {
    const char* cleanup = "xvfb-run: error: problem while cleaning up temporary directory";
    const bool xvfb_cleanup = r.status == 5 && r.err.find(cleanup) != std::string::npos;
    const bool tracer_crash = r.status != 0 && r.err.find("Tracer caught signal") != std::string::npos &&
                              r.err.find("LeakSanitizer has encountered a fatal error") != std::string::npos;
    return xvfb_cleanup || tracer_crash;
  };
  RunResult r = run_arwb_with_prefix(prefix, args);
  for (int again = 0; again < 2 && says_nothing(r); ++again) r = run_arwb_with_prefix(prefix, args);
  return r;
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

namespace {
nlohmann::ordered_json stats_of(const std::string& out, const std::string& err) {
  const std::string line = out.substr(0, out.find('\n'));
  auto s = nlohmann::ordered_json::parse(line, nullptr, false);
  if (s.is_object()) return s;
  ADD_FAILURE() << "the first line is not a JSON object: " << out << (err.empty() ? "" : "\nstderr: ") << err;
  return nlohmann::ordered_json::object();
}
}  // namespace

nlohmann::ordered_json stats(const RunResult& r) { return stats_of(r.out, r.err); }
nlohmann::ordered_json stats(const std::string& out) { return stats_of(out, ""); }

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (!l.empty()) out.push_back(l);
  return out;
}

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace arwb::test
