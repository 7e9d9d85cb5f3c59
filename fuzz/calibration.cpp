// Fuzz target: calibration files (src/calibration/calibration_file.cpp), read as every part of the program reads
// them: read_calibration on the bytes as a file (so the file checks, the YAML guards and our XML check run too),
// then as the paper's distCoeffs.xml beside a good cameraMatrix.xml (read_calibration_pair), then scaled to another
// source size. A read either gives a camera within calibration/camera_rule.hpp's rule (4, 5, 8, 12 or 14 finite
// distortion values) or fails with a message naming the file. A camera that reads, fitted to a small picture of its
// own aspect, renders a marker through the lab's renderer, as `arwb lab --calib` would.
#include "calibration/calibration_file.hpp"
#include "fuzz_files.hpp"
#include "synth/marker_view.hpp"

#include <opencv2/core/utils/logger.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

namespace {

void check(const arwb::Result<arwb::Calibration>& c, const std::string& path) {
  if (!c) {
    if (c.error().rfind(path, 0) != 0) std::abort();   // every message names the file
    return;
  }
  const cv::Matx33d& K = c->camera_matrix;
  if (!arwb::camera_matrix_problem(K).empty()) std::abort();
  for (int i = 0; i < 9; ++i)
    if (!std::isfinite(K.val[i])) std::abort();
  const size_t n = c->distortion.size();
  if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14) std::abort();
  for (double d : c->distortion)
    if (!std::isfinite(d)) std::abort();
  const arwb::Result<arwb::Calibration> scaled = arwb::calibration_for_size(*c, cv::Size(640, 480));
  if (scaled && !arwb::camera_matrix_problem(scaled->camera_matrix).empty()) std::abort();
  // The lab's renderer, 64 pixels on the long side at the file's own aspect (4:3 when it names none).
  const cv::Size own = !c->image_size.empty() ? c->image_size : cv::Size(640, 480);
  const double scale = 64.0 / std::max(own.width, own.height);
  const cv::Size small(std::max(1, int(std::lround(own.width * scale))), std::max(1, int(std::lround(own.height * scale))));
  if (const arwb::Result<arwb::Calibration> fitted = arwb::calibration_for_size(*c, small)) {
    const arwb::MarkerRenderer renderer({small, fitted->camera_matrix, fitted->distortion}, arwb::SynthMarker{});
    const arwb::MarkerView view = renderer.render(cv::Vec3d(0.3, 0, 0), cv::Vec3d(0, 0, 0.5));
    if (view.image.size() != small) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string camera = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    const std::string good =
        "<?xml version=\"1.0\"?>\n<opencv_storage>\n<cameraMatrix type_id=\"opencv-matrix\"><rows>3</rows>"
        "<cols>3</cols><dt>d</dt><data>600 0 320 0 600 240 0 0 1</data></cameraMatrix>\n</opencv_storage>\n";
    return arwb::fuzz::write_scratch("good_cameraMatrix.xml", reinterpret_cast<const uint8_t*>(good.data()),
                                     good.size());
  }();
  const std::string path = arwb::fuzz::write_scratch("calibration.yml", data, size);
  check(arwb::read_calibration(path), path);
  // The camera file is good: a failure is this file's, and names it first.
  check(arwb::read_calibration_pair(camera, path), path);
  return 0;
}
