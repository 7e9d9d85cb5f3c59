// What the model loaders share (internal to src/media): where the model is, what it may use and what went wrong
// so far (Context), files read under a limit, textures decoded by ours, and what every part gets once built.
//   model_file.cpp    load_model: the format by its bytes, then the mesh checked and its bounds computed
//   model_loader.cpp  what is declared here but decode_texture
//   model_texture.cpp decode_texture (the phone player's core has its own: web/core/model_texture.cpp)
//   model_obj.cpp     Wavefront OBJ and the material libraries (.mtl) it names, through tinyobjloader
//   model_gltf.cpp    glTF 2.0 (.gltf with its files, or one .glb), through tinygltf
#pragma once

#include "media/model_file.hpp"

#include "base/result.hpp"
#include "track/media_spec.hpp"
#include "track/mesh.hpp"

#include <opencv2/core.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace arwb::media::model {

using Bytes = std::vector<uint8_t>;

// "80 MB" for sizes of a megabyte or more (one decimal when not whole, so 64.5 MB is not shown as the limit of
// 64 MB it exceeds), "900 bytes" below.
std::string size_text(uint64_t bytes);

// The first line of a library's message, without trailing spaces or dots: the libraries end lines with "\n"
// and sometimes ".\n", and several messages may be chained.
std::string first_line(const std::string& text);

// The whole file at `path` (already resolved by resolve_scene_file), refused when larger than `limit` before
// anything is read. Errors name `name`, what the author wrote, not the resolved path.
Result<Bytes> read_limited(const std::string& path, const std::string& name, std::size_t limit);

// What every loader shares: where the model is, what it may use, and what went wrong so far.
struct Context {
  std::filesystem::path scene_dir;
  std::string relative;  // the model as the scene wrote it
  std::string name;      // the same, fit for a message
  std::filesystem::path folder;   // the model's folder as the scene wrote it ("models" for "models/x.obj")
  ModelLimits limits;
  std::vector<std::string> warnings;
  // Textures decoded so far, by canonical path (OBJ) or image index (glTF), so parts share them.
  std::map<std::string, std::shared_ptr<MediaContent>> textures;

  // A texture the model names (map_Kd, an image's uri): null and a warning when it cannot be read; an error
  // when it breaks the path rules (absolute, "..", a link leading out): those are refused as for the model.
  Result<std::shared_ptr<MediaContent>> external_texture(const std::string& written, const std::string& what);

  // A texture by its bytes (null and a warning when it cannot be shown): pixels on the desktop, decoded by
  // decode_image, which checks signature, header and limits first; the checked bytes in the phone player's core.
  std::shared_ptr<MediaContent> decode_texture(std::span<const uint8_t> bytes, const std::string& shown,
                                               const std::string& what);
};

// A colour of 0..1 components as 0..255 BGRA; a component that is not finite is taken as 1.
cv::Scalar bgra(double r, double g, double b, double a);

// Normals are unit length or absent: a part with a zero, infinite or NaN normal is shaded flat instead.
void normalise_normals(MeshPart& part);

// A part whose material has a texture but whose vertices have no texture coordinates cannot show it.
void drop_texture_without_uvs(Context& ctx, MeshPart& part);

// The loaders, on the model's bytes (the format recognised by load_model).
Result<std::shared_ptr<Mesh>> load_obj(Context& ctx, const Bytes& bytes);
Result<std::shared_ptr<Mesh>> load_gltf(Context& ctx, const Bytes& bytes, bool binary);

}  // namespace arwb::media::model
