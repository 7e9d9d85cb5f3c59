// The file check every reader makes (check_input_file, open_input_file, read_text_file): the whole text or one
// message naming the file; UTF-8 text; names escaped for the terminal; YAML's depth; edit_distance and
// nearest_name for "did you mean ...?".
#include "base/files.hpp"
#include "base/text.hpp"
#include "base/yaml_depth.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

namespace arwb {
namespace {

FileLimit limit(std::uintmax_t bytes) { return FileLimit{"a test file", bytes}; }

TEST(ReadTextFile, ReadsTheWholeFileAsItIs) {
  test::TempDir dir;
  const std::string text = std::string("line 1\r\nline 2\n\xEF\xBB\xBF", 18) + std::string(200000, 'x');
  test::write_file(dir.str("a.txt"), text);
  const Result<std::string> r = read_text_file(dir.str("a.txt"), limit(1u << 20));
  ASSERT_TRUE(r) << r.error();
  EXPECT_EQ(*r, text);
  test::write_file(dir.str("empty.txt"), "");
  EXPECT_EQ(*read_text_file(dir.str("empty.txt"), limit(10)), "");
}

TEST(ReadTextFile, EachFailureNamesTheFile) {
  test::TempDir dir;
  EXPECT_EQ(read_text_file(dir.str("missing.txt"), limit(100)).error(), dir.str("missing.txt") + ": no such file");
  EXPECT_EQ(read_text_file(dir.str(), limit(100)).error(), dir.str() + ": not a regular file (a folder)");
  EXPECT_EQ(read_text_file("/dev/null", limit(100)).error(), "/dev/null: not a regular file (a character device)");
  test::write_file(dir.str("big.txt"), std::string(2049, 'x'));
  EXPECT_EQ(read_text_file(dir.str("big.txt"), limit(2048)).error(),
            dir.str("big.txt") + ": larger than 2 KiB, the limit for a test file");
  EXPECT_EQ(read_text_file(dir.str("big.txt"), limit(16u << 20)).value().size(), 2049u);
  EXPECT_EQ(read_text_file(dir.str("big.txt"), FileLimit{"a preset", 1000}).error(),
            dir.str("big.txt") + ": larger than 1000 bytes, the limit for a preset");
}

// The preset path that was /dev/zero (it grew to 13 GB) and the FIFO that hung the reader: both refused
// by name, at once, before anything is opened.
TEST(CheckInputFile, AFifoADeviceAFolderAndASocketAreRefusedByNameWithoutBlocking) {
  test::TempDir dir;
  const std::string fifo = dir.str("preset.yaml");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const FileLimit preset{"a preset", 1u << 20};
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(check_input_file(fifo, preset).error(), fifo + ": not a regular file (a FIFO)");
  EXPECT_EQ(read_text_file(fifo, preset).error(), fifo + ": not a regular file (a FIFO)");
  EXPECT_EQ(open_input_file(fifo, preset).error(), fifo + ": not a regular file (a FIFO)");
  EXPECT_EQ(read_text_file("/dev/zero", preset).error(), "/dev/zero: not a regular file (a character device)");
  EXPECT_EQ(check_input_file(dir.str(), preset).error(), dir.str() + ": not a regular file (a folder)");
  const std::string sock = dir.str("s");
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(sock.size(), sizeof addr.sun_path);
  std::memcpy(addr.sun_path, sock.c_str(), sock.size() + 1);
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0);
  EXPECT_EQ(read_text_file(sock, preset).error(), sock + ": not a regular file (a socket)");
  ::close(fd);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2)) << "nothing may wait for a writer";
  // A link is followed: a link to a FIFO is a FIFO.
  std::filesystem::create_symlink(fifo, dir.str("link.yml"));
  EXPECT_EQ(check_input_file(dir.str("link.yml"), preset).error(), dir.str("link.yml") + ": not a regular file (a FIFO)");
}

TEST(CheckInputFile, TheSizeLimitIsNamedWithItsKind) {
  test::TempDir dir;
  test::write_file(dir.str("a.yml"), std::string(3000, '#'));
  EXPECT_TRUE(check_input_file(dir.str("a.yml"), FileLimit{"a preset", 3000}));
  EXPECT_EQ(check_input_file(dir.str("a.yml"), FileLimit{"a preset", 2048}).error(),
            dir.str("a.yml") + ": larger than 2 KiB, the limit for a preset");
  std::filesystem::resize_file(dir.str("a.yml"), std::uintmax_t{3} << 30);  // sparse
  EXPECT_EQ(check_input_file(dir.str("a.yml"), FileLimit{"an image", std::uintmax_t{1} << 30}).error(),
            dir.str("a.yml") + ": larger than 1 GiB, the limit for an image");
}

