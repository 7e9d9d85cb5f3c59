// The shipped example scenes load without a single error and place media on the synthetic source's markers, and
// make-media paints the files they use.
#include "capture/image_io.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

namespace arwb {
namespace {

namespace fs = std::filesystem;
using test::run_arwb;
using test::TempDir;

TEST(Examples, EveryShippedSceneRendersWithoutErrors) {
  const fs::path scripts = fs::path(ARWB_SOURCE_DIR) / "scripts";
  int scenes = 0;
  for (const auto& dir : fs::directory_iterator(scripts)) {
    if (!dir.is_directory()) continue;
    for (const auto& f : fs::directory_iterator(dir.path())) {
      const std::string ext = f.path().extension().string();
      if (ext != ".lua" && ext != ".xml") continue;
      ++scenes;
      TempDir out;
      const auto r = run_arwb("render --scene '" + f.path().string() + "' --input synthetic --frames 30 --out '" +
                              out.str("frames") + "'");
      EXPECT_EQ(r.status, 0) << f.path() << "\n" << r.err;
      // Scene errors and warnings go to stderr; an example has none.
      EXPECT_EQ(r.err, "") << f.path();
      std::smatch m;
      ASSERT_TRUE(std::regex_search(r.out, m, std::regex("([0-9]+) overlays drawn"))) << r.out;
      EXPECT_GE(std::stoi(m[1]), 30) << f.path() << ": fewer than one overlay per frame";
    }
  }
  EXPECT_GE(scenes, 6);   // museum (lua, xml), lab, classroom, links (lua, xml)
}

TEST(Examples, MakeMediaPaintsTheFilesTheScenesUse) {
  TempDir d;
  auto r = run_arwb("make-media --out '" + d.str() + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* png : {"museum/media/composition.png", "museum/media/sunset.png", "lab/media/flask.png"}) {
    const LoadedImage img = load_image(d.str(png), -1);
    EXPECT_TRUE(img.ok()) << img.error;
  }
  EXPECT_EQ(classify_path(d.str("museum/media/orbit.mp4")), PathKind::video);
  // A second run keeps what is there.
  r = run_arwb("make-media --out '" + d.str() + "'");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("0 written, 4 kept"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace arwb
