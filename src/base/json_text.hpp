// JSON values as text, the one way we write them: a string that is not UTF-8 (a file name in Latin-1, a view
// named "vue_\xE9t\xE9_1.png") has its bad bytes replaced by U+FFFD. nlohmann's own dump() throws type_error.316
// on such a string, which ended `arwb lab` and the window, and left `arwb calibrate --json` without its JSON.
#pragma once

#include <string>

namespace arwb {

// `indent` as nlohmann's dump(): -1 one line, n >= 0 pretty with n spaces. A template over the JSON type, so that
// base needs no JSON library: nlohmann::json and ordered_json both work.
template <typename Json>
std::string json_text(const Json& j, int indent = -1) {
  return j.dump(indent, ' ', false, Json::error_handler_t::replace);
}

}  // namespace arwb
