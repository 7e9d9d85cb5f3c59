// The command line every subcommand shares (cli/cli_common.hpp, CLI11 underneath): values in both spellings,
// ranges checked by the validators, one-line errors naming the option and the value, help made from the
// options, and the same behaviour through the arwb binary for every subcommand.
#include "cli/cli_common.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

using namespace arwb;
using test::run_arwb;

namespace {

// Parses `args` against a small command like detect's; the exit status (nullopt: run) and stderr.
struct Parsed {
  std::optional<int> status;
  std::string err;
  int threads = 1;
  double fps = 20;
  std::string size = "640x480";
  bool json = false;
  std::vector<std::string> paths;
};

Parsed parse(std::vector<std::string> args) {
  Parsed p;
  CommandLine cl("arwb try", "Tries things.");
  cl.app.add_option("PATH", p.paths, "paths");
  cl.app.add_option("--threads", p.threads, "threads")->type_name("N")->check(whole_number(1, 64));
  cl.app.add_option("--fps", p.fps, "rate")->type_name("F")->check(real_number(0, 240));
  cl.app.add_option("--size", p.size, "size")->type_name("WxH|off")->check(frame_size({16, 16}, {8192, 8192}, "off"));
  cl.app.add_flag("--json", p.json, "json");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  testing::internal::CaptureStderr();
  p.status = cl.parse(static_cast<int>(argv.size()), argv.data());
  p.err = testing::internal::GetCapturedStderr();
  return p;
}

size_t count_lines(const std::string& s) { return static_cast<size_t>(std::count(s.begin(), s.end(), '\n')); }

TEST(CommandLine, ReadsBothSpellingsFlagsAndArguments) {
  const Parsed p = parse({"a.png", "--threads", "4", "--fps=12.5", "--json", "--size=off", "b.png"});
  EXPECT_FALSE(p.status.has_value()) << p.err;
  EXPECT_EQ(p.threads, 4);
  EXPECT_DOUBLE_EQ(p.fps, 12.5);
  EXPECT_TRUE(p.json);
  EXPECT_EQ(p.size, "off");
  EXPECT_EQ(p.paths, (std::vector<std::string>{"a.png", "b.png"}));
  EXPECT_TRUE(p.err.empty());
  // After "--" everything is an argument, even what looks like an option.
  const Parsed rest = parse({"--", "--json", "-x"});
  EXPECT_FALSE(rest.status.has_value()) << rest.err;
  EXPECT_FALSE(rest.json);
  EXPECT_EQ(rest.paths, (std::vector<std::string>{"--json", "-x"}));
}

TEST(CommandLine, RangesAreCheckedAndNamedWithTheValue) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"--threads", "0"}, "arwb try: --threads 0: expected a whole number in 1..64 (see arwb try --help)\n"},
      {{"--threads=65"}, "--threads 65: expected a whole number in 1..64"},
      {{"--threads", "2.5"}, "--threads 2.5: expected a whole number"},
      {{"--threads", "x"}, "--threads x: expected a whole number"},
      {{"--fps", "nan"}, "--fps nan: expected a number in 0..240"},
      {{"--fps", "-1"}, "--fps -1: expected a number in 0..240"},
      {{"--fps", "1e9"}, "--fps 1e9: expected a number in 0..240"},
      {{"--size", "15x480"}, "--size 15x480: expected WxH between 16x16 and 8192x8192, or off"},
      {{"--size", "640x"}, "--size 640x: expected WxH"},
      {{"--size", "640x480junk"}, "--size 640x480junk: expected WxH"},
  };
  for (const Case& c : cases) {
    const Parsed p = parse(c.args);
    EXPECT_EQ(p.status, 2) << c.args[0];
    EXPECT_NE(p.err.find(c.message), std::string::npos) << p.err;
    EXPECT_EQ(count_lines(p.err), 1u) << p.err;
  }
  // The edges of a range are inside it.
  for (const auto& args : std::vector<std::vector<std::string>>{{"--threads", "1"}, {"--threads", "64"},
                                                                {"--fps", "0"}, {"--fps", "240"},
                                                                {"--size", "16x16"}, {"--size", "8192x8192"}})
    EXPECT_FALSE(parse(args).status.has_value()) << args[0] << " " << args[1];
}