TEST(OpenInputFile, ReadsWhatWasOpenedAtAnyOffset) {
  test::TempDir dir;
  test::write_file(dir.str("a.bin"), "0123456789");
  Result<InputFile> f = open_input_file(dir.str("a.bin"), limit(100));
  ASSERT_TRUE(f) << f.error();
  EXPECT_EQ(f->size(), 10u);
  char buf[8] = {};
  EXPECT_EQ(f->read_at(6, buf, sizeof buf), 4);
  EXPECT_EQ(std::string(buf, 4), "6789");
  EXPECT_EQ(f->read_at(20, buf, sizeof buf), 0);
}

// Text files must be UTF-8: a UTF-8 byte order mark is dropped; UTF-16 (either mark, or none) is named as such;
// invalid UTF-8 is refused with its line and column.
TEST(ReadTextFile, TextMustBeUtf8) {
  test::TempDir dir;
  const std::string f = dir.str("scene.xml");
  test::write_file(f, "\xEF\xBB\xBF<database/>\n");
  EXPECT_EQ(*read_text_file(f, limit(100)), "<database/>\n");
  test::write_file(f, std::string("\xFF\xFE<\0d\0b\0/\0>\0", 12));
  EXPECT_EQ(read_text_file(f, limit(100)).error(), f + ": UTF-16 text; save it as UTF-8");
  test::write_file(f, std::string("\xFE\xFF\0<\0d\0b\0/\0>", 12));
  EXPECT_EQ(read_text_file(f, limit(100)).error(), f + ": UTF-16 text; save it as UTF-8");
  test::write_file(f, std::string("<\0d\0b\0/\0>\0\n\0", 12));  // no byte order mark
  EXPECT_EQ(read_text_file(f, limit(100)).error(), f + ": UTF-16 text; save it as UTF-8");
  test::write_file(f, "-- caf\xC3\xA9\nprint('caf\xE9')\n");  // Latin-1 on line 2
  EXPECT_EQ(read_text_file(f, limit(100)).error(), f + ":2:11: not UTF-8 (byte 0xE9); save it as UTF-8");
  test::write_file(f, "ok\n\xC0\xAF");  // an overlong '/'
  EXPECT_EQ(read_text_file(f, limit(100)).error(), f + ":2:1: not UTF-8 (byte 0xC0); save it as UTF-8");
  test::write_file(f, std::string("a\0b", 3));
  EXPECT_EQ(read_text_file(f, limit(100)).error(), f + ":1:2: a NUL byte; not a text file");
  EXPECT_TRUE(check_utf8_text("\xE2\x82\xAC \xF0\x9F\x98\x80 \xED\x9F\xBF", "x"));
  EXPECT_FALSE(check_utf8_text("\xED\xA0\x80", "x")) << "a UTF-16 surrogate";
  EXPECT_FALSE(check_utf8_text("\xF4\x90\x80\x80", "x")) << "above U+10FFFF";
}

// A file of ours that could not be read goes beside the older ones, never over them; what is not a regular file
// is left where it is.
TEST(SetAside, NumbersTheNewOneAndLeavesFifosAlone) {
  test::TempDir dir;
  const std::string path = dir.str("recent.txt");
  for (const char* text : {"first", "second", "third"}) {
    test::write_file(path, text);
    const Result<std::string> to = set_aside(path);
    ASSERT_TRUE(to.ok()) << to.error();
    EXPECT_FALSE(std::filesystem::exists(path));
  }
  EXPECT_EQ(test::read_file(path + ".bad"), "first");
  EXPECT_EQ(test::read_file(path + ".bad.2"), "second");
  EXPECT_EQ(test::read_file(path + ".bad.3"), "third");

  ASSERT_EQ(::mkfifo(dir.str("fifo").c_str(), 0600), 0);
  EXPECT_EQ(set_aside(dir.str("fifo")).error(), dir.str("fifo") + ": not a regular file, left as it is");
  EXPECT_TRUE(std::filesystem::is_fifo(dir.str("fifo")));
  EXPECT_EQ(set_aside(dir.str("gone")).error(), dir.str("gone") + ": cannot be set aside (No such file or directory)");
}

// A scene named without a folder ("arwb render --scene scene.lua" in its folder) has an empty parent_path(): its
// files resolve in the current folder (render said "the scene's folder  cannot be resolved").
TEST(ResolveInside, AnEmptyFolderIsTheCurrentOne) {
  test::TempDir d;
  test::write_file(d.str("m.obj"), "v 0 0 0\n");
  const std::filesystem::path was = std::filesystem::current_path();
  std::filesystem::current_path(d.path());
  const ResolvedPath r = resolve_inside({}, "m.obj", {}, "the scene's folder");
  const ResolvedPath out = resolve_inside({}, "../m.obj", {}, "the scene's folder");
  std::filesystem::current_path(was);
  EXPECT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.path, std::filesystem::canonical(d.path() / "m.obj").string());
  EXPECT_EQ(out.error, "../m.obj: leaves the scene's folder");
}

