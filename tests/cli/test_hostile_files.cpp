// Files that once crashed or hung a reader, run as a user runs them: each is refused in one line of ours naming
// the file and the reason, with no library text and no control character from the name reaching the terminal.
#include "support/samples.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include <sys/stat.h>

using arwb::test::kSample;
using arwb::test::q;
using arwb::test::RunResult;
using arwb::test::TempDir;
using arwb::test::run_arwb;
using arwb::test::write_file;

namespace {

// stderr holds exactly `line` and a newline.
void expect_one_line(const RunResult& r, const std::string& line) {
  EXPECT_EQ(r.err, line + "\n");
}

}  // namespace

// 40,000 '[' in a preset or a dictionary overflowed the stack of OpenCV's YAML parser (a crash, signal 11).
TEST(CliHostileFiles, DeeplyNestedYamlIsRefusedWithItsLineBeforeOpenCvParsesIt) {
  TempDir dir;
  const std::string params = dir.str("deep.yml"), dict = dir.str("deep_dict.yml");
  write_file(params, "threshold_offset: 7\nx: " + std::string(40000, '[') + "\n");
  write_file(dict, "nmarkers: 1\nmarkersize: 4\nmarker_0: " + std::string(40000, '[') + "\n");
  RunResult r = run_arwb("detect --params " + q(params) + " " + q(kSample));
  EXPECT_EQ(r.status, 2);
  expect_one_line(r, "arwb detect: --params " + params + ":2: nested deeper than 32 levels");
  r = run_arwb("detect --dict " + q(dict) + " " + q(kSample));
  EXPECT_EQ(r.status, 2);
  expect_one_line(r, "arwb detect: --dict " + dict + ":3: nested deeper than 32 levels");
}

// A FIFO hung the reader (waiting for a writer) and /dev/zero grew without end: both refused by name, at once.
TEST(CliHostileFiles, AFifoOrADeviceAsAPresetOrDictionaryIsRefusedAtOnce) {
  TempDir dir;
  const std::string fifo = dir.str("preset.yml");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  RunResult r = run_arwb("detect --params " + q(fifo) + " " + q(kSample));
  EXPECT_EQ(r.status, 2);
  expect_one_line(r, "arwb detect: --params " + fifo + ": not a regular file (a FIFO)");
  r = run_arwb("detect --dict " + q(fifo) + " " + q(kSample));
  expect_one_line(r, "arwb detect: --dict " + fifo + ": not a regular file (a FIFO)");
  r = run_arwb("detect --params /dev/zero " + q(kSample));
  expect_one_line(r, "arwb detect: --params /dev/zero: not a regular file (a character device)");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(20));
}

TEST(CliHostileFiles, MalformedYamlIsOneLineOfOursWithItsLine) {
  TempDir dir;
  const std::string params = dir.str("bad.yml");
  write_file(params, "threshold_offset: 7\nx: [1 2\n");
  const RunResult r = run_arwb("detect --params " + q(params) + " " + q(kSample));
  EXPECT_EQ(r.status, 2);
  expect_one_line(r, "arwb detect: --params " + params + ":2: malformed YAML (missing , between the elements)");
  EXPECT_EQ(r.err.find("OpenCV"), std::string::npos);
}

// libpng printed "libpng error: IDAT: ..." (and warnings for valid files, "libpng warning: iCCP: ...") on the
// terminal beside our line.
TEST(CliHostileFiles, DecoderLibrariesPrintNothingOfTheirOwn) {
  TempDir dir;
  std::string png = arwb::test::read_file(kSample);
  // Flip a byte inside the first IDAT chunk's compressed data.
  const size_t idat = png.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  png[idat + 40] = static_cast<char>(png[idat + 40] ^ 0x5A);
  write_file(dir.str("crc.png"), png);
  const RunResult r = run_arwb("detect " + q(dir.str("crc.png")));
  EXPECT_EQ(r.status, 1);
  // libpng's own words for the damage, inside our one line ("IDAT: invalid bit length repeat").
  EXPECT_EQ(r.err.rfind(dir.str("crc.png") + ": corrupt or truncated image data (IDAT: ", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
  EXPECT_EQ(r.err.find("libpng"), std::string::npos) << r.err;
}

// A file name holding an escape sequence, a carriage return and a newline is printed escaped, on one line.
TEST(CliHostileFiles, ControlCharactersInFileNamesAreEscaped) {
  TempDir dir;
  const std::string name = "red\x1B[31m\rover\nwritten.png";
  write_file(dir.str(name), "not an image");
  const RunResult r = run_arwb("detect " + q(dir.str(name)));
  EXPECT_EQ(r.status, 1);
  expect_one_line(r, dir.str("red\\x1B[31m\\rover\\nwritten.png") + ": not an image (unknown signature)");
  EXPECT_EQ(r.err.find('\x1B'), std::string::npos);
  EXPECT_EQ(r.err.find('\r'), std::string::npos);
}

// A scene saved as UTF-16 (Windows' "Unicode") was sniffed as Lua and failed with a Lua syntax error; a Latin-1
// scene loaded with its bytes as they were, despite the docs saying scenes are UTF-8.
TEST(CliHostileFiles, ScenesMustBeUtf8AndUtf16IsNamed) {
  TempDir dir;
  const std::string xml = "<database><marker><id>0</id><resource>a.png</resource></marker></database>\n";
  std::string utf16 = "\xFF\xFE";
  for (char c : xml) utf16 += std::string{c, '\0'};
  write_file(dir.str("scene.xml"), utf16);
  const std::string common = " --input " + q(kSample) + " --out " + q(dir.str("out") + "/") + " --frames 1";
  RunResult r = run_arwb("render --scene " + q(dir.str("scene.xml")) + common);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("scene.xml: UTF-16 text; save it as UTF-8"), std::string::npos) << r.err;
  write_file(dir.str("scene.lua"), "-- caf\xE9\nmarker(0, {})\n");
  r = run_arwb("render --scene " + q(dir.str("scene.lua")) + common);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("scene.lua:1:7: not UTF-8 (byte 0xE9); save it as UTF-8"), std::string::npos) << r.err;
}
