// Opening bundles: one that was tampered with (media, manifest, an added or a missing file), a zip with "..",
// absolute, symbolic-link, duplicate or device entries, and zips that inflate past the limits are each refused
// naming the entry, with nothing written outside the temporary folder; the manifest's text read and written back.
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

// --- Refused bundles -----------------------------------------------------------------------------------------

struct Refusal {
  std::string error;
  std::set<std::string> parent_before, parent_after, tmp_after;
};

// Opens `bundle` and expects a refusal; what the bundle's folder and the temporary folder hold afterwards.
Refusal refuse(const fs::path& bundle, const BundleLimits& limits = {}) {
  Refusal r;
  PrivateTmp tmp;
  r.parent_before = listing(bundle.parent_path());
  Result<OpenedBundle> o = open_bundle(bundle.string(), limits);
  EXPECT_FALSE(o.ok()) << bundle;
  r.error = o.ok() ? "" : o.error();
  r.parent_after = listing(bundle.parent_path());
  r.tmp_after = tmp.contents();
  return r;
}

#define EXPECT_REFUSED(r, text)                                                                         \
  do {                                                                                                  \
    EXPECT_NE((r).error.find(text), std::string::npos) << (r).error;                                   \
    EXPECT_EQ((r).parent_before, (r).parent_after);                                                     \
    EXPECT_TRUE((r).tmp_after.empty()) << "the temporary folder was left";                             \
  } while (0)

class Tampered : public ::testing::Test {
 protected:
  void SetUp() override { export_museum(out_.path() / "museum"); }
  fs::path b() const { return out_.path() / "museum"; }
  test::TempDir out_;
};

TEST_F(Tampered, MediaChangedInPlace) {
  std::string png = read_file((b() / "scene/media/sunset.png").string());
  png[png.size() / 2] = char(png[png.size() / 2] ^ 1);   // same size
  write_file((b() / "scene/media/sunset.png").string(), png);
  EXPECT_REFUSED(refuse(b()), "scene/media/sunset.png: changed since export (SHA-256 differs)");
  write_file((b() / "scene/media/sunset.png").string(), png + "x");
  EXPECT_REFUSED(refuse(b()), "scene/media/sunset.png: changed since export (17679 bytes");
}

TEST_F(Tampered, ManifestEditedByHand) {
  const std::string text = read_file((b() / "manifest.json").string());
  // A digest edited: the file it names no longer matches.
  Result<Manifest> m = parse_manifest(text);
  ASSERT_TRUE(m.ok());
  Manifest edited = *m;
  for (BundleFile& f : edited.files)
    if (f.path == "scene/museum.lua") f.sha256 = std::string(64, '0');
  write_file((b() / "manifest.json").string(), manifest_json(edited));
  EXPECT_REFUSED(refuse(b()), "scene/museum.lua: changed since export (SHA-256 differs)");
  // A path that leaves the bundle.
  edited = *m;
  edited.files[0].path = "../outside.txt";
  write_file((b() / "manifest.json").string(), manifest_json(edited));
  EXPECT_REFUSED(refuse(b()), "manifest.json: files[0].path: \"../outside.txt\": has \"..\"");
  // Not JSON, a digest that is not hex, a newer format.
  write_file((b() / "manifest.json").string(), text.substr(0, text.size() / 2));
  EXPECT_REFUSED(refuse(b()), "manifest.json: not valid JSON");
  edited = *m;
  edited.files[2].sha256 = "xyz";
  write_file((b() / "manifest.json").string(), manifest_json(edited));
  EXPECT_REFUSED(refuse(b()), "manifest.json: files[2].sha256: not 64 lowercase hex digits");
  edited = *m;
  edited.format_version = kFormatVersion + 1;
  write_file((b() / "manifest.json").string(), manifest_json(edited));
  EXPECT_REFUSED(refuse(b()), "format_version 2: made by a newer arwb");
  fs::remove(b() / "manifest.json");
  EXPECT_REFUSED(refuse(b()), "no manifest.json");
}

