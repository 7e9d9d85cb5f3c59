// The synthetic benchmark set shared by `arwb synth` (which writes it to a folder) and `arwb bench` (which makes
// it in memory or reads it back): images and their truth as JSON lines.
#pragma once

#include "synth/synth.hpp"
#include "base/result.hpp"

#include <string>
#include <vector>

namespace arwb {

struct SetItem {
  std::string file;          // name inside the set's folder
  cv::Mat image;             // BGR
  std::vector<TruthMarker> truth;
  std::string notes;
};

// The sizes a mixed set cycles through.
const std::vector<cv::Size>& mixed_sizes();

// Image i of a set: size cycles through `sizes`, dictionaries through `dicts`.
SetItem make_set_item(const std::vector<Dictionary>& dicts, const std::vector<cv::Size>& sizes, uint64_t seed, int i);

// One truth.jsonl line: {"file","width","height","markers":[{"id","dict","corners"}],"notes"}.
std::string truth_line(const SetItem& item);

// Reads DIR/truth.jsonl and the images it names. Lines that cannot be used are reported in *skipped
// ("DIR/truth.jsonl:12: ...") and skipped. An error when the file itself cannot be read.
Result<std::vector<SetItem>> read_set(const std::string& dir, std::vector<std::string>* skipped);

}  // namespace arwb
