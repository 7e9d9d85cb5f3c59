// Exports: an example scene exported to a folder and to a zip opens from elsewhere with the original gone, its
// manifest listing every file with the right digest; exports that must not happen (a missing media file, an id out
// of range, a scene that does not load, a mapping that does not fire) write nothing; replacing and naming the out.
#include "bundle_fixture.hpp"

#include "bundle/bundle.hpp"
#include "bundle/bundle_files.hpp"

#include "calibration/calibration_file.hpp"
#include "support/png.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <zip.h>

#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <set>

namespace arwb::bundle {
namespace {

using namespace fixture;
using arwb::test::read_file;
using arwb::test::write_file;

TEST(Sha256, KnownDigests) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(BundlePath, RefusesWhatCouldLeaveTheFolder) {
  EXPECT_EQ(bundle_path_problem("scene/media/a.png"), "");
  EXPECT_NE(bundle_path_problem(""), "");
  EXPECT_NE(bundle_path_problem("/etc/passwd"), "");
  EXPECT_NE(bundle_path_problem("../x"), "");
  EXPECT_NE(bundle_path_problem("a/../../x"), "");
  EXPECT_NE(bundle_path_problem("a/./x"), "");
  EXPECT_NE(bundle_path_problem("a//x"), "");
  EXPECT_NE(bundle_path_problem("a\\..\\x"), "");
  EXPECT_NE(bundle_path_problem("C:x"), "");
  EXPECT_NE(bundle_path_problem(std::string("a\0b", 3)), "");
}

TEST(Export, MuseumToAFolderOpensElsewhereWithTheOriginalRemoved) {
  test::TempDir out;
  export_museum(out.path() / "museum");
  const fs::path b = out.path() / "museum";
  EXPECT_EQ(listing(b), (std::set<std::string>{"README.txt", "manifest.json", "markers.pdf", "scene/", "scene/media/",
                                                "scene/media/composition.png", "scene/media/orbit.mp4",
                                                "scene/media/sunset.png", "scene/museum.lua"}));
  // The manifest lists every file but itself, with its size and digest.
  Result<Manifest> m = parse_manifest(read_file((b / "manifest.json").string()));
  ASSERT_TRUE(m.ok()) << m.error();
  EXPECT_EQ(m->format_version, kFormatVersion);
  EXPECT_EQ(m->title, "museum");
  EXPECT_EQ(m->dictionary, "ARUCO_ORIGINAL");
  EXPECT_EQ(m->ids, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(m->marker_size_mm, 50);
  EXPECT_EQ(m->scene, "scene/museum.lua");
  EXPECT_EQ(m->calibration, "");
  ASSERT_EQ(m->files.size(), 6u);
  for (const BundleFile& f : m->files) {
    const std::string bytes = read_file((b / f.path).string());
    EXPECT_EQ(f.size, bytes.size()) << f.path;
    EXPECT_EQ(f.sha256, sha256_hex(bytes)) << f.path;
  }
  // The media are the originals, byte for byte.
  EXPECT_EQ(read_file((b / "scene/media/sunset.png").string()),
            read_file((kScripts / "museum/media/sunset.png").string()));
  // The self-test: each (id, mapping) fired; 3 ids x (own media, caption, counter).
  EXPECT_TRUE(m->self_test_passed);
  ASSERT_EQ(m->self_test.size(), 9u);
  for (const SelfTestRow& r : m->self_test) EXPECT_TRUE(r.detected && r.fired) << r.id << " " << r.detail;
  EXPECT_EQ(m->self_test[0].id, 0);
  EXPECT_EQ(m->self_test[0].mapping_line, 13);
  EXPECT_EQ(m->self_test[0].media, "image media/composition.png");
  const std::string readme = read_file((b / "README.txt").string());
  EXPECT_NE(readme.find("arwb play museum"), std::string::npos);
  EXPECT_NE(readme.find("100 %"), std::string::npos);
  EXPECT_EQ(read_file((b / "markers.pdf").string()).rfind("%PDF", 0), 0u);

  // Opened from elsewhere: a private copy, verified.
  PrivateTmp tmp;
  fs::path opened_dir;
  {
    Result<OpenedBundle> o = open_bundle(b.string());
    ASSERT_TRUE(o.ok()) << o.error();
    opened_dir = o->dir();
    EXPECT_NE(opened_dir.string().find(tmp.contents().begin()->substr(0, 10)), std::string::npos);
    EXPECT_EQ(fs::status(opened_dir).permissions() & fs::perms::all, fs::perms::owner_all);
    EXPECT_EQ(o->manifest().ids, m->ids);
    EXPECT_EQ(o->scene_path(), (opened_dir / "scene/museum.lua").string());
    EXPECT_EQ(o->calibration_path(), "");
    fs::remove_all(b);   // the original goes: the copy is what plays
    EXPECT_EQ(read_file(o->scene_path()), read_file((kScripts / "museum/museum.lua").string()));
    // Moved, the folder goes with the new owner.
    OpenedBundle moved = std::move(*o);
    EXPECT_EQ(moved.dir(), opened_dir);
    EXPECT_TRUE(fs::exists(opened_dir));
  }
  EXPECT_FALSE(fs::exists(opened_dir));
  EXPECT_TRUE(tmp.contents().empty());
}

TEST(Export, MuseumToAZipOpensElsewhere) {
  test::TempDir out;
  const fs::path zip = out.path() / "museum.arwb";
  export_museum(zip);
  ASSERT_TRUE(fs::is_regular_file(zip));
  EXPECT_EQ(listing(out.path()), (std::set<std::string>{"museum.arwb"}));   // no temporary sibling left
  // Entries with their paths, regular files only.
  int code = 0;
  zip_t* z = zip_open(zip.c_str(), ZIP_RDONLY, &code);
  ASSERT_NE(z, nullptr);
  std::set<std::string> names;
  for (zip_int64_t i = 0; i < zip_get_num_entries(z, 0); ++i) {
    names.insert(zip_get_name(z, zip_uint64_t(i), 0));
    zip_uint8_t opsys = 0;
    zip_uint32_t attr = 0;
    ASSERT_EQ(zip_file_get_external_attributes(z, zip_uint64_t(i), 0, &opsys, &attr), 0);
    EXPECT_EQ(opsys, ZIP_OPSYS_UNIX);
    EXPECT_TRUE(S_ISREG(attr >> 16));
    // Pictures and videos stored as they are (compressed already); text deflated.
    zip_stat_t st;
    ASSERT_EQ(zip_stat_index(z, zip_uint64_t(i), 0, &st), 0);
    const std::string name = st.name;
    const bool packed = name.size() > 4 && (name.substr(name.size() - 4) == ".png" || name.substr(name.size() - 4) == ".mp4");
    EXPECT_EQ(st.comp_method, packed ? ZIP_CM_STORE : ZIP_CM_DEFLATE) << name;
  }
  zip_discard(z);
  EXPECT_EQ(names, (std::set<std::string>{"README.txt", "manifest.json", "markers.pdf", "scene/media/composition.png",
                                          "scene/media/orbit.mp4", "scene/media/sunset.png", "scene/museum.lua"}));
  // Recognised by its bytes, not its name.
  const fs::path renamed = out.path() / "museum.data";
  fs::rename(zip, renamed);
  PrivateTmp tmp;
  {
    Result<OpenedBundle> o = open_bundle(renamed.string());
    ASSERT_TRUE(o.ok()) << o.error();
    fs::remove(renamed);
    EXPECT_EQ(listing(o->dir()), (std::set<std::string>{"README.txt", "manifest.json", "markers.pdf", "scene/",
                                                         "scene/media/", "scene/media/composition.png",
                                                         "scene/media/orbit.mp4", "scene/media/sunset.png",
                                                         "scene/museum.lua"}));
    EXPECT_EQ(read_file((o->dir() / "scene/media/orbit.mp4").string()),
              read_file((kScripts / "museum/media/orbit.mp4").string()));
    // The copy runs on its own: its scene loads and passes the same self-test where it lies now.
    ExportOptions again;
    again.scene = o->scene_path();
    again.out = out.str("again");
    Result<ExportPlan> plan = plan_export(again);
    ASSERT_TRUE(plan.ok()) << plan.error();
    EXPECT_EQ(plan->manifest.self_test.size(), 9u);
    EXPECT_FALSE(fs::exists(out.path() / "again"));   // a plan writes nothing
  }
  EXPECT_TRUE(tmp.contents().empty());
}

TEST(Export, EveryFileAModelReadsAndTheWebCards) {
  test::TempDir out;
  ASSERT_TRUE(export_to(kScripts / "models/models.lua", out.path() / "m").ok());
  Result<Manifest> m = parse_manifest(read_file(out.str("m/manifest.json")));
  ASSERT_TRUE(m.ok()) << m.error();
  std::set<std::string> paths;
  for (const BundleFile& f : m->files) paths.insert(f.path);
  // house.obj reads house.mtl: the model's own references come along.
  EXPECT_TRUE(paths.count("scene/house.obj"));
  EXPECT_TRUE(paths.count("scene/house.mtl"));
  EXPECT_TRUE(paths.count("scene/marker_post.gltf"));
  EXPECT_FALSE(paths.count("scene/make_gltf.py"));   // in the folder, but the scene never reads it

  ASSERT_TRUE(export_to(kScripts / "links/links.lua", out.path() / "l.zip").ok());
  PrivateTmp tmp;
  Result<OpenedBundle> o = open_bundle(out.str("l.zip"));
  ASSERT_TRUE(o.ok()) << o.error();
  ASSERT_EQ(o->manifest().web_cards.size(), 3u);
  EXPECT_EQ(o->manifest().web_cards[0].url, "https://opencv.org");
  EXPECT_EQ(o->manifest().web_cards[0].title, "OpenCV");
  EXPECT_EQ(o->manifest().web_cards[0].picture, "cards/web-1.png");
  EXPECT_EQ(read_file((o->dir() / "cards/web-1.png").string()).substr(1, 3), "PNG");
}

TEST(Export, ACubesFaceImagesAndTheXmlDatabasesMedia) {
  test::TempDir out;
  const fs::path dir = copy_example("museum", out.path());
  write_file((dir / "cube.lua").string(),
             "marker(4, { media = cube { size = 0.5, faces = { top = 'media/sunset.png', left = '#ff0000' } } })\n");
  Status s = export_to(dir / "cube.lua", out.path() / "cube");
  ASSERT_TRUE(s.ok()) << s.error();
  EXPECT_EQ(listing(out.path() / "cube").count("scene/media/sunset.png"), 1u);
  EXPECT_EQ(listing(out.path() / "cube").count("scene/media/composition.png"), 0u);
  s = export_to(dir / "museum.xml", out.path() / "xml");
  ASSERT_TRUE(s.ok()) << s.error();
  Result<Manifest> m = parse_manifest(read_file(out.str("xml/manifest.json")));
  ASSERT_TRUE(m.ok()) << m.error();
  EXPECT_EQ(m->scene, "scene/museum.xml");
  std::set<std::string> media;
  for (const BundleFile& f : m->files)
    if (f.role == "media") media.insert(f.path);
  EXPECT_EQ(media, (std::set<std::string>{"scene/media/composition.png", "scene/media/orbit.mp4",
                                          "scene/media/sunset.png"}));
  for (const SelfTestRow& r : m->self_test) EXPECT_GT(r.mapping_line, 0) << r.id;   // the database's rows
}

TEST(Export, CalibrationIsCopiedAndReadsBack) {
  test::TempDir out;
  Calibration c;
  c.camera_matrix = cv::Matx33d(500, 0, 160, 0, 500, 120, 0, 0, 1);
  c.distortion = {0.01, -0.02, 0, 0, 0};
  c.image_size = {320, 240};
  ASSERT_TRUE(write_calibration(out.str("cam.yml"), c, {}).ok());
  ASSERT_TRUE(export_to(kScripts / "museum/museum.lua", out.path() / "b", out.str("cam.yml")).ok());
  EXPECT_EQ(read_file(out.str("b/calibration.yml")), read_file(out.str("cam.yml")));
  PrivateTmp tmp;
  Result<OpenedBundle> o = open_bundle(out.str("b"));
  ASSERT_TRUE(o.ok()) << o.error();
  EXPECT_EQ(o->manifest().calibration, "calibration.yml");
  Result<Calibration> back = read_calibration(o->calibration_path());
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back->camera_matrix(0, 0), 500);

  // A calibration that does not read is refused, naming it.
  write_file(out.str("bad.yml"), "%YAML:1.0\nnothing: 1\n");
  const Status s = export_to(kScripts / "museum/museum.lua", out.path() / "b2", out.str("bad.yml"));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("bad.yml"), std::string::npos) << s.error();
  EXPECT_FALSE(fs::exists(out.path() / "b2"));
}

TEST(Export, ThePapersCalibrationPairKeepsItsNames) {
  // The paper's cameraMatrix.xml reads only with distCoeffs.xml beside it: both go in under those names.
  test::TempDir out;
  const fs::path corpus = fs::path(ARWB_SOURCE_DIR) / "fuzz/corpus/calibration";
  fs::create_directory(out.path() / "paper");
  fs::copy_file(corpus / "paper_cameraMatrix.xml", out.path() / "paper/cameraMatrix.xml");
  fs::copy_file(corpus / "paper_distCoeffs.xml", out.path() / "paper/distCoeffs.xml");
  const Status s = export_to(kScripts / "museum/museum.lua", out.path() / "paper.arwb", out.str("paper/cameraMatrix.xml"));
  ASSERT_TRUE(s.ok()) << s.error();
  PrivateTmp tmp;
  Result<OpenedBundle> o = open_bundle(out.str("paper.arwb"));
  ASSERT_TRUE(o.ok()) << o.error();
  EXPECT_EQ(o->manifest().calibration, "cameraMatrix.xml");
  std::set<std::string> calibration_files;
  for (const BundleFile& f : o->manifest().files)
    if (f.role == "calibration") calibration_files.insert(f.path);
  EXPECT_EQ(calibration_files, (std::set<std::string>{"cameraMatrix.xml", "distCoeffs.xml"}));
  Result<Calibration> back = read_calibration(o->calibration_path());
  ASSERT_TRUE(back.ok()) << back.error();
  Result<Calibration> original = read_calibration(out.str("paper/cameraMatrix.xml"));
  ASSERT_TRUE(original.ok()) << original.error();
  EXPECT_EQ(back->camera_matrix, original->camera_matrix);
  EXPECT_EQ(back->distortion, original->distortion);
}

TEST(Export, A16By9CalibrationPassesTheSelfTest) {
  // The self-test's frame takes the calibration's shape: a 1280x720 camera is not refused as "made for 16:9".
  test::TempDir out;
  Calibration c;
  c.camera_matrix = cv::Matx33d(1000, 0, 640, 0, 1000, 360, 0, 0, 1);
  c.distortion = {0.01, -0.02, 0, 0, 0};
  c.image_size = {1280, 720};
  ASSERT_TRUE(write_calibration(out.str("hd720.yml"), c, {}).ok());
  ExportOptions o;
  o.scene = (kScripts / "museum/museum.lua").string();
  o.out = out.str("hd.arwb");
  o.calibration = out.str("hd720.yml");
  Result<ExportPlan> plan = plan_export(o);
  ASSERT_TRUE(plan.ok()) << plan.error();
  EXPECT_TRUE(plan->manifest.self_test_passed);
  EXPECT_EQ(plan->manifest.calibration, "calibration.yml");
  // A calibration of a very wide strip still passes, at its own size.
  c.camera_matrix = cv::Matx33d(800, 0, 1000, 0, 800, 150, 0, 0, 1);
  c.image_size = {2000, 300};
  ASSERT_TRUE(write_calibration(out.str("strip.yml"), c, {}).ok());
  o.calibration = out.str("strip.yml");
  plan = plan_export(o);
  ASSERT_TRUE(plan.ok()) << plan.error();
}

// --- Exports that must not happen ----------------------------------------------------------------------------

class ExportRefused : public ::testing::Test {
 protected:
  // Writes the scene into a copy of the museum and exports it; the error, and checks that nothing was written.
  // The copy of the museum the scenes are written into.
  fs::path src() {
    const fs::path dir = out_.path() / "src";
    if (!fs::exists(dir)) copy_example("museum", out_.path()), fs::rename(out_.path() / "museum", dir);
    return dir;
  }
  std::string export_scene(const std::string& lua) {
    const fs::path dir = src();
    write_file((dir / "scene.lua").string(), lua);
    const std::set<std::string> before = listing(out_.path());
    const Status s = export_to(dir / "scene.lua", out_.path() / "out.arwb");
    EXPECT_FALSE(s.ok());
    EXPECT_EQ(listing(out_.path()), before) << "something was written";
    return s.error();
  }
  test::TempDir out_;
};

TEST_F(ExportRefused, AMissingMediaFile) {
  const std::string e = export_scene("marker(3, { media = image 'media/gone.png' })\n");
  EXPECT_NE(e.find("scene.lua:1:"), std::string::npos) << e;
  EXPECT_NE(e.find("media/gone.png: no such file"), std::string::npos) << e;
  EXPECT_EQ(e.rfind("cannot export: ", 0), 0u) << e;
  EXPECT_EQ(e.find("skipped"), std::string::npos) << e;
}

TEST_F(ExportRefused, ADatabaseRowThatDoesNotLoadStopsTheExport) {
  const fs::path dir = src();
  write_file((dir / "db.xml").string(),
             "<database dictionary=\"ARUCO_ORIGINAL\">\n"
             "  <row><id>1</id><resource>media/sunset.png</resource></row>\n"
             "  <row><id>2</id><resource>media/gone.png</resource></row>\n"
             "</database>\n");
  const Status s = export_to(dir / "db.xml", out_.path() / "out.arwb");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().rfind("cannot export: ", 0), 0u) << s.error();
  EXPECT_NE(s.error().find("media/gone.png"), std::string::npos) << s.error();
  EXPECT_EQ(s.error().find("row skipped"), std::string::npos) << s.error();
  EXPECT_FALSE(fs::exists(out_.path() / "out.arwb"));
}

