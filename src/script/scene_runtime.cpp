#include "script/scene_runtime.hpp"

#include "media/media_store.hpp"
#include "script/scene_model.hpp"

#include <opencv2/imgproc.hpp>

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace arwb::script {
namespace {

constexpr std::uintmax_t kMaxSceneBytes = 16u << 20;
constexpr size_t kMaxConsoleText = 4000;
constexpr size_t kCollapseWindow = 8;   // warnings and errors repeat within this many lines: counted, not repeated

// A stage picture of the current frame as media.
class StageContent : public MediaContent {
 public:
  StageContent(std::shared_ptr<const cv::Mat> image, uint64_t version) : image_(std::move(image)), version_(version) {}
  cv::Size size() const override { return image_->size(); }
  std::shared_ptr<const cv::Mat> current(uint64_t* version) const override {
    if (version) *version = version_;
    return image_;
  }

 private:
  std::shared_ptr<const cv::Mat> image_;
  uint64_t version_;
};

// The frame's stage picture as BGR or BGRA. Colour views are shared, not copied: each Frame draws its views into
// fresh buffers and never touches them after it is published.
std::shared_ptr<MediaContent> make_stage_content(const cv::Mat& view, uint64_t version) {
  if (view.empty() || view.depth() != CV_8U) return nullptr;
  auto m = std::make_shared<cv::Mat>();
  if (view.channels() == 1) cv::cvtColor(view, *m, cv::COLOR_GRAY2BGR);
  else if (view.channels() == 3 || view.channels() == 4) *m = view;
  else return nullptr;
  return std::make_shared<StageContent>(std::move(m), version);
}

// One (mapping, marker id): what its callbacks changed and what it shows.
struct Instance {
  bool media_set = false;      // a callback's return replaced the media
  MediaSpec media;
  int text_fn = LUA_NOREF;     // the replacing media's computed-text function
  bool place_set = false;
  PlaceSpec place;
  std::string content_key;     // image and web content, loaded once per key
  std::shared_ptr<MediaContent> content;
  std::string video_key;       // this instance's own video player
  std::shared_ptr<media::VideoContent> video;
  double position = 0;         // seconds into the video: grows while the marker is tracked
  bool inside = false;
  bool fresh = false;          // entered on this frame (no dt to add yet)
  std::string error;           // this frame's problem, for the Scene panel
};

struct Program {
  std::unique_ptr<LuaState> lua;   // null for an XML database
  SceneDef def;
  std::string path, display;
  std::map<std::pair<int, int>, Instance> instances;   // (mapping, id)
  std::set<int> disabled;                              // functions stopped by the budget or the memory cap
  std::vector<std::string> mapping_error;              // per mapping: why part of it is disabled
  std::set<int> inside;                                // ids entered and not left
  std::map<int, TrackedMarker> last;                   // their last tracks (for on_leave)
  bool stage_note = false;                             // "no stage pictures" was said
};

struct FileSig {
  bool exists = false;
  long long mtime_ns = 0, size = 0, inode = 0;
  bool operator==(const FileSig&) const = default;
};

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

bool read_text(const std::string& path, std::string* out, std::string* error) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) {
    *error = "no such file";
    return false;
  }
  if (!std::filesystem::is_regular_file(st)) {
    *error = "not a regular file";
    return false;
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > kMaxSceneBytes) {
    *error = "larger than 16 MiB";
    return false;
  }
  std::ifstream f(path, std::ios::binary);
  if (!f) {
    *error = "cannot be read";
    return false;
  }
  std::ostringstream ss;
  ss << f.rdbuf();
  *out = ss.str();
  return true;
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

std::string upper_dict(std::string s) {
  for (char& c : s) c = static_cast<char>((c >= 'a' && c <= 'z') ? c - 32 : c);
  if (s.rfind("DICT_", 0) == 0) s = s.substr(5);
  return s;
}

std::string fmt1(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", v);
  return b;
}

std::string mib(std::size_t bytes) {
  char b[32];
  std::snprintf(b, sizeof b, "%g MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return b;
}

// The Scene panel shows a mapping's name where MappingRow has a field for it.
template <class Row>
void set_row_name(Row& row, const std::string& name) {
  if constexpr (requires { row.name = name; }) row.name = name;
  else if (!name.empty()) row.ids += " (" + name + ")";
}

void push_marker(lua_State* L, const TrackedMarker& t, const std::string& dict, bool held) {
  lua_createtable(L, 0, 8);
  lua_pushinteger(L, t.id);
  lua_setfield(L, -2, "id");
  lua_pushlstring(L, dict.data(), dict.size());
  lua_setfield(L, -2, "dict");
  lua_createtable(L, 4, 0);
  for (int k = 0; k < 4; ++k) {
    lua_createtable(L, 0, 2);
    lua_pushnumber(L, t.corners[static_cast<size_t>(k)].x);
    lua_setfield(L, -2, "x");
    lua_pushnumber(L, t.corners[static_cast<size_t>(k)].y);
    lua_setfield(L, -2, "y");
    lua_rawseti(L, -2, k + 1);
  }
  lua_setfield(L, -2, "corners");
  lua_createtable(L, 0, 2);
  lua_pushnumber(L, t.centre.x);
  lua_setfield(L, -2, "x");
  lua_pushnumber(L, t.centre.y);
  lua_setfield(L, -2, "y");
  lua_setfield(L, -2, "centre");
  lua_pushnumber(L, t.side_px);
  lua_setfield(L, -2, "side");
  lua_pushnumber(L, t.visible_s);
  lua_setfield(L, -2, "seconds");
  lua_pushboolean(L, held);
  lua_setfield(L, -2, "held");
}

}  // namespace

struct SceneRuntime::Impl : Reporter {
  Impl(media::MediaStore& s, ScriptLimits l) : store(s), limits(l) {}
  ~Impl() override { prog.reset(); }

  media::MediaStore& store;
  ScriptLimits limits;
  SceneStatus status;
  std::unique_ptr<Program> prog;
  bool attempted = false;
  std::string attempt_path;
  FileSig attempt_sig;
  double frame_ms = 0;

  // ---- console -------------------------------------------------------------------------------------------------

  void report(int level, const std::string& text_in) override {
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
    c.push_back({level, std::move(text), 1});
    const size_t keep = static_cast<size_t>(std::max(1, limits.console_lines));
    if (c.size() > keep) c.erase(c.begin(), c.end() - static_cast<std::ptrdiff_t>(keep));
    ++status.console_serial;
  }

  // ---- loading -------------------------------------------------------------------------------------------------

  bool fail_load(const std::string& msg, int line) {
    // With no good scene yet, the file in question is still the one to show and edit.
    if (!prog) status.file = attempt_path;
    status.error = msg;
    status.error_line = line;
    report(2, msg);
    return false;
  }

  bool load(const std::string& path) {
    attempted = true;
    attempt_path = path;
    attempt_sig = file_sig(path);
    const std::string display = chunk_display_name(path);
    std::string text, err;
    if (!read_text(path, &text, &err)) return fail_load(display + ": " + err, 0);

    auto p = std::make_unique<Program>();
    p->path = path;
    p->display = display;
    std::string msg;
    int line = 0;
    const bool ok = looks_like_xml(text) ? load_xml(*p, text, &msg, &line) : load_lua(*p, text, &msg, &line);
    if (!ok) return fail_load(msg, line);

    p->mapping_error.assign(p->def.mappings.size(), std::string());
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

  bool load_lua(Program& p, const std::string& text, std::string* msg, int* line) {
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
      out = p.lua->pcall(0, 0);
      h.building = nullptr;
      if (!out.ok && out.budget) out.message += " while loading the scene";
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

  bool load_xml(Program& p, const std::string& text, std::string* msg, int* line) {
    std::filesystem::path dir = std::filesystem::path(p.path).parent_path();
    if (dir.empty()) dir = ".";
    std::error_code ec;
    const std::filesystem::path abs = std::filesystem::absolute(dir, ec);
    const Status st = load_database(p.display, text, ec ? dir : abs, &p.def, *this);
    if (!st) *msg = st.error(), *line = line_of(st.error(), p.display);
    return st.ok();
  }

  bool reload_if_changed() {
    if (!attempted) return false;
    if (file_sig(attempt_path) == attempt_sig) return false;
    load(attempt_path);
    return true;
  }

  void unload() {
    prog.reset();
    store.trim();
    attempted = false;
    status.file.clear();
    status.dictionary.clear();
    status.ok = false;
    status.mappings.clear();
  }

  // ---- calling Lua ---------------------------------------------------------------------------------------------

  std::string dict_of(const Program& p, const TrackedMarker& t) const { return t.dict.empty() ? p.def.dict_name : t.dict; }

  // "scene.lua:LINE: " for a function: where it was defined.
  std::string function_prefix(Program& p, int fn) {
    lua_State* L = p.lua->L();
    lua_rawgeti(L, LUA_REGISTRYINDEX, fn);
    lua_Debug ar;
    lua_getinfo(L, ">S", &ar);
    return p.display + ":" + std::to_string(std::max(0, ar.linedefined)) + ": ";
  }

  // Calls function `fn` with m [, dt]. True with its one result on the stack when it ran; false (reported, and
  // the function disabled when it ran out of budget or memory) when it failed.
  bool call(Program& p, int mi, int fn, const TrackedMarker& t, bool held, const double* dt, const std::string& what,
            Instance* inst) {
    if (fn == LUA_NOREF || p.disabled.count(fn)) return false;
    LuaState& ls = *p.lua;
    lua_State* L = ls.L();
    lua_checkstack(L, 8);
    lua_rawgeti(L, LUA_REGISTRYINDEX, fn);
    push_marker(L, t, dict_of(p, t), held);
    int nargs = 1;
    if (dt) {
      lua_pushnumber(L, *dt);
      nargs = 2;
    }
    const double before = ls.script_ms();
    const LuaState::Outcome out = ls.pcall(nargs, 1);
    frame_ms += ls.script_ms() - before;
    if (out.ok) return true;
    const std::string ctx = what + " of marker " + std::to_string(t.id);
    std::string msg;
    if (out.budget || out.memory) {
      p.disabled.insert(fn);
      if (out.budget)
        msg = (out.message.rfind(p.display + ":", 0) == 0 ? out.message : function_prefix(p, fn) + out.message);
      else
        msg = function_prefix(p, fn) + "not enough memory (the cap is " + mib(limits.memory_bytes) + ")";
      msg += " in " + ctx + "; disabled until the scene reloads";
      p.mapping_error[static_cast<size_t>(mi)] = msg;
    } else {
      msg = out.message.rfind(p.display + ":", 0) == 0 ? out.message : function_prefix(p, fn) + out.message;
      msg += " (in " + ctx + ")";
    }
    report(2, msg);
    if (inst) inst->error = msg;
    return false;
  }

  void set_media(Program& p, Instance& inst, const MediaSpec& spec, int text_fn) {
    if (inst.text_fn != LUA_NOREF) luaL_unref(p.lua->L(), LUA_REGISTRYINDEX, inst.text_fn);
    inst.media_set = true;
    inst.media = spec;
    inst.text_fn = text_fn;
  }

  // A callback's result (on top of the stack, popped): nothing, or {media = ..., place = ...}.
  void apply_return(Program& p, int fn, Instance& inst, const std::string& ctx) {
    lua_State* L = p.lua->L();
    const int r = lua_gettop(L);
    if (lua_isnil(L, r)) {
      lua_settop(L, r - 1);
      return;
    }
    if (lua_type(L, r) != LUA_TTABLE) {
      report(1, function_prefix(p, fn) + ctx + " returned a " + luaL_typename(L, r) +
                    "; return nothing or a table {media = ..., place = ...}");
      lua_settop(L, r - 1);
      return;
    }
    static const std::vector<std::string_view> kKnown = {"media", "place"};
    lua_pushnil(L);
    while (lua_next(L, r) != 0) {
      if (lua_type(L, -2) != LUA_TSTRING) {
        report(1, function_prefix(p, fn) + ctx + " returned a table with a value that is not named; ignored");
      } else if (std::string key = lua_tostring(L, -2); key != "media" && key != "place") {
        std::string m = function_prefix(p, fn) + ctx + " returned unknown field '" + key + "'";
        if (std::string d = did_you_mean(key, kKnown); !d.empty()) m += " (" + d + ")";
        report(1, m);
      }
      lua_pop(L, 1);
    }
    lua_pushliteral(L, "media");
    lua_rawget(L, r);
    if (lua_type(L, r + 1) == LUA_TBOOLEAN && !lua_toboolean(L, r + 1)) {
      set_media(p, inst, MediaSpec{}, LUA_NOREF);   // media = false: show nothing
    } else if (!lua_isnil(L, r + 1)) {
      const MediaValue* mv = test_media(L, r + 1);
      if (!mv) {
        report(2, function_prefix(p, fn) + ctx + " returned media that is not a media value (image, video, web, "
                                                 "text or stage): " + luaL_typename(L, r + 1) + "; ignored");
      } else if (!mv->error.empty()) {
        report(2, (mv->where.empty() ? function_prefix(p, fn) : mv->where) + mv->error + "; ignored (" + ctx + ")");
      } else {
        int ref = LUA_NOREF;
        if (mv->computed) {
          push_text_function(L, r + 1);
          ref = luaL_ref(L, LUA_REGISTRYINDEX);
        }
        set_media(p, inst, mv->spec, ref);
      }
    }
    lua_settop(L, r);
    lua_pushliteral(L, "place");
    lua_rawget(L, r);
    if (lua_type(L, r + 1) == LUA_TSTRING) {
      PlaceSpec ps;
      const std::string name = lua_tostring(L, r + 1);
      if (place_from_name(name, &ps)) {
        inst.place_set = true;
        inst.place = ps;
      } else {
        report(2, function_prefix(p, fn) + ctx + " returned unknown placement '" + name + "' (" +
                      place_kind_list() + "); ignored");
      }
    } else if (!lua_isnil(L, r + 1)) {
      const PlaceValue* pv = test_place(L, r + 1);
      if (!pv) {
        report(2, function_prefix(p, fn) + ctx + " returned place that is not a placement (" + place_kind_list() +
                      "): " + luaL_typename(L, r + 1) + "; ignored");
      } else if (!pv->error.empty()) {
        report(2, (pv->where.empty() ? function_prefix(p, fn) : pv->where) + pv->error + "; ignored (" + ctx + ")");
      } else {
        inst.place_set = true;
        inst.place = pv->spec;
      }
    }
    lua_settop(L, r - 1);
  }

  void run_callback(Program& p, int mi, int fn, const TrackedMarker& t, bool held, const double* dt,
                    const char* what, Instance& inst) {
    if (fn == LUA_NOREF || !p.lua) return;
    if (call(p, mi, fn, t, held, dt, what, &inst))
      apply_return(p, fn, inst, std::string(what) + " of marker " + std::to_string(t.id));
  }

  // ---- one frame -----------------------------------------------------------------------------------------------

  void enter(Program& p, const TrackedMarker& t) {
    p.inside.insert(t.id);
    p.last[t.id] = t;
    for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
      const Mapping& m = p.def.mappings[mi];
      if (!m.ids.contains(t.id)) continue;
      Instance& inst = p.instances[{static_cast<int>(mi), t.id}];
      inst.inside = true;
      inst.fresh = true;
      run_callback(p, static_cast<int>(mi), m.on_enter, t, !t.detected, nullptr, "on_enter", inst);
    }
  }

  void leave(Program& p, int id) {
    TrackedMarker t;
    t.id = id;
    if (auto it = p.last.find(id); it != p.last.end()) t = it->second;
    p.inside.erase(id);
    for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
      const Mapping& m = p.def.mappings[mi];
      if (!m.ids.contains(id)) continue;
      Instance& inst = p.instances[{static_cast<int>(mi), id}];
      inst.inside = false;
      if (inst.video) inst.video->set_clock(inst.position, false);   // paused where it stopped
      run_callback(p, static_cast<int>(mi), m.on_leave, t, false, nullptr, "on_leave", inst);
    }
    p.last.erase(id);
  }

  // The pixels for a media of an instance; null (reported) when there are none.
  std::shared_ptr<MediaContent> content_for(Program& p, const Mapping& m, Instance& inst, const MediaSpec& spec,
                                            const SceneInput& in,
                                            std::array<std::shared_ptr<MediaContent>, kStageCount>& stages) {
    const std::string at = p.display + ":" + std::to_string(m.line) + ": ";
    if (spec.kind != MediaKind::video && inst.video) {   // the media changed away from a video
      inst.video->set_clock(inst.position, false);
      inst.video.reset();
      inst.video_key.clear();
    }
    std::string err;
    switch (spec.kind) {
      case MediaKind::none: return nullptr;
      case MediaKind::image: {
        const std::string key = "image\n" + spec.path;
        if (inst.content_key != key) {
          inst.content_key = key;
          inst.content = store.image(spec.path, &err);
          if (!inst.content) report(2, at + (err.empty() ? spec.source + ": cannot be loaded" : err));
        }
        if (!inst.content) inst.error = "cannot load " + spec.source;
        return inst.content;
      }
      case MediaKind::web: {
        const std::string key = "web\n" + spec.url + "\n" + spec.title;
        if (inst.content_key != key) {
          inst.content_key = key;
          inst.content = store.web_card(spec);
        }
        return inst.content;
      }
      case MediaKind::text: return store.text_card(spec);
      case MediaKind::video: {
        const std::string key = "video\n" + spec.path + (spec.loop ? "\nloop" : "");
        if (inst.video_key != key) {
          inst.video_key = key;
          inst.position = 0;
          inst.video = store.video(spec.path, spec.loop, &err);
          if (!inst.video) report(2, at + (err.empty() ? spec.source + ": cannot be played" : err));
        }
        if (!inst.video) {
          inst.error = "cannot play " + spec.source;
          return nullptr;
        }
        inst.video->set_clock(inst.position, true);
        if (std::string e = inst.video->error(); !e.empty()) {
          report(2, at + e);
          inst.error = e;
        }
        return inst.video;
      }
      case MediaKind::stage: {
        Stage s{};
        if (!stage_from_name(spec.stage, &s) || static_cast<int>(s) >= kStageCount) return nullptr;
        const size_t k = static_cast<size_t>(s);
        if (!stages[k] && in.views) stages[k] = make_stage_content((*in.views)[k], in.frame_index);
        if (!stages[k] && !p.stage_note) {
          p.stage_note = true;
          report(1, at + "stage \"" + spec.stage + "\" has no picture on this frame (stage pictures need the "
                         "trace at level full); nothing shown");
        }
        return stages[k];
      }
    }
    return nullptr;
  }

  std::vector<Overlay> update(const SceneInput& in) {
    frame_ms = 0;
    std::vector<Overlay> overlays;
    if (!prog) {
      status.mappings.clear();
      status.script_ms = 0;
      return overlays;
    }
    Program& p = *prog;
    static const std::vector<TrackedMarker> kNoTracks;
    static const std::vector<TrackEvent> kNoEvents;
    const auto& tracks = in.tracks ? *in.tracks : kNoTracks;
    const auto& events = in.events ? *in.events : kNoEvents;

    // The markers this scene sees: all, or those of its dictionary when it named one.
    std::map<int, const TrackedMarker*> seen;
    const std::string want = upper_dict(p.def.dict_name);
    for (const TrackedMarker& t : tracks) {
      if (!p.def.dictionary.empty() && !t.dict.empty() && upper_dict(t.dict) != want) continue;
      seen.emplace(t.id, &t);
    }
    for (auto& [key, inst] : p.instances) inst.error.clear();

    // Enter and leave: the tracker's events, then whatever they missed (markers in view when the scene loaded).
    for (const TrackEvent& e : events) {
      if (e.kind == TrackEvent::Kind::enter) {
        if (auto it = seen.find(e.id); it != seen.end() && !p.inside.count(e.id)) enter(p, *it->second);
      } else if (p.inside.count(e.id)) {
        leave(p, e.id);
      }
    }
    for (const auto& [id, t] : seen)
      if (!p.inside.count(id)) enter(p, *t);
    for (const int id : std::vector<int>(p.inside.begin(), p.inside.end()))
      if (!seen.count(id)) leave(p, id);

    // on_update, and the play position.
    for (const auto& [id, t] : seen) {
      p.last[id] = *t;
      for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
        const Mapping& m = p.def.mappings[mi];
        if (!m.ids.contains(id)) continue;
        Instance& inst = p.instances[{static_cast<int>(mi), id}];
        if (!inst.fresh) inst.position += std::max(0.0, in.dt_s);
        inst.fresh = false;
        run_callback(p, static_cast<int>(mi), m.on_update, *t, !t->detected, &in.dt_s, "on_update", inst);
      }
    }

    // Overlays: each mapping in declaration order (later ones drawn over earlier ones), its markers in id order.
    std::array<std::shared_ptr<MediaContent>, kStageCount> stages{};
    for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
      const Mapping& m = p.def.mappings[mi];
      for (const auto& [id, t] : seen) {
        if (!m.ids.contains(id)) continue;
        Instance& inst = p.instances[{static_cast<int>(mi), id}];
        MediaSpec spec = inst.media_set ? inst.media : m.media;
        if (spec.kind == MediaKind::none) {
          content_for(p, m, inst, spec, in, stages);   // pauses a video the media was before
          continue;
        }
        const int fn = inst.media_set ? inst.text_fn : m.text_fn;
        if (spec.kind == MediaKind::text && fn != LUA_NOREF) {
          if (!p.lua || !call(p, static_cast<int>(mi), fn, *t, !t->detected, nullptr, "text", &inst)) continue;
          lua_State* L = p.lua->L();
          if (lua_type(L, -1) == LUA_TSTRING || lua_type(L, -1) == LUA_TNUMBER) {
            spec.text = lua_tostring(L, -1);
          } else {
            const std::string msg = function_prefix(p, fn) + "a text function must return a string, not " +
                                    luaL_typename(L, -1) + " (text of marker " + std::to_string(id) + ")";
            lua_pop(L, 1);
            report(2, msg);
            inst.error = msg;
            continue;
          }
          lua_pop(L, 1);
        }
        const PlaceSpec& place = inst.place_set ? inst.place : m.place;
        std::shared_ptr<MediaContent> content = content_for(p, m, inst, spec, in, stages);
        if (!content) continue;
        const cv::Size size = content->size();
        if (size.width <= 0 || size.height <= 0) continue;
        std::string why;
        const std::optional<MediaQuad> quad =
            arwb::place(place, t->corners, double(size.width) / double(size.height), in.frame, &why);
        if (!quad) {
          const std::string msg = p.display + ":" + std::to_string(m.line) + ": marker " + std::to_string(id) +
                                  ": " + (why.empty() ? "cannot be placed" : why);
          report(1, msg);
          inst.error = why;
          continue;
        }
        Overlay o;
        o.marker_id = id;
        o.mapping = static_cast<int>(mi);
        o.media = std::move(spec);
        o.place = place;
        o.quad = *quad;
        o.content = std::move(content);
        overlays.push_back(std::move(o));
      }
    }
    if (p.lua) {
      const double before = p.lua->script_ms();
      p.lua->collect_garbage();
      frame_ms += p.lua->script_ms() - before;
    }
    fill_rows(&seen);
    status.script_ms = frame_ms;
    return overlays;
  }

  void fill_rows(const std::map<int, const TrackedMarker*>* seen) {
    status.mappings.clear();
    if (!prog) return;
    Program& p = *prog;
    for (size_t mi = 0; mi < p.def.mappings.size(); ++mi) {
      const Mapping& m = p.def.mappings[mi];
      MappingRow row;
      row.ids = m.ids.text();
      set_row_name(row, m.name);
      row.media = m.media.describe();
      row.placement = m.place.describe();
      row.line = m.line;
      int visible = 0, held = 0;
      double longest = 0;
      std::string error = mi < p.mapping_error.size() ? p.mapping_error[mi] : std::string();
      if (seen)
        for (const auto& [id, t] : *seen) {
          if (!m.ids.contains(id)) continue;
          if (t->detected) {
            ++visible;
            longest = std::max(longest, t->visible_s);
          } else {
            ++held;
          }
          if (auto it = p.instances.find({static_cast<int>(mi), id}); error.empty() && it != p.instances.end())
            error = it->second.error;
        }
      if (!error.empty()) row.state = "error: " + error;
      else if (visible > 0)
        row.state = "visible " + fmt1(longest) + " s" +
                    (visible + held > 1 ? " (" + std::to_string(visible + held) + " markers)" : "");
      else if (held > 0) row.state = "held";
      else row.state = "waiting";
      status.mappings.push_back(std::move(row));
    }
  }
};

SceneRuntime::SceneRuntime(media::MediaStore& store, ScriptLimits limits)
    : impl_(std::make_unique<Impl>(store, limits)) {}
SceneRuntime::~SceneRuntime() = default;

bool SceneRuntime::load(const std::string& path) { return impl_->load(path); }
bool SceneRuntime::reload_if_changed() { return impl_->reload_if_changed(); }
void SceneRuntime::unload() { impl_->unload(); }
std::vector<Overlay> SceneRuntime::update(const SceneInput& in) { return impl_->update(in); }
const SceneStatus& SceneRuntime::status() const { return impl_->status; }
std::string SceneRuntime::dictionary() const { return impl_->prog ? impl_->prog->def.dictionary : std::string(); }

}  // namespace arwb::script