TEST_F(Tampered, ManifestThatMeansSomethingArwbNeverWrites) {
  // Each hand edit keeps the manifest's syntax and every digest right, and is refused naming the field.
  const std::string text = read_file((b() / "manifest.json").string());
  Result<Manifest> m = parse_manifest(text);
  ASSERT_TRUE(m.ok()) << m.error();
  const auto refused = [&](const Manifest& edited, const std::string& expected) {
    write_file((b() / "manifest.json").string(), manifest_json(edited));
    EXPECT_REFUSED(refuse(b()), expected);
  };
  Manifest e = *m;
  e.scene = "scene/media/sunset.png";
  refused(e, "manifest.json: scene: \"scene/media/sunset.png\" is not listed as the scene (its role is \"media\")");
  e = *m;
  for (BundleFile& f : e.files)
    if (f.path == "scene/media/sunset.png") f.role = "scene";
  e.scene = "scene/media/sunset.png";
  refused(e, "manifest.json: scene: \"scene/media/sunset.png\" is not a Lua scene or an XML database");
  e = *m;
  e.calibration = "scene/media/sunset.png";
  refused(e, "manifest.json: calibration: \"scene/media/sunset.png\" is not listed as a calibration");
  for (BundleFile& f : e.files)
    if (f.path == "scene/media/sunset.png") f.role = "calibration";
  refused(e, "manifest.json: calibration: \"scene/media/sunset.png\" does not read (scene/media/sunset.png");
  e = *m;
  e.dictionary = "NOPE";
  refused(e, "manifest.json: dictionary: \"NOPE\" is not a known dictionary");
  e.dictionary = "DICT_4X4_50";
  refused(e, "manifest.json: dictionary: \"DICT_4X4_50\" is not how arwb names a dictionary (4X4_50)");
  e = *m;
  e.ids = {5000};
  refused(e, "manifest.json: ids[0]: 5000 is not a marker of ARUCO_ORIGINAL (ids 0 to 1023)");
  e.ids = {};
  refused(e, "manifest.json: ids: empty");
  e.ids = {2, 1};
  refused(e, "manifest.json: ids[1]: not in ascending order");
  // Ids and a dictionary the scene does not map (the player's synthetic source would show markers that do nothing).
  e = *m;
  e.ids.push_back(1000);
  refused(e, "manifest.json: ids: 1000 is not a marker the scene maps");
  e = *m;
  const int dropped = e.ids.back();
  e.ids.pop_back();
  refused(e, "manifest.json: ids: the scene maps " + std::to_string(dropped) + ", which is not listed");
  e = *m;
  e.dictionary = "4X4_50";
  e.ids = {0};
  refused(e, "manifest.json: dictionary: \"4X4_50\" is not the scene's (ARUCO_ORIGINAL)");
  e = *m;
  e.files[0].role = "weird";
  refused(e, "manifest.json: files[0].role: \"weird\" is not one of scene, media, calibration, sheet, readme, card");
  e = *m;
  e.self_test_passed = false;
  refused(e, "manifest.json: self_test_passed: false");
  // The original still opens.
  write_file((b() / "manifest.json").string(), text);
  PrivateTmp tmp;
  Result<OpenedBundle> o = open_bundle(b().string());
  EXPECT_TRUE(o.ok()) << o.error();
}

TEST_F(Tampered, FileAddedOrMissing) {
  write_file((b() / "scene/extra.lua").string(), "print('hi')\n");
  EXPECT_REFUSED(refuse(b()), "scene/extra.lua: not in the manifest");
  fs::remove(b() / "scene/extra.lua");
  fs::remove(b() / "scene/media/orbit.mp4");
  EXPECT_REFUSED(refuse(b()), "scene/media/orbit.mp4: missing");
}

TEST_F(Tampered, SymbolicLinkInAFolderBundle) {
  fs::remove(b() / "scene/media/sunset.png");
  fs::create_symlink("/etc/passwd", b() / "scene/media/sunset.png");
  EXPECT_REFUSED(refuse(b()), "scene/media/sunset.png: is a symbolic link");
}

TEST(ManifestText, NotJsonSaysWhere) {
  Result<Manifest> m = parse_manifest("{\n  \"a\": ,\n}\n");
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.error(), "manifest.json: not valid JSON at line 2, column 8 (byte 10)");
  m = parse_manifest("{\"title\": \"é\", x}");
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().find("at line 1, column 16"), std::string::npos) << m.error();
  // Valid syntax that nlohmann refuses as out of range (fuzz/manifest found it): refused, not thrown.
  m = parse_manifest("{\"format_version\": 9e8395}");
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.error(), "manifest.json: not valid JSON (a number too large for a double)");
}

