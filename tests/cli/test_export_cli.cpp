// `arwb export`: the summary (files, sizes, the self-test table, where it wrote), exit 0; an existing bundle
// kept without --force; a scene that cannot be exported is one line naming the file and line, exit 1, with
// nothing written; usage errors exit 2.
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace {

namespace fs = std::filesystem;
using arwb::test::run_arwb;
using arwb::test::TempDir;
using arwb::test::write_file;

const std::string kMuseum = std::string(ARWB_SOURCE_DIR) + "/scripts/museum/museum.lua";

size_t lines(const std::string& text) {
  size_t n = 0;
  for (const char c : text) n += c == '\n';
  return n;
}

TEST(ExportCli, WritesABundleAndSaysWhatIsInIt) {
  TempDir out;
  const std::string bundle = out.str("museum.arwb");
  const auto r = run_arwb("export --scene '" + kMuseum + "' --out '" + bundle + "' --title 'Museum room' --marker-size-mm 80");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  for (const char* part : {"files:", "scene/media/orbit.mp4", "markers.pdf", "README.txt", "self-test (ARUCO_ORIGINAL, 3 ids)",
                           "detected  fired", "image media/composition.png",
                           "exported Museum room (3 markers of ARUCO_ORIGINAL, 80 mm) to " })
    EXPECT_NE(r.out.find(part), std::string::npos) << part << "\n" << r.out;
  EXPECT_TRUE(fs::is_regular_file(bundle));

  // Kept without --force: one line, status 1.
  const auto again = run_arwb("export --scene '" + kMuseum + "' --out '" + bundle + "'");
  EXPECT_EQ(again.status, 1);
  EXPECT_EQ(lines(again.err), 1u) << again.err;
  EXPECT_NE(again.err.find("exists; add --force to replace it"), std::string::npos) << again.err;
  const auto forced = run_arwb("export --scene '" + kMuseum + "' --out '" + bundle + "' --force --quiet");
  EXPECT_EQ(forced.status, 0) << forced.err;
  EXPECT_EQ(lines(forced.out), 1u) << forced.out;
}

TEST(ExportCli, ASceneThatCannotBeExportedIsOneLineAndWritesNothing) {
  TempDir out;
  fs::copy(fs::path(kMuseum).parent_path(), out.path() / "src", fs::copy_options::recursive);
  write_file(out.str("src/broken.lua"), "marker(1, { media = image 'media/sunset.png' })\nmarker(2, { media = image 'media/nope.png' })\n");
  const auto r = run_arwb("export --scene '" + out.str("src/broken.lua") + "' --out '" + out.str("b") + "'");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("arwb export: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("broken.lua:2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("media/nope.png: no such file"), std::string::npos) << r.err;
  // The export stops there; the load-time wording ("; marker(2) skipped") would say it went on.
  EXPECT_NE(r.err.find("arwb export: cannot export: "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("skipped"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out.path() / "b"));
}

// A model that does not load is refused in the loader's own words, as render says them, not "cannot load m/a.glb".
TEST(ExportCli, AModelThatDoesNotLoadIsRefusedWithTheLoadersReason) {
  TempDir out;
  fs::create_directories(out.path() / "m");
  write_file(out.str("m/b.glb"), "garbage");
  write_file(out.str("scene.lua"), "marker(843, { media = model \"m/b.glb\", place = on_marker {} })\n");
  const auto r = run_arwb("export --scene '" + out.str("scene.lua") + "' --out '" + out.str("b.arwb") + "'");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("m/b.glb: not a 3D model (OBJ, glTF or GLB)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out.path() / "b.arwb"));
}

TEST(ExportCli, UsageErrors) {
  TempDir out;
  auto r = run_arwb("export --out '" + out.str("b") + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--scene"), std::string::npos) << r.err;
  r = run_arwb("export --scene '" + kMuseum + "' --out '" + out.str("b") + "' --marker-size-mm 2");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--marker-size-mm 2"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out.path() / "b"));
  // 0 is no size (it once meant 50 silently); the help shows one default.
  r = run_arwb("export --scene '" + kMuseum + "' --out '" + out.str("b") + "' --marker-size-mm 0");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--marker-size-mm"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out.path() / "b"));
  r = run_arwb("export --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("--calib"), std::string::npos);
  EXPECT_NE(r.out.find("the printed markers' side (1..1000; default 50)"), std::string::npos) << r.out;
  // A zip's name with a trailing '/' is a usage error, before anything is loaded.
  r = run_arwb("export --scene '" + kMuseum + "' --out '" + out.str("mz.arwb") + "/' --force");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is a zip bundle; drop the trailing '/'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out.path() / "mz.arwb"));
}

}  // namespace
