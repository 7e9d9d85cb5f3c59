// Shared helpers for the test binaries: temporary folders and running the arwb binary.
#pragma once
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace arwb::test {

// A fresh empty folder under the system temp dir, removed when the object goes.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string str(const std::string& name = "") const { return name.empty() ? path_.string() : (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

struct RunResult {
  int status = -1;      // exit status of the process
  std::string out;      // its stdout
  std::string err;      // its stderr
};

// Runs the arwb binary with the arguments given as one shell-quoted string.
RunResult run_arwb(const std::string& args);

// Runs the arwb binary in a virtual X display (xvfb-run, a 1920x1080 screen, Mesa's software OpenGL), for the
// workbench window's tests.
RunResult run_arwb_window(const std::string& args);

// Writes bytes to a file.
void write_file(const std::string& path, const std::string& bytes);
std::string read_file(const std::string& path);

// Text as JSON (keys in their written order); a parse error fails the test with nlohmann's message and the text
// near the byte it names.
inline nlohmann::ordered_json parse(const std::string& text) {
  try {
    return nlohmann::ordered_json::parse(text);
  } catch (const nlohmann::ordered_json::parse_error& e) {
    ADD_FAILURE() << e.what() << "\nnear: " << text.substr(e.byte > 40 ? e.byte - 40 : 0, 80);
    return {};
  }
}

// The JSON line `arwb --stats` prints first (the window's tests read what the workbench did from it).
inline nlohmann::ordered_json stats_line(const RunResult& r) { return parse(r.out.substr(0, r.out.find('\n'))); }

}  // namespace arwb::test
