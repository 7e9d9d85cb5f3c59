// Fuzz target: the lab's files a user writes or edits by hand (src/lab), the same bytes as each: a plan
// (read_plan), a videos.csv (read_video_list) and the lines of an interrupted run's cells.jsonl (cell_from_line, as a
// resumed run reads them). What they promise: a refusal is one line naming the file (or, for a cell, says why the
// cell is run again); an accepted plan has 1 to kMaxLabCells cells; an accepted videos.csv has ids, sizes,
// distances and lights a table can use; a cell read back has no negative count and no more found than shown, and
// written again reads again to the same counts.
#include "fuzz_files.hpp"
#include "lab/plan.hpp"
#include "lab/cells_file.hpp"
#include "lab/run.hpp"
#include "lab/videos.hpp"

#include <opencv2/core/utils/logger.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

namespace {

using namespace arwb::lab;

bool one_line_naming(const std::string& message, const std::string& name) {
  return message.find(name) != std::string::npos && message.find('\n') == std::string::npos;
}

void check_plan(const uint8_t* data, size_t size) {
  const std::string path = arwb::fuzz::write_scratch("plan.yml", data, size);
  const arwb::Result<LabPlan> p = read_plan(path);
  if (!p) {
    if (!one_line_naming(p.error(), "plan.yml")) std::abort();
    return;
  }
  const size_t cells = p->cell_count();
  if (cells < 1 || cells > kMaxLabCells) std::abort();
}

void check_videos(const uint8_t* data, size_t size) {
  arwb::fuzz::write_scratch("videos.csv", data, size);
  const auto rows = read_video_list(arwb::fuzz::scratch_dir().string());
  if (!rows) {
    if (!one_line_naming(rows.error(), "videos.csv")) std::abort();
    return;
  }
  for (const VideoRow& r : *rows) {
    if (r.id < 0 || !(r.size_mm > 0) || !(r.distance_m > 0) || !(r.lux >= 0) || !std::isfinite(r.size_mm) ||
        !std::isfinite(r.distance_m) || !std::isfinite(r.lux))
      std::abort();
    if (r.first_frame < 0 || (r.last_frame != -1 && r.last_frame < r.first_frame)) std::abort();
  }
}

void check_cells(const uint8_t* data, size_t size) {
  const std::string key = "fuzz-key";
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  for (std::string line; std::getline(in, line);) {
    std::string problem;
    const auto cell = cell_from_line(key, line, 1, &problem);
    if (!cell) {
      if (problem.find('\n') != std::string::npos) std::abort();
      continue;
    }
    for (const DetectorTally& t : cell->second.detectors)
      if (t.frames < 0 || t.detected < 0 || t.wrong_id < 0 || t.empty_frames < 0 || t.false_positives < 0 ||
          t.detected > t.frames)
        std::abort();
    const auto again = cell_from_line(key, cell_to_line(key, cell->first, cell->second), 1);
    if (!again || again->first != cell->first || again->second.detectors.size() != cell->second.detectors.size())
      std::abort();
    for (size_t i = 0; i < again->second.detectors.size(); ++i)
      if (again->second.detectors[i].detected != cell->second.detectors[i].detected ||
          again->second.detectors[i].frames != cell->second.detectors[i].frames)
        std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    return true;
  }();
  (void)quiet;
  check_plan(data, size);
  check_videos(data, size);
  check_cells(data, size);
  return 0;
}