TEST(ManifestText, RoundTrip) {
  Manifest m;
  m.title = "T";
  m.generator = "arwb 0.1.0";
  m.dictionary = "ARUCO_ORIGINAL";
  m.ids = {3, 7};
  m.marker_size_mm = 42.5;
  m.scene = "scene/s.lua";
  m.files = {{"scene/s.lua", 12, std::string(64, 'a'), "scene"}, {"cards/web-1.png", 5, std::string(64, 'b'), "card"}};
  m.self_test = {{3, 4, "image a.png", true, true, ""}, {7, 5, "callbacks only", true, true, ""}};
  m.self_test_passed = true;
  m.web_cards = {{"https://x.org", "X", "cards/web-1.png"}};
  Result<Manifest> back = parse_manifest(manifest_json(m));
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(manifest_json(*back), manifest_json(m));
  EXPECT_EQ(back->self_test[1].media, "callbacks only");
  // What it points at must be listed.
  m.scene = "scene/other.lua";
  EXPECT_EQ(parse_manifest(manifest_json(m)).error(), "manifest.json: scene: \"scene/other.lua\" is not among files");
  // Deep nesting is refused before parsing.
  EXPECT_EQ(parse_manifest(std::string(100000, '[')).error(), "manifest.json: line 1: nested deeper than 16 levels");
  // The marker size is what arwb export takes, no more (1e-300 mm made poses of 10^300 m).
  m.scene = "scene/s.lua";
  for (const double mm : {1e-300, 0.5, 1000.5, 1e300}) {
    m.marker_size_mm = mm;
    EXPECT_EQ(parse_manifest(manifest_json(m)).error(), "manifest.json: marker_size_mm: not a size of 1 to 1000 mm") << mm;
  }
  for (const double mm : {kMinMarkerSizeMm, kMaxMarkerSizeMm}) {
    m.marker_size_mm = mm;
    EXPECT_TRUE(parse_manifest(manifest_json(m)).ok()) << mm;
  }
}

// --- Hostile zips --------------------------------------------------------------------------------------------

void put16(std::string& o, unsigned v) {
  o += char(v & 0xff);
  o += char((v >> 8) & 0xff);
}
void put32(std::string& o, std::uint32_t v) {
  put16(o, v & 0xffff);
  put16(o, v >> 16);
}

struct RawEntry {
  std::string name, data;
  std::uint32_t mode = 0100644;   // the Unix mode in the external attributes
};

// A zip of stored entries written byte by byte, so its names and attributes can be anything libzip would not
// write itself (a duplicate, "..", a link).
std::string raw_zip(const std::vector<RawEntry>& entries) {
  std::string out, central;
  for (const RawEntry& e : entries) {
    const std::uint32_t offset = std::uint32_t(out.size());
    const std::uint32_t crc = test::crc32(e.data);
    put32(out, 0x04034b50);
    put16(out, 20), put16(out, 0), put16(out, 0), put16(out, 0), put16(out, 0);
    put32(out, crc), put32(out, std::uint32_t(e.data.size())), put32(out, std::uint32_t(e.data.size()));
    put16(out, unsigned(e.name.size())), put16(out, 0);
    out += e.name + e.data;
    put32(central, 0x02014b50);
    put16(central, (3 << 8) | 20), put16(central, 20), put16(central, 0), put16(central, 0);
    put16(central, 0), put16(central, 0);
    put32(central, crc), put32(central, std::uint32_t(e.data.size())), put32(central, std::uint32_t(e.data.size()));
    put16(central, unsigned(e.name.size())), put16(central, 0), put16(central, 0), put16(central, 0), put16(central, 0);
    put32(central, e.mode << 16);
    put32(central, offset);
    central += e.name;
  }
  const std::uint32_t cd_offset = std::uint32_t(out.size());
  out += central;
  put32(out, 0x06054b50);
  put16(out, 0), put16(out, 0), put16(out, unsigned(entries.size())), put16(out, unsigned(entries.size()));
  put32(out, std::uint32_t(central.size())), put32(out, cd_offset), put16(out, 0);
  return out;
}

