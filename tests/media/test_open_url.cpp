// open_url: links reach the opener as one argument, untouched by any shell; other schemes start nothing; the
// opener is reaped.
#include "media/open_url.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
using arwb::media::open_url;
using arwb::test::TempDir;

namespace {

// Restores an environment variable when the test ends.
class EnvGuard {
 public:
  explicit EnvGuard(const char* name) : name_(name) {
    if (const char* v = std::getenv(name)) old_ = v;
  }
  ~EnvGuard() {
    if (old_) setenv(name_, old_->c_str(), 1);
    else unsetenv(name_);
  }
  EnvGuard(const EnvGuard&) = delete;
  EnvGuard& operator=(const EnvGuard&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// An opener that records each call as a file "<dir>/call.<pid>": the argument count, then each argument followed
// by a NUL byte. Written elsewhere and moved in, so a file that exists is complete.
std::string write_recorder(const fs::path& dir, const std::string& name) {
  const fs::path script = dir / name;
  std::ofstream(script) << "#!/bin/sh\n"
                        << "out='" << dir.string() << "'\n"
                        << "{ printf '%s\\n' \"$#\"; for a in \"$@\"; do printf '%s\\0' \"$a\"; done; }"
                        << " > \"$out/tmp.$$\"\n"
                        << "mv \"$out/tmp.$$\" \"$out/call.$$\"\n";
  fs::permissions(script, fs::perms::owner_all);
  return script.string();
}

std::vector<fs::path> calls(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("call.", 0) == 0) out.push_back(e.path());
  return out;
}

// The arguments of the single recorded call, waiting for it with a generous deadline.
std::optional<std::vector<std::string>> recorded_call(const fs::path& dir) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (calls(dir).empty() && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const auto found = calls(dir);
  if (found.size() != 1) return std::nullopt;
  const std::string bytes = arwb::test::read_file(found[0].string());
  const size_t nl = bytes.find('\n');
  if (nl == std::string::npos) return std::nullopt;
  std::vector<std::string> args;
  for (size_t start = nl + 1; start < bytes.size();) {
    const size_t end_of_arg = bytes.find('\0', start);
    if (end_of_arg == std::string::npos) return std::nullopt;
    args.push_back(bytes.substr(start, end_of_arg - start));
    start = end_of_arg + 1;
  }
  if (std::to_string(args.size()) != bytes.substr(0, nl)) return std::nullopt;
  return args;
}

class OpenUrl : public ::testing::Test {
 protected:
  EnvGuard opener_env{"ARWB_URL_OPENER"};
  EnvGuard path_env{"PATH"};
  TempDir tmp;
};

}  // namespace

TEST_F(OpenUrl, PassesTheUrlAsOneArgumentUntouched) {
  setenv("ARWB_URL_OPENER", write_recorder(tmp.path(), "opener").c_str(), 1);
  // Everything a shell would act on: separators, substitutions, quotes, globs, redirections.
  const std::string url = "https://example.com/a;b&c|d?q=$(touch%20pwned)&r=`id`&s='x'\"y\"%20*>out#f\\g";
  ASSERT_EQ(open_url(url), "");
  const auto args = recorded_call(tmp.path());
  ASSERT_TRUE(args);
  ASSERT_EQ(args->size(), 1u);
  EXPECT_EQ((*args)[0], url);
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
}

TEST_F(OpenUrl, RefusesOtherSchemesWithoutStartingAnything) {
  setenv("ARWB_URL_OPENER", write_recorder(tmp.path(), "opener").c_str(), 1);
  EXPECT_EQ(open_url("ftp://x"), "ftp://x: only http and https links are opened");
  EXPECT_EQ(open_url("javascript:alert(1)"), "javascript:alert(1): only http and https links are opened");
  EXPECT_EQ(open_url("file:///etc/passwd"), "file:///etc/passwd: only http and https links are opened");
  EXPECT_EQ(open_url("https://a b"), "https://a b: contains spaces or control characters");
  EXPECT_NE(open_url("https://example.com/" + std::string(3000, 'a')), "");
  // A good link after them: its call must be the only one recorded.
  ASSERT_EQ(open_url("https://example.com/sentinel"), "");
  const auto args = recorded_call(tmp.path());
  ASSERT_TRUE(args) << calls(tmp.path()).size() << " calls recorded";
  EXPECT_EQ(*args, std::vector<std::string>{"https://example.com/sentinel"});
}

TEST_F(OpenUrl, StartsXdgOpenFromThePathByDefault) {
  unsetenv("ARWB_URL_OPENER");
  write_recorder(tmp.path(), "xdg-open");
  // First on the PATH; the rest stays, as the recorder needs mv.
  const char* path = std::getenv("PATH");
  setenv("PATH", (tmp.str() + ":" + (path ? path : "/usr/bin:/bin")).c_str(), 1);
  ASSERT_EQ(open_url("http://example.org/"), "");
  const auto args = recorded_call(tmp.path());
  ASSERT_TRUE(args);
  EXPECT_EQ(*args, std::vector<std::string>{"http://example.org/"});
}

TEST_F(OpenUrl, ReportsAnOpenerThatCannotStart) {
  setenv("ARWB_URL_OPENER", (tmp.path() / "no-such-opener").c_str(), 1);
  const std::string error = open_url("https://example.com/");
  EXPECT_NE(error.find("cannot start " + tmp.str("no-such-opener")), std::string::npos) << error;
  EXPECT_NE(error.find("No such file"), std::string::npos) << error;

  std::ofstream(tmp.path() / "not-executable") << "#!/bin/sh\n";
  setenv("ARWB_URL_OPENER", (tmp.path() / "not-executable").c_str(), 1);
  EXPECT_NE(open_url("https://example.com/"), "");
}

TEST_F(OpenUrl, ReapsTheOpenerSoItLeavesNoZombie) {
  setenv("ARWB_URL_OPENER", write_recorder(tmp.path(), "opener").c_str(), 1);
  ASSERT_EQ(open_url("https://example.com/z"), "");
  ASSERT_TRUE(recorded_call(tmp.path()));
  // The recorder names its file after its pid. Once it ends, only a waitpid removes it from /proc: a child
  // nobody waits for stays there as a zombie for as long as this process lives.
  const std::string name = calls(tmp.path()).at(0).filename().string();
  const fs::path proc = "/proc/" + name.substr(name.find('.') + 1);
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (fs::exists(proc) && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_FALSE(fs::exists(proc)) << arwb::test::read_file((proc / "stat").string());
}
