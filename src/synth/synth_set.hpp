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
  std::string condition;     // a hard set's image: its Hardship's name; empty in a standard set
};

// The standard set: photographs of every kind at mixed_sizes(). The hard set: each image one of the hardships
// (synth.hpp) in turn, at hard_sizes().
enum class SetKind { standard, hard };

// The sizes a mixed set cycles through.
const std::vector<cv::Size>& mixed_sizes();

// The sizes a hard set cycles through: mixed_sizes() and 3840x2160.
const std::vector<cv::Size>& hard_sizes();

// Image i of a set: size cycles through `sizes`, dictionaries through `dicts`; in a hard set, the hardship changes
// after each round of sizes, so that every size meets every hardship.
SetItem make_set_item(const std::vector<Dictionary>& dicts, const std::vector<cv::Size>& sizes, uint64_t seed, int i,
                      SetKind kind = SetKind::standard);

// One truth.jsonl line: {"file","width","height","markers":[{"id","dict","corners"}],"notes"}, and "condition"
// for a hard set's image.
std::string truth_line(const SetItem& item);

// Reads DIR/truth.jsonl and the images it names. Lines that cannot be used are reported in *skipped
// ("DIR/truth.jsonl:12: ...") and skipped. An error when the file itself cannot be read.
Result<std::vector<SetItem>> read_set(const std::string& dir, std::vector<std::string>* skipped);

}  // namespace arwb
