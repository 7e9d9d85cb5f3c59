// The docs' commands, run: every fenced block of README.md and docs/*.md whose info string's first word is `sh` is
// one test, so the docs cannot drift from the program. The second word of the info string says how (GitHub shows
// the first word only, so `sh display` renders as sh):
//   sh          run with /bin/sh -e, without a display;
//   sh display  the same under xvfb-run -a -s "-screen 0 1600x900x24": it opens a window, so its arwb commands must
//               end by themselves (--frames N, --screenshot);
//   sh camera   needs a real camera: not run (the test is skipped), but it fails unless a comment line in the block
//               says why it needs a camera;
//   sh build    the set-up, build and test commands, which build the tree a test runs in: not run; each command
//               line must be a line of .ci/run (the README's test command is exactly what CI runs), or that line's
//               set-up and build with another last step (the README's run command: `... && build/arwb`).
// Any other marker, and a block in `bash` or `shell`, fails its test.
//
// A block runs in a fresh scratch folder where build/arwb is the arwb under test and the source tree's top-level
// entries (assets, scripts, docs, packaging, third_party, ...) are symbolic links, so the documented relative paths
// work and whatever the commands write lands in the scratch folder. HOME is a folder of its own, so the window's
// layout and settings of the person running the tests are neither read nor changed. A block fails when it exits
// non-zero, runs longer than kTimeoutSeconds, or changes a file of the source tree through those links.
//
// It needs nothing of the project but the arwb binary: no target is linked, and its few helpers are its own.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace {

namespace fs = std::filesystem;

// A fresh empty folder under the system's temporary folder, removed with everything in it when the object goes.
class TempDir {
 public:
  TempDir() {
    std::string name = (fs::temp_directory_path() / "arwb_docs_XXXXXX").string();
    if (!mkdtemp(name.data())) throw std::runtime_error("mkdtemp failed under " + fs::temp_directory_path().string());
    path_ = name;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  std::string str(const std::string& name = "") const { return name.empty() ? path_.string() : (path_ / name).string(); }

 private:
  fs::path path_;
};

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f << bytes;
}

// docs/detector-history.md is the detector's diary, moved from the README as it was written: its commands are the
// record of what was measured then (some took minutes), not instructions that must still run.
const std::vector<std::string> kNotChecked = {"docs/detector-history.md"};
// The longest a block may run (the sanitizer tree is a few times slower than Release); the docs keep theirs to
// seconds.
constexpr int kTimeoutSeconds = 300;
const char* kScreen = "-screen 0 1600x900x24";

enum class Kind { plain, display, camera, build, bad };

struct Block {
  std::string file;    // relative to the source tree: README.md, docs/lab.md
  int index = 0;       // which of the file's shell blocks, from 1: the test's name, which edits elsewhere keep
  int line = 0;        // the opening fence's line, from 1
  std::string info;    // the fence's info string
  std::string text;    // the block's lines, without the fence's indentation
  Kind kind = Kind::bad;
  std::string problem;  // why the block is bad
};

// How gtest prints a block (in --gtest_list_tests, which ctest reads, and in failures): where it is.
void PrintTo(const Block& b, std::ostream* os) { *os << b.file << ":" << b.line; }

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> w;
  for (std::string x; in >> x;) w.push_back(x);
  return w;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

// The command lines of a block: neither blank nor a comment.
std::vector<std::string> commands_of(const Block& b) {
  std::vector<std::string> out;
  for (const auto& l : lines_of(b.text)) {
    const std::string t = trim(l);
    if (!t.empty() && t[0] != '#') out.push_back(t);
  }
  return out;
}