TEST_F(ExportRefused, AMediaFileOutsideTheScenesFolder) {
  write_file(out_.str("outside.png"), read_file((kScripts / "museum/media/sunset.png").string()));
  fs::create_symlink(out_.path() / "outside.png", src() / "media/link.png");
  const std::string e = export_scene("marker(3, { media = image 'media/link.png' })\n");
  EXPECT_NE(e.find("media/link.png: leaves the scene's folder"), std::string::npos) << e;
}

TEST_F(ExportRefused, AnIdOutOfRange) {
  const std::string e = export_scene("marker(5000, { media = image 'media/sunset.png' })\n");
  EXPECT_NE(e.find("5000"), std::string::npos) << e;
  EXPECT_NE(e.find("scene.lua:1"), std::string::npos) << e;
}

TEST_F(ExportRefused, ASceneThatDoesNotLoad) {
  const std::string e = export_scene("marker(1, { media = image 'media/sunset.png' }\n");
  EXPECT_NE(e.find("scene.lua:"), std::string::npos) << e;
}

TEST_F(ExportRefused, AMappingThatDoesNotFire) {
  const std::string e = export_scene(
      "marker(1, { media = image 'media/sunset.png' })\n"
      "marker(4, { on_enter = function(m) error('broken exhibit') end })\n");
  EXPECT_NE(e.find("marker 4 does not fire"), std::string::npos) << e;
  EXPECT_NE(e.find("scene.lua:2"), std::string::npos) << e;
  EXPECT_NE(e.find("broken exhibit"), std::string::npos) << e;
}

