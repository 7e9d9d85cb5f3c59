// Running another program and waiting for it: how arwb export converts media for phones with ffmpeg.
#pragma once

#include "base/result.hpp"

#include <string>
#include <vector>

namespace arwb {

struct ProcessResult {
  int exit_status = -1;     // the program's exit status; 128 + N when signal N ended it
  std::string output;       // what it wrote to stdout and stderr, interleaved; the last 64 KiB when it said more
};

// Runs argv[0] (looked up on PATH) with argv, stdin from /dev/null, and waits for it. Fails only when it cannot be
// started: "ffmpeg is not installed (not found on PATH)", or the system's reason.
Result<ProcessResult> run_program(const std::vector<std::string>& argv);

}  // namespace arwb
