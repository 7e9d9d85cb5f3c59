// What the model loaders share (model_loader.hpp): sizes and messages, files read under a limit, textures.
//
// The libraries parse; everything that touches the file system or the pixels of a texture is ours. Every file a
// model names goes through resolve_scene_file (media_path.hpp), so it obeys the same rules as an image the scene
// names; textures are decoded by Context::decode_texture (model_texture.cpp), never by the stb copy inside tinygltf.
#include "media/model_loader.hpp"

#include "base/files.hpp"
#include "media/media_path.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace arwb::media::model {

std::string size_text(uint64_t bytes) {
  constexpr uint64_t kMB = 1u << 20;
  if (bytes < kMB) return std::to_string(bytes) + " bytes";
  if (bytes % kMB == 0) return std::to_string(bytes / kMB) + " MB";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f MB", static_cast<double>(bytes) / kMB);
  return buf;
}

std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == ' ' || line.back() == '\r' || line.back() == '.')) line.pop_back();
  return shown_name(line);
}

Result<Bytes> read_limited(const std::string& path, const std::string& name, std::size_t limit) {
  // No limit of base/files' own: ours is the caller's, and its message names what the author wrote.
  Result<InputFile> file = open_input_file(path, FileLimit{"a 3D model", std::numeric_limits<std::uintmax_t>::max()});
  if (!file) {
    std::string reason = file.error();
    if (reason.starts_with(path + ": ")) reason = reason.substr(path.size() + 2);
    return fail(name + ": " + reason);
  }
  if (file->size() > limit)
    return fail(name + ": " + size_text(file->size()) + ", more than the limit of " + size_text(limit));
  Bytes bytes(static_cast<std::size_t>(file->size()));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const long long n = file->read_at(done, bytes.data() + done, bytes.size() - done);
    if (n < 0) return fail(name + ": cannot be read");
    if (n == 0) break;  // shrank since it was opened
    done += static_cast<std::size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

Result<std::shared_ptr<MediaContent>> Context::external_texture(const std::string& written, const std::string& what) {
  const ResolvedFile file = resolve_scene_file(scene_dir, written, folder);
  if (!file.ok()) {
    if (file.error.ends_with(": no such file")) {
      warnings.push_back(name + ": " + what + ": " + file.error);
      return std::shared_ptr<MediaContent>();
    }
    return fail(name + ": " + what + ": " + file.error);
  }
  if (auto it = textures.find(file.path); it != textures.end()) return it->second;
  if (static_cast<int>(textures.size()) >= limits.textures)
    return fail(name + ": more than the limit of " + std::to_string(limits.textures) + " textures");
  Result<Bytes> bytes = read_limited(file.path, shown_name(written), limits.file_bytes);
  if (!bytes) {
    warnings.push_back(name + ": " + what + ": " + bytes.error());
    return std::shared_ptr<MediaContent>();
  }
  std::shared_ptr<MediaContent> texture = decode_texture(*bytes, shown_name(written), what);
  textures[file.path] = texture;
  return texture;
}

cv::Scalar bgra(double r, double g, double b, double a) {
  const auto c = [](double v) { return std::isfinite(v) ? std::clamp(v, 0.0, 1.0) * 255.0 : 255.0; };
  return cv::Scalar(c(b), c(g), c(r), c(a));
}

void normalise_normals(MeshPart& part) {
  for (cv::Vec3f& n : part.normals) {
    const double len = cv::norm(n);
    if (!std::isfinite(len) || len < 1e-12) {
      part.normals.clear();
      return;
    }
    n *= static_cast<float>(1.0 / len);
  }
}

void drop_texture_without_uvs(Context& ctx, MeshPart& part) {
  if (part.texture && part.uvs.empty()) {
    ctx.warnings.push_back(ctx.name + ": material '" + shown_name(part.name) +
                           "' has a texture but its faces have no texture coordinates");
    part.texture.reset();
  }
}

}  // namespace arwb::media::model
