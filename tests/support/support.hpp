// Shared helpers for the test binaries: temporary folders, running the arwb binary and reading what it printed.
#pragma once
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

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

// The JSON line `arwb --stats` prints first (the window's tests read what the workbench did from it). A first line
// that is not a JSON object fails the test, naming the output (and the run's stderr), and gives an empty object.
nlohmann::ordered_json stats(const RunResult& r);
nlohmann::ordered_json stats(const std::string& out);

// `s` in single quotes, as one word of run_arwb's shell line (for the paths the tests make, which hold no quote).
inline std::string q(const std::string& s) { return "'" + s + "'"; }

// The lines of a program's output (its newlines).
inline size_t line_count(const std::string& s) { return size_t(std::count(s.begin(), s.end(), '\n')); }

// The text's lines that are not empty.
std::vector<std::string> lines(const std::string& text);

}  // namespace arwb::test
