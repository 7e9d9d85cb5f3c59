// Result and Status: a value or a message, never both; and whole-file writing that never leaves half a file.
#include "base/files.hpp"
#include "base/result.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace arwb {
namespace {

Result<int> half(int v) {
  if (v % 2) return fail(std::to_string(v) + " is odd");
  return v / 2;
}

Status check(bool good) {
  if (!good) return fail("bad");
  return {};
}

TEST(Result, CarriesAValueOrAMessage) {
  auto a = half(8);
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(*a, 4);
  EXPECT_EQ(a.error(), "");
  auto b = half(7);
  EXPECT_FALSE(b);
  EXPECT_EQ(b.error(), "7 is odd");
  EXPECT_THROW((void)b.value(), std::bad_variant_access) << "reading a failed result's value is a programmer error";
  Result<std::string> s = std::string("text");
  EXPECT_EQ(s->size(), 4u);
  EXPECT_EQ(std::move(s).value(), "text");
}

TEST(Result, StatusIsSuccessOrAMessage) {
  EXPECT_TRUE(check(true));
  EXPECT_EQ(check(true).error(), "");
  EXPECT_FALSE(check(false));
  EXPECT_EQ(check(false).error(), "bad");
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Files, WriteAtomicallyReplacesTheWholeFile) {
  test::TempDir dir;
  const std::string path = dir.str("scene.lua");
  std::string err;
  ASSERT_TRUE(write_file_atomically(path, "first version, longer than the second", &err)) << err;
  ASSERT_TRUE(write_file_atomically(path, "second", &err)) << err;
  EXPECT_EQ(slurp(path), "second");
  EXPECT_FALSE(std::filesystem::exists(path + ".arwb-saving")) << "no temporary file is left behind";
}

// Files that belong together: all replaced, or, when one cannot be written, none (the others keep their old text)
// and no temporary file is left; the error names the file it is about.
TEST(Files, FilesWrittenTogetherAreAllReplacedOrNone) {
  test::TempDir dir;
  const std::string a = dir.str("a.yml"), b = dir.str("b.xml");
  std::string failed, err;
  ASSERT_TRUE(write_files_atomically({{a, "a one"}, {b, "b one"}}, &failed, &err)) << err;
  EXPECT_EQ(slurp(a), "a one");
  EXPECT_EQ(slurp(b), "b one");
  const std::string missing = dir.str("no/such/folder/c.xml");
  EXPECT_FALSE(write_files_atomically({{a, "a two"}, {b, "b two"}, {missing, "c"}}, &failed, &err));
  EXPECT_EQ(failed, missing);
  EXPECT_FALSE(err.empty());
  EXPECT_EQ(slurp(a), "a one") << "nothing is replaced when one file cannot be written";
  EXPECT_EQ(slurp(b), "b one");
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename().string().find("arwb-saving"), std::string::npos) << e.path();
}

TEST(Files, WriteIntoAMissingFolderFailsAndSaysWhy) {
  test::TempDir dir;
  std::string err;
  EXPECT_FALSE(write_file_atomically(dir.str("no/such/folder/scene.lua"), "x", &err));
  EXPECT_FALSE(err.empty());
}

}  // namespace
}  // namespace arwb
