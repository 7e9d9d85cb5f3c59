// 3D models for scenes: Wavefront OBJ (with its .mtl and textures; Debian's tinyobjloader) and glTF 2.0 (.gltf
// with its .bin and images, or one .glb; Debian's tinygltf), read into a Mesh (track/mesh.hpp).
//
// Model files are shared files like any other media, so untrusted: the model and every file it refers to (a
// material library, a buffer, a texture) must resolve inside the scene's folder, by the same rules as images
// (media_path.hpp: no absolute path, no "..", no symbolic link leading out, regular files only). The format is
// recognised by its bytes, never by the name: "glTF" magic for .glb, a JSON object with an "asset" for .gltf,
// OBJ statements (v, vt, vn, f, o, g, usemtl, mtllib, #) for OBJ. Sizes are checked before anything large is
// read or allocated. Nothing here throws or crashes on a broken file; every failure is one message naming what
// the author wrote and the reason.
#pragma once

#include "track/mesh.hpp"
#include "base/result.hpp"

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>

namespace arwb::media {

struct ModelLimits {
  std::size_t file_bytes = 64u << 20;          // the model file, and each file it refers to
  std::size_t triangles = kMaxMeshTriangles;
  std::size_t vertices = kMaxMeshVertices;
  int textures = 32;                           // distinct texture images
};

// The model `relative` (as the scene wrote it) inside `scene_dir`: triangles (polygons are fanned), normals
// where the file has them, texture coordinates, and one MeshPart per material with its base colour (OBJ's Kd
// and d, glTF's baseColorFactor) and texture (map_Kd, baseColorTexture), the textures read as images are
// (media_path.hpp's checks and limits; a glTF's embedded images by their bytes). glTF nodes' transforms are
// applied (the default scene, or every root node when there is none). Bounds are computed.
// Errors, for example: "models/x.obj: no such file", "models/x.obj: leaves the scene's folder",
// "models/a.txt: not a 3D model (OBJ, glTF or GLB)", "models/big.glb: 80 MB, more than the limit of 64 MB",
// "models/x.obj:12: face index 40 out of range (30 vertices)", "models/x.gltf: buffer 0: x.bin: no such file",
// "models/x.gltf: no triangles", "models/x.obj: 3000000 triangles, more than the limit of 2000000".
// A texture that cannot be read does not refuse the model: its part keeps its colour and *warning says why.
Result<std::shared_ptr<Mesh>> load_model(const std::filesystem::path& scene_dir, const std::string& relative,
                                         const ModelLimits& limits = {}, std::string* warning = nullptr);

}  // namespace arwb::media
