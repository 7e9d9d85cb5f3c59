// Where the shipped data is looked for: beside an installed executable (bin/arwb -> share/arwb), else in the source
// tree; only a share/arwb that holds assets counts.
#include "base/data_dirs.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace arwb {
namespace {

namespace fs = std::filesystem;

TEST(DataDirs, AnInstalledExecutableUsesItsOwnShareFolder) {
  test::TempDir prefix;
  fs::create_directories(prefix.path() / "bin");
  fs::create_directories(prefix.path() / "share/arwb/assets/teaching");
  fs::create_directories(prefix.path() / "share/arwb/examples");
  const DataDirs d = find_data_dirs(prefix.path() / "bin/arwb", "/nowhere/source");
  EXPECT_TRUE(d.installed);
  EXPECT_EQ(d.assets, (prefix.path() / "share/arwb/assets").string());
  EXPECT_EQ(d.examples, (prefix.path() / "share/arwb/examples").string());
  EXPECT_EQ(d.web, (prefix.path() / "share/arwb/web").string());
}

TEST(DataDirs, ABuildTreeExecutableUsesTheSourceTree) {
  test::TempDir build;   // build/arwb: build/../share/arwb does not exist
  fs::create_directories(build.path() / "build");
  const DataDirs d = find_data_dirs(build.path() / "build/arwb", "/src/tree/", build.path() / "build");
  EXPECT_FALSE(d.installed);
  EXPECT_EQ(d.assets, "/src/tree/assets");
  EXPECT_EQ(d.examples, "/src/tree/scripts");
  EXPECT_EQ(d.web, (build.path() / "build/web/site").string());   // the site the build assembles
}

TEST(DataDirs, AShareFolderWithoutAssetsIsNotAnInstallation) {
  // /usr/local/share/arwb left with only examples (or a user's own folder of that name) is not taken for a
  // complete installation: the tour and presets would be missing.
  test::TempDir prefix;
  fs::create_directories(prefix.path() / "share/arwb/examples");
  test::write_file(prefix.str("share/arwb/assets"), "a file, not a folder");
  const DataDirs d = find_data_dirs(prefix.path() / "bin/arwb", "/src/tree");
  EXPECT_FALSE(d.installed);
  EXPECT_EQ(d.assets, "/src/tree/assets");
}

TEST(DataDirs, AnUnknownExecutableUsesTheSourceTree) {
  const DataDirs d = find_data_dirs("", "/src/tree");
  EXPECT_FALSE(d.installed);
  EXPECT_EQ(d.examples, "/src/tree/scripts");
}

TEST(DataDirs, ThisTestBinaryIsInABuildTree) {
  // The test runs from build/tests/...; the process's lookup resolves /proc/self/exe and finds the source tree.
  const DataDirs& d = data_dirs();
  EXPECT_FALSE(d.installed);
  EXPECT_EQ(d.assets, (fs::path(ARWB_SOURCE_DIR) / "assets").lexically_normal().string());
  EXPECT_TRUE(fs::is_regular_file(fs::path(d.assets) / "teaching/tour.txt"));
  EXPECT_TRUE(fs::is_directory(d.examples));
}

}  // namespace
}  // namespace arwb