void classify(Block& b) {
  const auto w = words(b.info);
  if (w.empty() || w[0] != "sh") {
    b.problem = "a `" + (w.empty() ? b.info : w[0]) + "` block: write `sh` (with a marker if needed) so that it is run";
    return;
  }
  const std::string marker = w.size() > 1 ? w[1] : "";
  if (w.size() > 2) {
    b.problem = "one marker at most after `sh`, found `" + b.info + "`";
  } else if (marker.empty()) {
    b.kind = Kind::plain;
  } else if (marker == "display") {
    b.kind = Kind::display;
  } else if (marker == "camera") {
    b.kind = Kind::camera;
  } else if (marker == "build") {
    b.kind = Kind::build;
  } else {
    b.problem = "unknown marker `" + marker + "` (sh, sh display, sh camera, sh build)";
  }
  if (b.kind != Kind::bad && commands_of(b).empty()) {
    b.kind = Kind::bad;
    b.problem = "a block without a command";
  }
}

// The fenced blocks of one Markdown file whose info string starts with sh (or names another shell), as CommonMark
// reads fences: ``` or ~~~, three or more, indented by up to three spaces (deeper inside list items), closed by the
// same character at least as many times.
std::vector<Block> shell_blocks_of(const std::string& rel) {
  std::vector<Block> blocks;
  const auto lines = lines_of(read_file((fs::path(ARWB_SOURCE_DIR) / rel).string()));
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string& l = lines[i];
    const size_t indent = l.find_first_not_of(' ');
    if (indent == std::string::npos || (l[indent] != '`' && l[indent] != '~')) continue;
    const char fence_char = l[indent];
    size_t run = 0;
    while (indent + run < l.size() && l[indent + run] == fence_char) ++run;
    if (run < 3) continue;
    const std::string info = trim(l.substr(indent + run));
    size_t close = i + 1;
    for (; close < lines.size(); ++close) {
      const std::string t = trim(lines[close]);
      if (t.size() >= run && t.find_first_not_of(fence_char) == std::string::npos) break;
    }
    const auto w = words(info);
    const std::string lang = w.empty() ? "" : w[0];
    if (lang == "sh" || lang == "bash" || lang == "shell" || lang == "zsh") {
      Block b;
      b.file = rel;
      b.index = static_cast<int>(blocks.size()) + 1;
      b.line = static_cast<int>(i) + 1;
      b.info = info;
      for (size_t k = i + 1; k < close && k < lines.size(); ++k) {
        const std::string& c = lines[k];
        const size_t strip = std::min(indent, c.find_first_not_of(' ') == std::string::npos ? c.size()
                                                                                             : c.find_first_not_of(' '));
        b.text += c.substr(strip) + "\n";
      }
      classify(b);
      if (close >= lines.size()) {
        b.kind = Kind::bad;
        b.problem = "the block is never closed";
      }
      blocks.push_back(b);
    }
    i = close;
  }
  return blocks;
}

std::vector<std::string> doc_files() {
  std::vector<std::string> files = {"README.md"};
  std::vector<std::string> docs;
  const fs::path dir = fs::path(ARWB_SOURCE_DIR) / "docs";
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".md") docs.push_back("docs/" + e.path().filename().string());
  std::sort(docs.begin(), docs.end());
  for (const auto& d : docs)
    if (std::find(kNotChecked.begin(), kNotChecked.end(), d) == kNotChecked.end()) files.push_back(d);
  return files;
}

const std::vector<Block>& all_blocks() {
  static const std::vector<Block> blocks = [] {
    std::vector<Block> all;
    for (const auto& f : doc_files())
      for (auto& b : shell_blocks_of(f)) all.push_back(std::move(b));
    return all;
  }();
  return blocks;
}

// Blocks that open a window (Window/...): the display blocks, and any block that starts xvfb-run itself. Each gets
// an X server of its own (xvfb-run -a), as the window tests do.
bool needs_x(const Block& b) { return b.kind == Kind::display || b.text.find("xvfb-run") != std::string::npos; }

std::vector<Block> blocks_where(bool x) {
  std::vector<Block> out;
  for (const auto& b : all_blocks())
    if (needs_x(b) == x) out.push_back(b);
  return out;
}

