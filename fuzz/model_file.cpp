// Fuzz target: the 3D model loader (src/media/model_file.cpp: load_model), as a scene's `model "..."` reads a
// file: the input is the model (OBJ, glTF or GLB: recognised by its bytes), read from a scratch scene folder that
// also holds a material library (model.mtl), a buffer (model.bin, 64 bytes) and a texture (tex.png) for the input
// to name. What load_model promises: a refusal is one message naming the model; a mesh it returns is consistent
// (validate), has triangles, stays within the limits given, and names its source. The limits are small so that
// no input runs long.
#include "fuzz_files.hpp"
#include "media/model_file.hpp"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fs = std::filesystem;
  static const fs::path scene = arwb::fuzz::scratch_dir() / "scene";
  static const bool ready = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    fs::create_directories(scene);
    const std::string mtl = "newmtl a\nKd 1 0 0\nd 0.5\nmap_Kd tex.png\nnewmtl b\nKd 0 0 1\n";
    const std::string bin(64, '\x01');
    arwb::fuzz::write_scratch("scene/model.mtl", reinterpret_cast<const uint8_t*>(mtl.data()), mtl.size());
    arwb::fuzz::write_scratch("scene/model.bin", reinterpret_cast<const uint8_t*>(bin.data()), bin.size());
    return cv::imwrite((scene / "tex.png").string(), cv::Mat(8, 8, CV_8UC3, cv::Scalar(40, 160, 220)));
  }();
  if (!ready) std::abort();

  arwb::fuzz::write_scratch("scene/model", data, size);
  arwb::media::ModelLimits limits;
  limits.file_bytes = 1u << 20;
  limits.triangles = 20'000;
  limits.vertices = 20'000;
  limits.textures = 4;
  std::string warning;
  const auto mesh = arwb::media::load_model(scene, "model", limits, &warning);
  if (!mesh) {
    if (!mesh.error().starts_with("model")) std::abort();
    return 0;
  }
  const arwb::Mesh& m = **mesh;
  if (!m.validate().empty() || m.triangle_count() == 0 || m.triangle_count() > limits.triangles ||
      m.vertex_count() > limits.vertices || m.source != "model")
    std::abort();
  return 0;
}