TEST_F(ExportRefused, ASceneThatMapsNothing) {
  EXPECT_NE(export_scene("-- empty\n").find("maps no marker"), std::string::npos);
}

// --- Writing -------------------------------------------------------------------------------------------------

TEST(ExportWrite, AnExistingOutIsReplacedOnlyWithForceAndOnlyWhenABundle) {
  test::TempDir out;
  const fs::path scene = kScripts / "museum/museum.lua";
  ASSERT_TRUE(export_to(scene, out.path() / "b").ok());
  Status s = export_to(scene, out.path() / "b");
  EXPECT_NE(s.error().find("exists; add --force"), std::string::npos) << s.error();
  s = export_to(scene, out.path() / "b", "", true);
  EXPECT_TRUE(s.ok()) << s.error();
  EXPECT_EQ(listing(out.path()).count("b/manifest.json"), 1u);
  // A user's file put into the bundle's folder: not ours to delete.
  write_file(out.str("b/notes.txt"), "mine\n");
  s = export_to(scene, out.path() / "b", "", true);
  EXPECT_NE(s.error().find("holds notes.txt, which is not part of its bundle"), std::string::npos) << s.error();
  EXPECT_EQ(read_file(out.str("b/notes.txt")), "mine\n");
  // A folder or file that is no bundle at all.
  fs::create_directory(out.path() / "photos");
  write_file(out.str("photos/a.jpg"), "x");
  s = export_to(scene, out.path() / "photos", "", true);
  EXPECT_NE(s.error().find("not a bundle"), std::string::npos) << s.error();
  EXPECT_TRUE(fs::exists(out.path() / "photos/a.jpg"));
  write_file(out.str("report.zip"), "not a zip");
  s = export_to(scene, out.path() / "report.zip", "", true);
  EXPECT_NE(s.error().find("not a zip"), std::string::npos) << s.error();
  EXPECT_EQ(read_file(out.str("report.zip")), "not a zip");
  // A plain file where a folder bundle was asked for.
  write_file(out.str("existing.txt"), "notes\n");
  s = export_to(scene, out.path() / "existing.txt", "", true);
  EXPECT_NE(s.error().find("existing.txt is a file, not a bundle folder; not replacing it"), std::string::npos)
      << s.error();
  EXPECT_EQ(read_file(out.str("existing.txt")), "notes\n");
  // A zip bundle replaced by another.
  ASSERT_TRUE(export_to(scene, out.path() / "z.arwb").ok());
  ASSERT_TRUE(export_to(kScripts / "links/links.lua", out.path() / "z.arwb", "", true).ok());
  PrivateTmp tmp;
  Result<OpenedBundle> o = open_bundle(out.str("z.arwb"));
  ASSERT_TRUE(o.ok()) << o.error();
  EXPECT_EQ(o->manifest().title, "links");
  // No temporary sibling is left anywhere.
  for (const std::string& name : listing(out.path())) EXPECT_EQ(name.find(".partial"), std::string::npos) << name;
}

