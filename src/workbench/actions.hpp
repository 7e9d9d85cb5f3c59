// Scripted workbench steps for tests and demos: "N:verb[=arg];..." run at UI frame N (see `arwb --help`).
#pragma once

#include <string>
#include <vector>

namespace arwb {

struct Action {
  int frame = 0;
  std::string verb, arg;
};

// Parses every spec into `out`, sorted by frame (stable). False and a message naming the bad item otherwise.
// `verbs`: the verbs allowed (the workbench's are ui/actions.hpp's, the player's player_action_verbs()).
bool parse_actions(const std::vector<std::string>& specs, std::vector<Action>* out, std::string* error,
                   const std::vector<std::string>& verbs);
// The player's verbs (`arwb play --help`).
const std::vector<std::string>& player_action_verbs();

}  // namespace arwb
