// 3D models read once and shared while anyone holds them: the desktop's MediaStore and the phone player's core
// (web/core) both answer MediaProvider::model through one of these.
#pragma once

#include "track/mesh.hpp"

#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace arwb::media {

class ModelCache {
 public:
  // The model `relative` (as the scene wrote it) inside `scene_dir`, read by load_model (model_file.hpp) on the
  // first call and shared while anyone holds it, cached by the scene's folder and the model's canonical path (so
  // "models/a.obj" and "./models/a.obj" share one mesh). Null and *error set on failure (load_model's message);
  // *error cleared on success. *warning (if given) gets what the load warned about (a texture that could not be
  // read), again on each call that finds the model cached. Safe to call from several threads.
  std::shared_ptr<const Mesh> get(const std::filesystem::path& scene_dir, const std::string& relative,
                                  std::string* error, std::string* warning);
  // Forgets the models nobody holds any more.
  void trim();

 private:
  struct Cached {
    std::weak_ptr<const Mesh> mesh;
    std::string warning;
  };
  std::mutex mutex_;
  std::unordered_map<std::string, Cached> models_;
};

}  // namespace arwb::media