TEST(ExportWrite, AFolderNamedWithATrailingSlash) {
  test::TempDir out;
  const Status s = export_to(kScripts / "museum/museum.lua", out.str("museum/"));
  ASSERT_TRUE(s.ok()) << s.error();
  EXPECT_TRUE(fs::is_regular_file(out.path() / "museum/manifest.json"));
  EXPECT_EQ(listing(out.path()).size(), listing(out.path() / "museum").size() + 1);   // nothing else beside it
  EXPECT_NE(read_file(out.str("museum/README.txt")).find("arwb play museum\n"), std::string::npos);
}

TEST(ExportWrite, AZipsNameWithATrailingSlashIsRefused) {
  // "mz.arwb/" with --force once replaced the zip mz.arwb with a folder of that name.
  test::TempDir out;
  const fs::path scene = kScripts / "museum/museum.lua";
  ASSERT_TRUE(export_to(scene, out.path() / "mz.arwb").ok());
  const std::string zip = read_file(out.str("mz.arwb"));
  for (const std::string& name : {std::string("mz.arwb/"), std::string("mz.arwb//"), std::string("MZ.ZIP/")}) {
    const Status s = export_to(scene, out.str(name), "", true);
    ASSERT_FALSE(s.ok()) << name;
    EXPECT_NE(s.error().find("--out " + out.str(name) + ": a name ending in "), std::string::npos) << s.error();
    EXPECT_NE(s.error().find("is a zip bundle; drop the trailing '/'"), std::string::npos) << s.error();
  }
  EXPECT_TRUE(fs::is_regular_file(out.path() / "mz.arwb"));
  EXPECT_EQ(read_file(out.str("mz.arwb")), zip);
  EXPECT_FALSE(fs::exists(out.path() / "MZ.ZIP"));
  EXPECT_EQ(out_name_problem(out.str("mz.arwb")), "");
  EXPECT_EQ(out_name_problem(out.str("folder/")), "");
  // ".arwb" alone was written as a folder of that name.
  EXPECT_EQ(out_name_problem(out.str(".arwb")), "the bundle has no name before .arwb (write NAME.arwb)");
  EXPECT_EQ(out_name_problem(".ZIP"), "the bundle has no name before .ZIP (write NAME.ZIP)");
  EXPECT_FALSE(export_to(scene, out.str(".arwb")).ok());
  EXPECT_FALSE(fs::exists(out.path() / ".arwb"));
}

