// What a scene declares, shared by the Lua API (scene_api.cpp), the XML database (scene_database.cpp) and the
// runtime (scene_runtime.cpp). Internal to src/script.
#pragma once

#include "track/media_spec.hpp"
#include "track/placement.hpp"
#include "script/lua_host.hpp"
#include "base/result.hpp"

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace arwb::script {

// The ids a mapping covers: inclusive ranges.
struct IdSet {
  std::vector<std::pair<int, int>> ranges;
  bool contains(int id) const;
  std::string text() const;   // "7", "100-199", "1, 5, 9"
};

// One marker(...) call or database row.
struct Mapping {
  IdSet ids;
  std::string name;
  MediaSpec media;               // kind none: callbacks only
  int text_fn = LUA_NOREF;       // a computed text's function (registry reference)
  PlaceSpec place;
  int on_enter = LUA_NOREF, on_update = LUA_NOREF, on_leave = LUA_NOREF;
  int line = 0;
  // Why marker() refused this call ("scene.lua:5: logo.png: no such file"): the Scene panel keeps its row with the
  // reason, and nothing of it runs. "" for a mapping in use.
  std::string skipped;
};

struct SceneDef {
  std::string dictionary;                    // as the scene asked for it; "" when it did not
  std::string dict_name = "ARUCO_ORIGINAL";  // the dictionary ids are checked against
  int dict_size = 1024;
  bool markers_declared = false;             // a marker() call was seen (dictionary must come before)
  std::vector<Mapping> mappings;
};

// Payloads of the scene API's values (full userdata).
struct MediaValue {
  MediaSpec spec;
  bool computed = false;   // text(function): the function is the userdata's user value 1
  std::string error;       // non-empty: the constructor's arguments were bad (the value is unusable)
  std::string where;       // the constructor's position, "scene.lua:5: "
};
struct PlaceValue {
  PlaceSpec spec;
  std::string error;
  std::string where;
};
struct IdsValue {
  std::vector<int> ids;
  std::string error;
  std::string where;
};

// Registers the scene API's globals (dictionary, marker, ids, media and placement constructors).
void open_scene_api(lua_State* L);
// The value at idx if it is a live media / placement value, else null. Host mode, no errors.
const MediaValue* test_media(lua_State* L, int idx);
const PlaceValue* test_place(lua_State* L, int idx);
// Pushes a media value's computed-text function (nil when none).
void push_text_function(lua_State* L, int idx);
// `place = "beside"`: the placement kind's defaults by name.
bool place_from_name(std::string_view name, PlaceSpec* out);
// The placement kinds' names, for messages: "on_marker, beside, billboard, screen".
std::string place_kind_list();

// "did you mean 'place'?" for a misspelt field among `known`, or "".
std::string did_you_mean(std::string_view word, const std::vector<std::string_view>& known);

// The dictionary's id check: "" or "id 5000 is not a marker of ARUCO_ORIGINAL (ids 0 to 1023)".
std::string check_id(const SceneDef& def, long long id);

// The paper's database (an XML table of ids and resources), read into `def`. Bad rows are reported through
// `reporter` with their line and skipped. An error ("file:line: message") when the file is not a usable
// database at all.
Status load_database(const std::string& display, const std::string& text, const std::filesystem::path& dir,
                     SceneDef* def, Reporter& reporter);

}  // namespace arwb::script
