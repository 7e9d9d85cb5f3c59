// Fuzz target: custom dictionaries (src/detect/dictionary.cpp), as `--dict FILE.yml`, the workbench's dictionary
// list and scenes name them: parse_dictionaries on a list holding a predefined name and the file, so the whole path
// (file checks, OpenCV's YAML, the marker codes) runs. A dictionary that loads is then explored as the Dictionary
// panel does (closest pairs, distance histogram), whose sums are checked.
#include "detect/dictionary.hpp"
#include "fuzz_files.hpp"

#include <opencv2/core/utils/logger.hpp>

#include <cstdint>
#include <cstdlib>
#include <numeric>
#include <optional>
#include <vector>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    return true;
  }();
  (void)quiet;

  const std::string path = arwb::fuzz::write_scratch("custom.yml", data, size);
  std::string error;
  std::optional<std::vector<arwb::Dictionary>> dicts;
  dicts = arwb::parse_dictionaries("4X4_50," + path, &error);
  if (!dicts) {
    if (error.empty()) std::abort();
    return 0;
  }
  if (dicts->size() != 2) std::abort();
  const arwb::Dictionary& d = (*dicts)[1];
  if (d.size() < 1) std::abort();
  const std::vector<int> hist = arwb::distance_histogram(d);
  const long long n = d.size();
  if (std::accumulate(hist.begin(), hist.end(), 0LL) != n * (n - 1) / 2 + n) std::abort();
  const auto pairs = arwb::closest_pairs(d, 8);
  if (pairs.empty() || pairs.front().distance != d.min_distance()) std::abort();
  return 0;
}
