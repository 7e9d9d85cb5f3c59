// Loading a scene file (Lua or the paper's XML database), reloading it when it changes, and the console its
// messages go to.
#include "base/files.hpp"
#include "script/scene_runtime_impl.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>

namespace arwb::script {
namespace {

// Lua compiles a scene with no hook running (about 0.1 s a megabyte): scenes are a few kilobytes.
constexpr FileLimit kSceneFile{"a scene", kMaxChunkBytes};
constexpr size_t kMaxConsoleText = 4000;
constexpr size_t kCollapseWindow = 8;   // warnings and errors repeat within this many lines: counted, not repeated

FileSig file_sig(const std::string& path) {
  FileSig s;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return s;
  s.exists = true;
  s.mtime_ns = static_cast<long long>(st.st_mtim.tv_sec) * 1'000'000'000LL + st.st_mtim.tv_nsec;
  s.size = static_cast<long long>(st.st_size);
  s.inode = static_cast<long long>(st.st_ino);
  return s;
}

// A database is XML: its first character (after a byte-order mark and spaces) is '<', which no Lua chunk
// starts with.
bool looks_like_xml(const std::string& text) {
  size_t i = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
  while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\n' || text[i] == '\r')) ++i;
  return i < text.size() && text[i] == '<';
}

// The line in "display:LINE: message", or 0.
int line_of(const std::string& msg, const std::string& display) {
  if (msg.rfind(display + ":", 0) != 0) return 0;
  size_t i = display.size() + 1;
  int line = 0;
  bool digits = false;
  while (i < msg.size() && msg[i] >= '0' && msg[i] <= '9' && line < 100'000'000) {
    line = line * 10 + (msg[i++] - '0');
    digits = true;
  }
  return digits && i < msg.size() && msg[i] == ':' ? line : 0;
}

}  // namespace

std::string mib(std::size_t bytes) {
  char b[32];
  std::snprintf(b, sizeof b, "%g MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return b;
}

// [SECTION] Console

void SceneRuntime::Impl::report(int level, const std::string& text_in) {
  std::string text = text_in.size() > kMaxConsoleText ? text_in.substr(0, kMaxConsoleText) + "..." : text_in;
  auto& c = status.console;
  // Print output collapses only when the same line comes again right away; warnings and errors also when
  // they alternate with a few others (two markers failing on every frame), and the line moves to the end.
  const size_t window = std::min(level == 0 ? size_t(1) : kCollapseWindow, c.size());
  for (size_t k = 0; k < window; ++k) {
    auto it = c.end() - 1 - static_cast<std::ptrdiff_t>(k);
    if (it->level == level && it->text == text) {
      ConsoleLine line = std::move(*it);
      ++line.repeats;
      c.erase(it);
      c.push_back(std::move(line));
      ++status.console_serial;
      return;
    }
  }
  if (level == 2 && logged_errors.size() <= kMaxLoggedErrors && logged_errors.insert(text).second) {
    fresh_errors.push_back(logged_errors.size() <= kMaxLoggedErrors
                               ? text
                               : "the scene reports more errors; the Scene panel's console lists them");
  }
  c.push_back({level, std::move(text), 1});
  const size_t keep = static_cast<size_t>(std::max(1, limits.console_lines));
  if (c.size() > keep) c.erase(c.begin(), c.end() - static_cast<std::ptrdiff_t>(keep));
  ++status.console_serial;
}

// [SECTION] Loading

bool SceneRuntime::Impl::fail_load(const std::string& msg, int line) {
  // With no good scene yet, the file in question is still the one to show and edit.
  if (!prog) status.file = attempt_path;
  status.error = msg;
  status.error_line = line;
  report(2, msg);
  // The load error reaches the log through status().error, once.
  if (!fresh_errors.empty() && fresh_errors.back() == msg) fresh_errors.pop_back();
  return false;
}

bool SceneRuntime::Impl::load(const std::string& path) {
  logged_errors.clear();   // a new attempt's errors are news again
  attempted = true;
  attempt_path = path;
  attempt_sig = file_sig(path);
  const std::string display = chunk_display_name(path);
  const Result<std::string> read = read_text_file(path, kSceneFile);
  // The message starts with the path; the console names scenes by their display name. UTF-16 and invalid UTF-8
  // are refused there, by name and line, before the text is sniffed as XML or Lua.
  if (!read) {
    const std::string msg = display + read.error().substr(path.size());
    return fail_load(msg, line_of(msg, display));
  }
  const std::string& text = *read;

  auto p = std::make_unique<Program>();
  p->path = path;
  p->display = display;
  std::string msg;
  int line = 0;
  const bool ok = looks_like_xml(text) ? load_xml(*p, text, &msg, &line) : load_lua(*p, text, &msg, &line);
  if (!ok) return fail_load(msg, line);

  p->mapping_error.assign(p->def.mappings.size(), std::string());
  p->event_error.assign(p->def.mappings.size(), std::string());
  prog = std::move(p);   // the old scene (its Lua state, players and overrides) goes only now
  store.trim();
  status.file = path;
  status.dictionary = prog->def.dictionary;
  status.ok = true;
  status.error.clear();
  status.error_line = 0;
  ++status.generation;
  fill_rows(nullptr);
  return true;
}

bool SceneRuntime::Impl::load_lua(Program& p, const std::string& text, std::string* msg, int* line) {
  try {
    p.lua = std::make_unique<LuaState>(limits, this, p.path);
  } catch (const std::exception& e) {
    *msg = p.display + ": " + e.what();
    return false;
  }
  lua_State* L = p.lua->L();
  Host& h = p.lua->host();
  open_scene_api(L);
  LuaState::Outcome out = p.lua->load_chunk(text);
  if (out.ok) {
    h.building = &p.def;
    p.lua->begin_frame();
    out = p.lua->pcall(0, 0);
    h.building = nullptr;
    report_suppressed(p);
    if (!out.ok && (out.budget || out.time)) {
      if (out.message.rfind(p.display + ":", 0) != 0) out.message = p.display + ": " + out.message;
      out.message += " while loading the scene";
    }
  }
  if (out.ok) return true;
  if (out.memory)
    out.message = p.display + ": not enough memory while loading the scene (the cap is " +
                  mib(limits.memory_bytes) + ")";
  else if (line_of(out.message, p.display) == 0 && out.message.rfind(p.display + ":", 0) != 0)
    out.message = p.display + ": " + out.message;
  *msg = out.message;
  *line = line_of(out.message, p.display);
  return false;
}

bool SceneRuntime::Impl::load_xml(Program& p, const std::string& text, std::string* msg, int* line) {
  std::filesystem::path dir = std::filesystem::path(p.path).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  const std::filesystem::path abs = std::filesystem::absolute(dir, ec);
  const Status st = load_database(p.display, text, ec ? dir : abs, &p.def, *this);
  if (!st) *msg = st.error(), *line = line_of(st.error(), p.display);
  return st.ok();
}

bool SceneRuntime::Impl::reload_if_changed() {
  if (!attempted) return false;
  if (file_sig(attempt_path) == attempt_sig) return false;
  load(attempt_path);
  return true;
}

void SceneRuntime::Impl::unload() {
  prog.reset();
  store.trim();
  attempted = false;
  status.file.clear();
  status.dictionary.clear();
  status.ok = false;
  status.mappings.clear();
}

}  // namespace arwb::script
