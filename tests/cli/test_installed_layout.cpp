// An arwb copied into an installation's layout (PREFIX/bin/arwb beside PREFIX/share/arwb, as the Debian package puts
// it) reads its shipped data there, not from the source tree it was built in; `arwb --help` names the folders.
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include <sys/wait.h>

namespace arwb {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

// Runs PROGRAM (a copy or link of arwb) with the arguments, as run_arwb does for the built one.
test::RunResult run_program(const fs::path& program, const std::string& args) {
  TempDir tmp;
  const std::string out = tmp.str("out.txt"), err = tmp.str("err.txt");
  // Appended piece by piece: GCC 12's -Wrestrict misfires on "'" + std::string (a known false positive).
  std::string cmd = "'";
  cmd += program.string();
  cmd += "' " + args + " >'" + out + "' 2>'" + err + "' </dev/null";
  const int raw = std::system(cmd.c_str());
  test::RunResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
  r.out = test::read_file(out);
  r.err = test::read_file(err);
  return r;
}

TEST(InstalledLayout, ACopyInAPrefixUsesItsShareFolder) {
  TempDir prefix;
  fs::create_directories(prefix.path() / "bin");
  fs::create_directories(prefix.path() / "share/arwb/assets/teaching");
  fs::create_directories(prefix.path() / "share/arwb/examples");
  fs::copy_file(ARWB_BINARY, prefix.path() / "bin/arwb");
  const auto r = run_program(prefix.path() / "bin/arwb", "--help");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string share = (prefix.path() / "share/arwb").string();
  EXPECT_NE(r.out.find("installed beside arwb"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(share + "/assets\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(share + "/examples\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(share + "/assets/teaching/tour.txt)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find(std::string(ARWB_SOURCE_DIR) + "/assets"), std::string::npos) << r.out;

  // A link to the installed binary (~/bin/arwb -> PREFIX/bin/arwb) finds the same folder: the real file counts.
  fs::create_directories(prefix.path() / "elsewhere");
  fs::create_symlink(prefix.path() / "bin/arwb", prefix.path() / "elsewhere/arwb");
  const auto linked = run_program(prefix.path() / "elsewhere/arwb", "--help");
  EXPECT_NE(linked.out.find(share + "/assets\n"), std::string::npos) << linked.out;
}

TEST(InstalledLayout, TheBuiltBinaryUsesTheSourceTree) {
  const auto r = test::run_arwb("--help");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string source = fs::path(ARWB_SOURCE_DIR).lexically_normal().string();
  EXPECT_NE(r.out.find("in the source tree arwb was built from"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(source + "/assets\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(source + "/scripts\n"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace arwb
