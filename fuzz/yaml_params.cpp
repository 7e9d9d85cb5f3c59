// Fuzz target: detector parameter presets (src/detect/params.cpp, load_params_yaml), as `--params FILE.yml`, the
// workbench's preset loading and `arwb render --params` read them: from a file, so the file checks run too. A
// load either changes the parameters to values inside the table's ranges, or fails with messages naming the file
// and changes nothing.
#include "detect/params.hpp"
#include "fuzz_files.hpp"

#include <opencv2/core/utils/logger.hpp>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    return true;
  }();
  (void)quiet;

  const std::string path = arwb::fuzz::write_scratch("preset.yml", data, size);
  arwb::DetectorParams params;
  const arwb::DetectorParams before = params;
  std::vector<std::string> errors, notes;
  bool ok = false;
  ok = arwb::load_params_yaml(path, params, &errors, &notes);
  if (!ok && errors.empty()) std::abort();
  for (const std::string& e : errors)
    if (e.rfind(path, 0) != 0) std::abort();   // every message names the file
  for (const arwb::ParamInfo& info : arwb::param_table()) {
    const double v = arwb::get_param(params, info);
    if (!ok && v != arwb::get_param(before, info)) std::abort();   // a failed load changes nothing
    if (!(v >= info.min_value && v <= info.max_value)) std::abort();
  }
  return 0;
}
