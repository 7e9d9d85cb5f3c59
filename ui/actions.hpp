// The workbench's --actions ("N:verb[=arg];...", `arwb --help` lists the verbs): each step is turned here, and only
// here, into the request (ui/request.hpp) a menu, a key or a panel would make; the window carries it out at UI
// frame N.
#pragma once

#include "base/result.hpp"
#include "ui/request.hpp"

#include <string>
#include <vector>

namespace arwb::ui {

// The verbs, in the order `arwb --help` gives them.
const std::vector<std::string>& action_verbs();

// A verb and its argument as the request they make, or a message naming the verb and the argument it cannot take
// ("--actions: no stage 'blur'", "--actions lab_frames: 1 to 10000 frames per cell, not '0'").
Result<Request> action_request(const std::string& verb, const std::string& arg);

// A step of a script: at UI frame `frame`, its request, or why it cannot be one (said in the log when the frame
// comes, and the window goes on).
struct ScriptStep {
  int frame = 0;
  Result<Request> request;
};

// Every step of `specs`, sorted by frame (stable); a step that is not FRAME:VERB[=ARG] or whose verb is unknown
// fails the whole, naming it ("--actions '5:explode': unknown verb 'explode'").
Result<std::vector<ScriptStep>> parse_script(const std::vector<std::string>& specs);

}  // namespace arwb::ui
