// cells.jsonl: a run's finished cells, one line each (cell_to_line), appended as each finishes. Read back,
// it resumes an interrupted run (arwb lab --out), and it joins the parts of a run spread over processes or
// machines (arwb lab --shard, --merge).
#pragma once

#include "lab/run.hpp"

#include "base/result.hpp"

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace arwb::lab {

// Resuming an interrupted run. The key names everything the frames and tallies depend on (the plan, seed,
// detectors and their parameters, camera, sensor): a saved cell is taken only under the same key. A cell as one
// line of JSON, and back: nullopt for a line that is not one, or of another key; nullopt and `problem` for a line
// of this key whose counts cannot be (a negative count, more found than frames: an edited line), so that the
// cell is run again and the user told why.
std::string lab_run_key(const LabPlan& plan, const LabOptions& options);
std::string cell_to_line(const std::string& key, size_t index, const CellResult& c);
std::optional<std::pair<size_t, CellResult>> cell_from_line(const std::string& key, const std::string& line,
                                                            size_t detectors, std::string* problem = nullptr);

// What reading one cells file gave.
struct CellsFile {
  int taken = 0;                       // cells put into `finished`
  std::vector<std::string> problems;   // lines of this run whose counts cannot be: "FILE:LINE: detected -2 is negative"
  int other_runs = 0;                  // lines of another plan or options (another key)
  std::string other_run;               // how the first of those differs, in words (key_difference)
};

// Takes the cells of the run `key` from the file at `path` into `finished` (indexed by cell; a cell already there is
// kept, so of two files the first given wins). A last line without its newline (cut short by an interruption) and
// lines of other runs are left out. An error names the file when it cannot be read: not a regular file (a FIFO
// would block), bigger than 256 MiB. A file that does not exist holds no cell.
Result<CellsFile> read_cells_file(const std::string& path, const std::string& key, size_t detectors,
                                  std::vector<std::shared_ptr<const CellResult>>& finished);

// How the run key `theirs` differs from `ours` (lab_run_key), as the first differing thing in words: "its seed is
// 7, this run's 1", "its parameter min_perimeter_px is 30, this run's 48", "its plan's lux is [800], this run's
// [1000,850,500]"; "" when they are the same.
std::string key_difference(const std::string& theirs, const std::string& ours);

// The line for each of `cells` in order (cell_to_line), as cells.jsonl holds them.
std::string cells_file_text(const std::string& key, const std::vector<CellResult>& cells);

}  // namespace arwb::lab