TEST(RawZip, TheTestsOwnWriterMakesAZipThatOpens) {
  // The fixture itself: a good bundle rewritten entry by entry with raw_zip opens.
  test::TempDir out;
  const fs::path src = out.path() / "src";
  export_museum(src);
  std::vector<RawEntry> entries;
  for (const std::string& rel : listing(src))
    if (rel.back() != '/') entries.push_back({rel, read_file((src / rel).string())});
  write_file(out.str("ok.zip"), raw_zip(entries));
  PrivateTmp tmp;
  Result<OpenedBundle> o = open_bundle(out.str("ok.zip"));
  EXPECT_TRUE(o.ok()) << o.error();
}

class HostileZip : public ::testing::Test {
 protected:
  // A zip in a folder of its own (whose listing is checked), with a manifest-less but otherwise plain entry first.
  fs::path zip(const std::vector<RawEntry>& entries) {
    const fs::path dir = out_.path() / ("z" + std::to_string(n_++));
    fs::create_directory(dir);
    const fs::path p = dir / "bundle.arwb";
    std::vector<RawEntry> all{{"README.txt", "hello\n"}};
    all.insert(all.end(), entries.begin(), entries.end());
    write_file(p.string(), raw_zip(all));
    return p;
  }
  test::TempDir out_;
  int n_ = 0;
};

TEST_F(HostileZip, EntriesThatWouldLeaveTheFolderAreRefusedByName) {
  EXPECT_REFUSED(refuse(zip({{"../evil.txt", "x"}})), "entry \"../evil.txt\": has \"..\"");
  EXPECT_REFUSED(refuse(zip({{"scene/../../evil.txt", "x"}})), "entry \"scene/../../evil.txt\": has \"..\"");
  EXPECT_REFUSED(refuse(zip({{"/tmp/evil.txt", "x"}})), "entry \"/tmp/evil.txt\": absolute path");
  EXPECT_REFUSED(refuse(zip({{"scene\\..\\evil.txt", "x"}})), "backslash");
  EXPECT_REFUSED(refuse(zip({{"link", "/etc/passwd", 0120777}})), "entry \"link\": is a symbolic link");
  EXPECT_REFUSED(refuse(zip({{"dev", "", 0020644}})), "entry \"dev\": is a device");
  EXPECT_REFUSED(refuse(zip({{"fifo", "", 0010644}})), "entry \"fifo\": is not a regular file");
  EXPECT_REFUSED(refuse(zip({{"a.txt", "1"}, {"a.txt", "2"}})), "two entries have the same name");
  // Nothing landed beside the zips or in the folder above either.
  EXPECT_FALSE(fs::exists(out_.path() / "evil.txt"));
  EXPECT_FALSE(fs::exists("/tmp/evil.txt") && fs::last_write_time("/tmp/evil.txt") > fs::file_time_type::clock::now() - std::chrono::minutes(5));
}

// The manifest is read from the zip first: an entry it does not list is refused before anything is inflated (a
// 6 MB zip of unlisted entries wrote 4 GB to the temporary folder first), and a listed one as soon as it inflates
// past its size.
TEST_F(HostileZip, OnlyWhatTheManifestListsIsInflated) {
  const fs::path src = out_.path() / "museum";
  export_museum(src);
  std::vector<RawEntry> files;   // as RawZip.TheTestsOwnWriterMakesAZipThatOpens: a zip that opens
  for (const std::string& rel : listing(src))
    if (rel.back() != '/') files.push_back({rel, read_file((src / rel).string())});
  const auto zip_of = [&](const std::string& name, const std::vector<RawEntry>& entries) {
    const fs::path dir = out_.path() / name;
    fs::create_directory(dir);
    write_file((dir / "bundle.arwb").string(), raw_zip(entries));
    return dir / "bundle.arwb";
  };
  std::vector<RawEntry> extra = files;
  extra.push_back({"extra.bin", std::string(1 << 20, 'x')});
  EXPECT_REFUSED(refuse(zip_of("extra", extra)), "entry \"extra.bin\": not in the manifest");
  std::vector<RawEntry> longer = files;
  for (RawEntry& e : longer)
    if (e.name == "scene/museum.lua") e.data += std::string(1 << 20, '-');
  const std::string size = std::to_string(read_file((src / "scene/museum.lua").string()).size());
  EXPECT_REFUSED(refuse(zip_of("longer", longer)),
                 "entry \"scene/museum.lua\": inflates past its " + size + " bytes in the manifest");
}