std::string test_name(const testing::TestParamInfo<Block>& info) {
  std::string n;
  for (char c : info.param.file) n += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return n + "_" + std::to_string(info.param.index);
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The last lines of an output, for a failure's message.
std::string tail(const std::string& text, size_t n = 40) {
  const auto lines = lines_of(text);
  std::string out;
  for (size_t i = lines.size() > n ? lines.size() - n : 0; i < lines.size(); ++i) out += "  " + lines[i] + "\n";
  return out;
}

// The source tree's top-level entries a block sees: all but hidden ones (.git, .ci) and build trees (build*, or any
// folder holding a CMakeCache.txt), which a block has its own build/ in place of.
std::vector<fs::path> linked_entries() {
  std::vector<fs::path> entries;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(ARWB_SOURCE_DIR)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name[0] == '.' || name.rfind("build", 0) == 0) continue;
    if (fs::exists(e.path() / "CMakeCache.txt", ec)) continue;
    entries.push_back(e.path());
  }
  return entries;
}

// The scratch folder a block runs in: build/arwb, build/web (the WebAssembly core) and links to the source tree's
// top-level entries.
std::unique_ptr<TempDir> make_scratch() {
  auto dir = std::make_unique<TempDir>();
  fs::create_directories(dir->path() / "build");
  fs::create_symlink(ARWB_BINARY, dir->path() / "build" / "arwb");
  fs::create_symlink(fs::path(ARWB_BINARY).parent_path() / "web", dir->path() / "build" / "web");
  for (const auto& e : linked_entries()) fs::create_symlink(e, dir->path() / e.filename());
  return dir;
}

// What a block could change through the links: every file of the source tree's top-level entries but the code
// folders, which no documented command writes into and which someone may be editing while the tests run.
std::map<std::string, std::pair<uintmax_t, fs::file_time_type>> source_files() {
  std::map<std::string, std::pair<uintmax_t, fs::file_time_type>> files;
  std::error_code ec;
  for (const auto& e : linked_entries()) {
    const std::string name = e.filename().string();
    if (name == "src" || name == "ui" || name == "tests" || name == "web") continue;
    auto note = [&](const fs::path& p) {
      if (fs::is_regular_file(fs::symlink_status(p, ec)))
        files[fs::relative(p, ARWB_SOURCE_DIR).string()] = {fs::file_size(p, ec), fs::last_write_time(p, ec)};
    };
    note(e);
    if (fs::is_directory(fs::symlink_status(e, ec)))
      for (auto it = fs::recursive_directory_iterator(e, ec); it != fs::recursive_directory_iterator();
           it.increment(ec))
        note(it->path());
  }
  return files;
}

struct Ran {
  int status = -1;
  std::string out, err;
};

Ran run(const Block& b) {
  Ran r;
  for (int attempt = 0; attempt < 3; ++attempt) {
    TempDir logs;
    auto scratch = make_scratch();
    fs::create_directories(logs.path() / "home");
    write_file(logs.str("block.sh"), b.text);
    const std::string shell = "timeout -k 10 " + std::to_string(kTimeoutSeconds) + " /bin/sh -e " +
                              shell_quote(logs.str("block.sh"));
    // A plain block gets no display: one that opens a window fails rather than opening it on the screen of the
    // person running the tests.
    std::string cmd = "cd " + shell_quote(scratch->str()) + " && env -u WAYLAND_DISPLAY -u XDG_CONFIG_HOME " +
                      (b.kind == Kind::display ? "" : "-u DISPLAY ") + "HOME=" + shell_quote(logs.str("home")) + " ";
    if (b.kind == Kind::display) cmd += "xvfb-run -a -s " + shell_quote(kScreen) + " ";
    cmd += shell;
    cmd += " >" + shell_quote(logs.str("out")) + " 2>" + shell_quote(logs.str("err")) + " </dev/null";
    const int raw = std::system(cmd.c_str());
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw);
    r.out = read_file(logs.str("out"));
    r.err = read_file(logs.str("err"));
    // xvfb-run can lose a race with Xvfb's reset when the last window closes and exit 5 with this line instead of
    // the block's status (tests/support.cpp says more): that run said nothing about the block, so it runs again.
    const bool xvfb_cleanup = b.kind == Kind::display && r.status == 5 &&
                              r.err.find("xvfb-run: error: problem while cleaning up") != std::string::npos;
    if (!xvfb_cleanup) break;
  }
  return r;
}

