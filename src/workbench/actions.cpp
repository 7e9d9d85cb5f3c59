#include "workbench/actions.hpp"

#include <algorithm>
#include <stdexcept>

namespace arwb {

const std::vector<std::string>& player_action_verbs() {
  static const std::vector<std::string> kVerbs = {"overlay", "stage", "click", "fullscreen", "quit"};
  return kVerbs;
}

bool parse_actions(const std::vector<std::string>& specs, std::vector<Action>* out, std::string* error,
                   const std::vector<std::string>& verbs) {
  for (const auto& spec : specs) {
    size_t start = 0;
    while (start <= spec.size()) {
      size_t end = spec.find(';', start);
      if (end == std::string::npos) end = spec.size();
      const std::string item = spec.substr(start, end - start);
      start = end + 1;
      if (item.empty()) continue;
      const size_t colon = item.find(':');
      Action a;
      try {
        size_t used = 0;
        a.frame = std::stoi(item.substr(0, colon), &used);
        if (colon == std::string::npos || used != colon || a.frame < 0) throw std::invalid_argument("frame");
      } catch (const std::exception&) {
        *error = "--actions '" + item + "': expected FRAME:VERB[=ARG]";
        return false;
      }
      const std::string rest = item.substr(colon + 1);
      const size_t eq = rest.find('=');
      a.verb = rest.substr(0, eq);
      a.arg = eq == std::string::npos ? "" : rest.substr(eq + 1);
      const bool known = std::find(verbs.begin(), verbs.end(), a.verb) != verbs.end();
      if (!known) {
        *error = "--actions '" + item + "': unknown verb '" + a.verb + "'";
        return false;
      }
      out->push_back(a);
    }
  }
  std::stable_sort(out->begin(), out->end(), [](const Action& x, const Action& y) { return x.frame < y.frame; });
  return true;
}

}  // namespace arwb