TEST(ExportReadme, UnderlineCountsCharactersAndThePlayLineIsShellQuoted) {
  test::TempDir out;
  ExportOptions o;
  o.scene = (kScripts / "museum/museum.lua").string();
  o.out = out.str("Salle d'expo.arwb");
  o.title = "Musée Ω";   // 7 characters, 10 bytes
  Result<ExportPlan> plan = plan_export(o);
  ASSERT_TRUE(plan.ok()) << plan.error();
  std::string readme;
  for (const auto& [path, bytes] : plan->generated)
    if (path == "README.txt") readme = bytes;
  EXPECT_EQ(readme.rfind("Musée Ω\n=======\n\n", 0), 0u) << readme;
  EXPECT_NE(readme.find("arwb play 'Salle d'\\''expo.arwb'\n"), std::string::npos) << readme;
  o.out = out.str("plain-name_1.arwb");
  plan = plan_export(o);
  ASSERT_TRUE(plan.ok()) << plan.error();
  for (const auto& [path, bytes] : plan->generated) {
    if (path == "README.txt") {
      EXPECT_NE(bytes.find("arwb play plain-name_1.arwb\n"), std::string::npos) << bytes;
    }
  }
}

TEST(ExportReadme, ATitleWithControlCharactersOrTooLongIsRefused) {
  test::TempDir out;
  ExportOptions o;
  o.scene = (kScripts / "museum/museum.lua").string();
  o.out = out.str("b.arwb");
  for (const std::string& title : {std::string("two\nlines"), std::string("a\ttab"), std::string("esc\x1b[31m")}) {
    o.title = title;
    Result<ExportPlan> plan = plan_export(o);
    ASSERT_FALSE(plan.ok()) << title;
    EXPECT_EQ(plan.error().rfind("--title ", 0), 0u) << plan.error();
    EXPECT_NE(plan.error().find("has a control character"), std::string::npos) << plan.error();
  }
  o.title = std::string(200, 'x');
  EXPECT_TRUE(plan_export(o).ok());
  o.title = std::string(201, 'x');
  Result<ExportPlan> plan = plan_export(o);
  ASSERT_FALSE(plan.ok());
  EXPECT_NE(plan.error().find("longer than 200 characters"), std::string::npos) << plan.error();
  EXPECT_LT(plan.error().size(), 200u) << plan.error();
  // 200 two-byte characters are 200 characters.
  std::string wide;
  for (int i = 0; i < 200; ++i) wide += "é";
  o.title = wide;
  EXPECT_TRUE(plan_export(o).ok());
  EXPECT_FALSE(fs::exists(out.path() / "b.arwb"));
}