TEST_F(HostileZip, ALongEntryNameIsCutInTheMessage) {
  // A 600-byte name would make one huge line: the message shows its start and "…".
  // Appended, not std::string + "...": GCC 12 with the precompiled header warns of a false out-of-bounds copy there.
  const std::string name = std::string(600, 'a').append("/../evil.txt");
  const Refusal r = refuse(zip({{name, "x"}}));
  EXPECT_REFUSED(r, "entry \"" + std::string(120, 'a') + "\u2026\": has \"..\"");
  EXPECT_LT(r.error.size(), 400u) << r.error;
}

TEST_F(HostileZip, NotABundleAtAll) {
  EXPECT_REFUSED(refuse(zip({})), "no manifest.json");
  const fs::path text = out_.path() / "notes.arwb";
  write_file(text.string(), "just text\n");
  EXPECT_NE(refuse(text).error.find("not a bundle (neither a folder nor a zip)"), std::string::npos);
}

// A zip made with libzip (deflated), of `files` entries of `size` bytes each: zeros (a bomb's stuff), or bytes
// that hardly compress.
fs::path libzip_zip(const fs::path& dir, const std::string& zip_name, std::uint64_t size, int files, bool zeros) {
  const fs::path p = dir / zip_name;
  int code = 0;
  zip_t* z = zip_open(p.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &code);
  EXPECT_NE(z, nullptr);
  std::string bytes(size_t(size), '\0');
  std::uint32_t x = 12345;
  if (!zeros)
    for (char& c : bytes) c = char((x = x * 1103515245u + 12345u) >> 24);
  for (int i = 0; i < files; ++i) {
    zip_source_t* s = zip_source_buffer(z, bytes.data(), bytes.size(), 0);
    const std::string name = (zeros ? "zeros-" : "data-") + std::to_string(i) + ".bin";
    const zip_int64_t idx = zip_file_add(z, name.c_str(), s, 0);
    EXPECT_GE(idx, 0);
    zip_set_file_compression(z, zip_uint64_t(idx), ZIP_CM_DEFLATE, 9);
  }
  EXPECT_EQ(zip_close(z), 0);
  return p;
}

TEST_F(HostileZip, ABombIsRefusedOnTheBytesReallyInflated) {
  // A zip without a manifest is refused before anything is inflated; the limits below are extract_zip's, which
  // hold for the files a manifest lists too.
  const fs::path dir = out_.path() / "bomb";
  fs::create_directory(dir);
  // 64 MiB of zeros deflate to about 64 KiB: the default limits refuse its ratio as soon as it passes 1000,
  // whatever the entry declares.
  const fs::path bomb = libzip_zip(dir, "bomb.zip", 64ull << 20, 1, true);
  EXPECT_LT(fs::file_size(bomb), 100u << 10);
  EXPECT_REFUSED(refuse(bomb), "no manifest.json");
  const auto extract_refuses = [&](const fs::path& zip, const BundleLimits& l, const std::string& text) {
    test::TempDir into;
    const Status s = extract_zip(zip, into.path(), {l.max_entries, l.max_file_bytes, l.max_total_bytes, l.max_ratio});
    EXPECT_NE(s.ok() ? std::string::npos : s.error().find(text), std::string::npos) << (s.ok() ? "extracted" : s.error());
  };
  extract_refuses(bomb, {}, "entry \"zeros-0.bin\": inflates more than 1000 times its compressed size");
  // Lowered limits: one file's size, all files' size, the count of entries.
  const fs::path small = libzip_zip(dir, "small.zip", 2u << 20, 3, false);
  BundleLimits l;
  l.max_file_bytes = 1u << 20;
  extract_refuses(small, l, "entry \"data-0.bin\": inflates past 1048576 bytes");
  l = {};
  l.max_total_bytes = 5u << 20;
  extract_refuses(small, l, "entry \"data-2.bin\": the bundle inflates past 5242880 bytes");
  l = {};
  l.max_ratio = 100;
  const fs::path zeros = libzip_zip(dir, "zeros.zip", 1u << 20, 1, true);
  extract_refuses(zeros, l, "entry \"zeros-0.bin\": inflates more than 100 times");
  l = {};
  l.max_entries = 2;
  EXPECT_REFUSED(refuse(small, l), "3 entries, more than the limit of 2");
}

}  // namespace
}  // namespace arwb::bundle
