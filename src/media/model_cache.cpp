#include "media/model_cache.hpp"

#include "media/media_path.hpp"
#include "media/model_file.hpp"

namespace arwb::media {

std::shared_ptr<const Mesh> ModelCache::get(const std::filesystem::path& scene_dir, const std::string& relative,
                                            std::string* error, std::string* warning) {
  if (warning) warning->clear();
  const ResolvedFile file = resolve_scene_file(scene_dir, relative);
  if (!file.ok()) {
    if (error) *error = file.error;
    return nullptr;
  }
  // The scene's folder is part of the key because the model's own references are judged against that folder.
  std::error_code ec;
  const std::filesystem::path folder = std::filesystem::canonical(scene_dir, ec);
  const std::string key = (ec ? scene_dir.string() : folder.string()) + '\x1f' + file.path;
  {
    std::lock_guard lock(mutex_);
    if (auto it = models_.find(key); it != models_.end())
      if (std::shared_ptr<const Mesh> held = it->second.mesh.lock()) {
        if (error) error->clear();
        if (warning) *warning = it->second.warning;
        return held;
      }
  }
  // Read without the lock, so that one large model does not hold up the others.
  std::string warned;
  Result<std::shared_ptr<Mesh>> loaded = load_model(scene_dir, relative, ModelLimits{}, &warned);
  if (!loaded) {
    if (error) *error = loaded.error();
    return nullptr;
  }
  std::shared_ptr<const Mesh> mesh = std::move(*loaded);
  std::lock_guard lock(mutex_);
  Cached& slot = models_[key];
  if (std::shared_ptr<const Mesh> raced = slot.mesh.lock()) {  // read twice: keep one
    mesh = std::move(raced);
  } else {
    slot.mesh = mesh;
    slot.warning = warned;
  }
  if (error) error->clear();
  if (warning) *warning = slot.warning;
  return mesh;
}

void ModelCache::trim() {
  std::lock_guard lock(mutex_);
  std::erase_if(models_, [](const auto& entry) { return entry.second.mesh.expired(); });
}

}  // namespace arwb::media