TEST(CommandLine, UnknownMissingAndRepeatedOptionsAreOneLine) {
  Parsed p = parse({"--jsn", "a.png"});
  EXPECT_EQ(p.status, 2);
  EXPECT_EQ(p.err, "arwb try: unknown option --jsn (see arwb try --help)\n");
  p = parse({"--thraeds=3"});
  EXPECT_EQ(p.status, 2);
  EXPECT_NE(p.err.find("unknown option --thraeds"), std::string::npos) << p.err;
  p = parse({"--threads"});
  EXPECT_EQ(p.status, 2);
  EXPECT_NE(p.err.find("--threads needs a value"), std::string::npos) << p.err;
  // A required option given as "" is missing.
  for (const std::string args : {"markers --out ''", "synth --out=", "render --scene '' --input synthetic --out x"}) {
    const auto r = run_arwb(args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_NE(r.err.find("needs a value"), std::string::npos) << r.err;
  }
  p = parse({"--threads", "2", "--threads", "3"});
  EXPECT_EQ(p.status, 2);
  EXPECT_NE(p.err.find("--threads is given more than once"), std::string::npos) << p.err;
}

TEST(CommandLine, HelpIsMadeFromTheOptions) {
  CommandLine cl("arwb try", "Tries things.", "A note after the options.");
  int threads = 1;
  std::string out;
  cl.app.add_option("--out", out, "where to write")->type_name("DIR")->required();
  cl.app.add_option("--threads", threads, "threads for the detector")->type_name("N")->check(whole_number(1, 64));
  const std::string help = cl.app.help();
  EXPECT_EQ(help.rfind("usage: arwb try --out DIR [options]\n", 0), 0u) << help;
  EXPECT_NE(help.find("Tries things."), std::string::npos) << help;
  EXPECT_NE(help.find("--threads N"), std::string::npos) << help;
  EXPECT_NE(help.find("threads for the detector (1..64; default 1)"), std::string::npos) << help;
  EXPECT_NE(help.find("where to write (required)"), std::string::npos) << help;
  EXPECT_NE(help.find("-h, --help"), std::string::npos) << help;
  EXPECT_NE(help.find("A note after the options."), std::string::npos) << help;
  // --help wins over a missing required option, and exits 0 with the help on stdout.
  std::string arg = "--help";
  char* argv[] = {arg.data()};
  testing::internal::CaptureStdout();
  const auto status = cl.parse(1, argv);
  const std::string printed = testing::internal::GetCapturedStdout();
  EXPECT_EQ(status, 0);
  EXPECT_EQ(printed, help);
}

TEST(CommandLine, FrameSizes) {
  EXPECT_EQ(parse_frame_size("640x480"), cv::Size(640, 480));
  for (const char* bad : {"", "x", "640", "640x", "x480", "640x480x2", "-640x480", "640 x480", "0x480", "axb"})
    EXPECT_FALSE(parse_frame_size(bad).has_value()) << bad;
}

// Every subcommand: --help exits 0 with its usage on stdout and nothing on stderr; an unknown option and a
// stray argument are one-line errors with status 2 that name them.
TEST(CommandLine, EverySubcommandHasHelpAndRejectsUnknownOptions) {
  for (const std::string cmd : {"detect", "markers", "synth", "bench", "render", "make-media"}) {
    auto r = run_arwb(cmd + " --help");
    EXPECT_EQ(r.status, 0) << cmd;
    EXPECT_EQ(r.out.rfind("usage: arwb " + cmd, 0), 0u) << r.out;
    EXPECT_NE(r.out.find("-h, --help"), std::string::npos) << r.out;
    EXPECT_TRUE(r.err.empty()) << r.err;
    r = run_arwb(cmd + " --no-such-option");
    EXPECT_EQ(r.status, 2) << cmd;
    EXPECT_EQ(r.err, "arwb " + cmd + ": unknown option --no-such-option (see arwb " + cmd + " --help)\n");
  }
  for (const std::string cmd : {"markers --out x", "synth --out x", "make-media"}) {
    const auto r = run_arwb(cmd + " stray");
    EXPECT_EQ(r.status, 2) << cmd;
    EXPECT_NE(r.err.find("unexpected argument 'stray'"), std::string::npos) << r.err;
    EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  }
}

// `arwb --help` lists the subcommands and the workbench's options, with their ranges and defaults.
TEST(CommandLine, TopLevelHelpListsSubcommandsAndWorkbenchOptions) {
  const auto r = run_arwb("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(r.err.empty()) << r.err;
  for (const char* s : {"usage: arwb [options]", "subcommands", "  detect ", "  markers ", "  synth ", "  bench ",
                        "  make-media ", "  render ", "--source synthetic|camera:N[@WxH]|PATH", "--frames N",
                        "--fps-cap F", "(0..240; default 20)", "--resize W|WxH|off", "default 640", "--actions STEPS", "Keys:"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  EXPECT_EQ(run_arwb("-h").out, r.out);
  const auto bad = run_arwb("--fps-cap 500");
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.err, "arwb: --fps-cap 500: expected a number in 0..240 (see arwb --help)\n");
}

}  // namespace

// --out of a kind the command does not write is refused naming the kinds it does, not made into a folder of that
// name; a folder with a dot in its name is still one when it exists or ends in '/'.
TEST(CommandLine, AnOutOfAnotherKindIsRefusedWithTheKindsAccepted) {
  test::TempDir d;
  struct Case {
    std::string args, expected;
  };
  const Case cases[] = {
      {"render --scene s.lua --input synthetic --out " + d.str("x.gif"),
       "arwb render: --out " + d.str("x.gif") + ": a .gif file is not written here; expected FILE.mp4, FILE.avi, "
       "FILE.mkv or a folder (a folder's name may end in '/') (see arwb render --help)\n"},
      {"markers --out " + d.str("x.txt"),
       "arwb markers: --out " + d.str("x.txt") + ": a .txt file is not written here; expected FILE.pdf, FILE.svg or "
       "a folder (a folder's name may end in '/') (see arwb markers --help)\n"},
      {"synth --out " + d.str("x.png"),
       "arwb synth: --out " + d.str("x.png") + ": a .png file is not written here; expected a folder (a folder's "
       "name may end in '/') (see arwb synth --help)\n"},
      {"export --scene s.lua --out " + d.str("x.tar"),
       "arwb export: --out " + d.str("x.tar") + ": a .tar file is not written here; expected FILE.arwb, FILE.zip or "
       "a folder (a folder's name may end in '/') (see arwb export --help)\n"}};
  for (const Case& c : cases) {
    const auto r = run_arwb(c.args);
    EXPECT_EQ(r.status, 2) << c.args;
    EXPECT_EQ(r.err, c.expected);
    EXPECT_FALSE(std::filesystem::exists(d.str("x.gif")) || std::filesystem::exists(d.str("x.txt")));
  }
  // A folder whose name has a dot: ending in '/', or existing.
  EXPECT_EQ(run_arwb("markers --ids 0-1 --out " + d.str("set.v2/")).status, 0);
  EXPECT_TRUE(std::filesystem::is_directory(d.str("set.v2")));
  EXPECT_EQ(run_arwb("markers --ids 2 --out " + d.str("set.v2")).status, 0);
  EXPECT_EQ(run_arwb("markers --ids 2 --out " + d.str("run.2026")).status, 2);
}