class DocBlock : public testing::TestWithParam<Block> {};

TEST_P(DocBlock, Runs) {
  const Block& b = GetParam();
  const std::string where = b.file + ":" + std::to_string(b.line) + " (```" + b.info + ")";
  switch (b.kind) {
    case Kind::bad:
      FAIL() << where << ": " << b.problem << "\n" << b.text;
    case Kind::camera: {
      bool says_why = false;
      for (const auto& l : lines_of(b.text)) {
        const std::string t = trim(l);
        says_why = says_why || (!t.empty() && t[0] == '#' && t.find("camera") != std::string::npos);
      }
      ASSERT_TRUE(says_why) << where << ": a `sh camera` block is not run; a comment line in it must say why it "
                            << "needs a camera\n" << b.text;
      GTEST_SKIP() << where << " needs a camera: not run";
    }
    case Kind::build: {
      const std::string ci_path = (fs::path(ARWB_SOURCE_DIR) / ".ci" / "run").string();
      std::vector<std::string> ci;
      for (const auto& l : lines_of(read_file(ci_path))) ci.push_back(trim(l));
      ASSERT_FALSE(ci.empty()) << ci_path << " is missing or empty";
      for (const auto& c : commands_of(b)) {
        bool found = std::find(ci.begin(), ci.end(), c) != ci.end();
        for (const auto& line : ci) {
          const auto last = line.rfind(" && ");
          if (last != std::string::npos && c.size() > last + 4 && c.compare(0, last + 4, line, 0, last + 4) == 0)
            found = true;   // the same set-up and build as a line of CI's, and another last step
        }
        EXPECT_TRUE(found) << where << ": this command is not what .ci/run runs (nor its set-up and build with "
                           << "another last step):\n  " << c << "\n.ci/run:\n" << tail(read_file(ci_path), 100);
      }
      return;
    }
    case Kind::plain:
    case Kind::display: {
      const auto before = source_files();
      const Ran r = run(b);
      EXPECT_EQ(r.status, 0) << where << " exited " << r.status
                             << (r.status == 124 ? " (ran longer than " + std::to_string(kTimeoutSeconds) + " s)" : "")
                             << "\n" << b.text << "stdout (the end):\n" << tail(r.out) << "stderr (the end):\n"
                             << tail(r.err);
      const auto after = source_files();
      for (const auto& [path, stat] : after) {
        const auto it = before.find(path);
        EXPECT_TRUE(it != before.end() && it->second == stat)
            << where << " " << (it == before.end() ? "made" : "changed") << " " << path
            << " in the source tree (a command wrote through the scratch folder's link): write into the scratch "
            << "folder instead";
      }
      return;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Shell, DocBlock, testing::ValuesIn(blocks_where(false)), test_name);
INSTANTIATE_TEST_SUITE_P(Window, DocBlock, testing::ValuesIn(blocks_where(true)), test_name);

TEST(DocCommands, FindsTheDocsAndTheirBlocks) {
  ASSERT_TRUE(fs::is_regular_file(fs::path(ARWB_SOURCE_DIR) / "README.md")) << ARWB_SOURCE_DIR;
  EXPECT_GT(doc_files().size(), 5u);
  int build = 0, runnable = 0;
  for (const auto& b : all_blocks()) {
    build += b.kind == Kind::build;
    runnable += b.kind == Kind::plain || b.kind == Kind::display;
  }
  EXPECT_GE(build, 1) << "README.md's quick start is a `sh build` block";
  EXPECT_GE(runnable, 10);
}

}  // namespace