TEST(ExportWrite, ASourceChangedAfterThePlanIsNamedAndNothingIsWritten) {
  test::TempDir out;
  const fs::path dir = copy_example("museum", out.path());
  ExportOptions o;
  o.scene = (dir / "museum.lua").string();
  o.out = out.str("b.arwb");
  Result<ExportPlan> plan = plan_export(o);
  ASSERT_TRUE(plan.ok()) << plan.error();
  write_file((dir / "media/sunset.png").string(), "changed");
  const Status s = write_export(*plan);
  EXPECT_NE(s.error().find("sunset.png: changed since it was checked"), std::string::npos) << s.error();
  EXPECT_FALSE(fs::exists(out.path() / "b.arwb"));
}

// --web: the phone player's site (DataDirs::web) goes in whole, each file listed with role "web", and the bundle
// still opens for arwb play; a site without its page, service worker or core is named and nothing is written.
TEST(ExportWeb, TheSiteGoesInWithItsOwnRoleAndTheBundleStillOpens) {
  test::TempDir src, out;
  const fs::path dir = copy_example("museum", src.path());
  const fs::path site = src.path() / "site";
  for (const char* f : {"index.html", "sw.js", "web/player.js", "web/arwb_core.wasm", "web/licenses/opencv.txt"}) {
    fs::create_directories((site / f).parent_path());
    arwb::test::write_file((site / f).string(), std::string("the bytes of ") + f);
  }
  ExportOptions o;
  o.scene = (dir / "museum.lua").string();
  o.out = (out.path() / "museum").string();
  o.web_site = site.string();
  Result<ExportPlan> plan = plan_export(o);
  ASSERT_TRUE(plan.ok()) << plan.error();
  ASSERT_TRUE(write_export(*plan).ok());
  Result<Manifest> m = parse_manifest(read_file((out.path() / "museum/manifest.json").string()));
  ASSERT_TRUE(m.ok()) << m.error();
  std::set<std::string> web;
  for (const BundleFile& f : m->files) {
    EXPECT_EQ(f.role == "web", is_web_path(f.path)) << f.path << " " << f.role;
    if (f.role == "web") web.insert(f.path);
    EXPECT_EQ(f.sha256, sha256_hex(read_file((out.path() / "museum" / f.path).string()))) << f.path;
  }
  EXPECT_EQ(web, (std::set<std::string>{"index.html", "sw.js", "web/arwb_core.wasm", "web/licenses/opencv.txt",
                                       "web/player.js"}));
  PrivateTmp tmp;
  Result<OpenedBundle> opened = open_bundle((out.path() / "museum").string());
  EXPECT_TRUE(opened.ok()) << opened.error();

  // Without its service worker the site is refused, by name, and nothing is written.
  fs::remove(site / "sw.js");
  o.out = (out.path() / "second").string();
  Result<ExportPlan> refused = plan_export(o);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().find("--web: the phone player's sw.js is missing from " + site.string()), std::string::npos)
      << refused.error();
  EXPECT_FALSE(fs::exists(out.path() / "second"));
}

}  // namespace
}  // namespace arwb::bundle
