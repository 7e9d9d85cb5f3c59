// The guided teaching tour: steps a teacher can edit or translate in a plain text file
// (assets/teaching/tour.txt, whose first lines document the format). One step per pipeline stage, plus an
// [overview] before them, [pose] (what a marker's corners say in 3D) after them and a [summary] at the end.
#pragma once

#include "detect/trace.hpp"

#include <string>
#include <vector>

namespace arwb {

struct TourStep {
  std::string key;                  // a stage name (stage_name()), "overview", "pose" or "summary"
  bool is_stage = false;
  Stage stage = Stage::accepted;    // the stage when is_stage; Stage::accepted (no stage) otherwise
  std::string title;
  std::string text;                 // paragraphs separated by "\n\n"; the lines of a paragraph joined by spaces
  std::vector<std::string> params;  // parameter-table names to show as sliders in this step
  std::string look;                 // what to look at on screen, one line
  int line = 0;                     // 1-based line of the step's [key] header
};

// Reads a tour. Each problem is one entry in `errors`, "path:line: message" (unknown stage or parameter, a step
// without a title or text, text before the first step, a repeated step ...; "path: cannot read" for a missing
// file). Lenient, so a teacher's typo never blanks the tour: a step with an unknown name is skipped, an unknown
// parameter is left out, a missing title falls back to the key, and every other step is kept. False only when no
// step could be read. UTF-8 text is kept as written; a byte-order mark and \r line ends are removed.
bool load_tour(const std::string& path, std::vector<TourStep>* steps, std::vector<std::string>* errors);

}  // namespace arwb