TEST(Utf8Replaced, EachBadByteIsOneReplacementCharacterAndUtf8IsKept) {
  EXPECT_EQ(utf8_replaced("caf\xe9_plan"), "caf\xef\xbf\xbd_plan");
  EXPECT_EQ(utf8_replaced("caf\xc3\xa9 \xe2\x82\xac"), "caf\xc3\xa9 \xe2\x82\xac");
  EXPECT_EQ(utf8_replaced("\xc0\xaf"), "\xef\xbf\xbd\xef\xbf\xbd");   // an overlong '/'
  EXPECT_EQ(utf8_replaced("\xed\xa0\x80"), "\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd");   // a surrogate
  EXPECT_EQ(utf8_replaced(""), "");
}

TEST(Printable, ControlCharactersInNamesAreEscaped) {
  EXPECT_EQ(printable("museum.png"), "museum.png");
  EXPECT_EQ(printable("a\nb\rc\td"), "a\\nb\\rc\\td");
  EXPECT_EQ(printable("\x1B[31mred.png"), "\\x1B[31mred.png");
  EXPECT_EQ(printable("bell\x07 del\x7F"), "bell\\x07 del\\x7F");
  EXPECT_EQ(printable("caf\xC3\xA9 \xE2\x82\xAC"), "caf\xC3\xA9 \xE2\x82\xAC") << "UTF-8 stays";
  EXPECT_EQ(printable("\xC2\x9B" "31m"), "\\u009B31m") << "a C1 control (CSI)";
  EXPECT_EQ(printable("latin\xE9"), "latin\\xE9") << "a byte that is not UTF-8";
}

TEST(YamlDepth, FlatPresetsAndDictionariesPass) {
  EXPECT_TRUE(check_yaml_depth("%YAML:1.0\n---\nthreshold_offset: 7\n# [[[[ a comment\nname: \"[[[[\"\n", "p.yml"));
  EXPECT_TRUE(check_yaml_depth("nmarkers: 2\nmarker_0: \"0101\"\nlist: [1, [2, 3], {a: 4}]\nseq:\n  - 1\n  - 2\n", "d"));
  EXPECT_TRUE(check_yaml_depth("", "e"));
  EXPECT_TRUE(check_yaml_depth("word: a[b[c[d[e[f\n", "plain") ) << "[ inside a plain word opens nothing";
}

TEST(YamlDepth, DeepFlowAndBlockNestingIsRefusedWithTheLine) {
  EXPECT_EQ(check_yaml_depth("a: 1\nb: " + std::string(40000, '[') + "\n", "p.yml").error(),
            "p.yml:2: nested deeper than 32 levels");
  EXPECT_EQ(check_yaml_depth("a:\n  " + std::string(33, '{'), "p.yml").error(), "p.yml:2: nested deeper than 32 levels");
  EXPECT_TRUE(check_yaml_depth("a: " + std::string(31, '[') + std::string(31, ']'), "p.yml"));
  std::string dashes;
  for (int i = 0; i < 40000; ++i) dashes += "- ";
  EXPECT_EQ(check_yaml_depth("x:\n" + dashes + "1\n", "p.yml").error(), "p.yml:2: nested deeper than 32 levels");
  std::string indented;
  for (int i = 0; i < 40; ++i) indented += std::string(size_t(i), ' ') + "k" + std::to_string(i) + ":\n";
  EXPECT_EQ(check_yaml_depth(indented, "p.yml").error(), "p.yml:33: nested deeper than 32 levels");
  // Flow over several lines counts on.
  EXPECT_EQ(check_yaml_depth("a: [\n" + std::string(20, '[') + "\n" + std::string(20, '{') + "\n", "p.yml").error(),
            "p.yml:3: nested deeper than 32 levels");
}

TEST(EditDistance, CountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(edit_distance("", ""), 0);
  EXPECT_EQ(edit_distance("abc", ""), 3);
  EXPECT_EQ(edit_distance("", "abc"), 3);
  EXPECT_EQ(edit_distance("place", "place"), 0);
  EXPECT_EQ(edit_distance("plac", "place"), 1);
  EXPECT_EQ(edit_distance("pIace", "place"), 1);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3);
  EXPECT_EQ(edit_distance("otsu", "outs"), 2);
}

TEST(NearestName, OnlyATypoAway) {
  const std::vector<std::string> stages = {"otsu", "bit_grid", "contours"};
  EXPECT_EQ(nearest_name("otus", stages), "otsu");
  EXPECT_EQ(nearest_name("bitgrid", stages), "bit_grid");
  EXPECT_EQ(nearest_name("threshold", stages), "");
  const std::vector<std::string_view> fields = {"side", "place", "id"};
  EXPECT_EQ(nearest_name("sid", fields), "side");
  EXPECT_EQ(nearest_name("x", fields), "") << "a whole word replaced is no typo";
  EXPECT_EQ(nearest_name("side", fields), "side");
}

}  // namespace
}  // namespace arwb
