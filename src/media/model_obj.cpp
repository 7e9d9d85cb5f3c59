// Wavefront OBJ through tinyobjloader, and the material libraries (.mtl) it names (mtllib), read by our rules.
// The library trusts the file's indices, so every face's indices are checked here, with the face's line, before
// anything is built from them.
#include "media/model_loader.hpp"

#include "base/files.hpp"
#include "media/media_path.hpp"

#include <tiny_obj_loader.h>

#include <cstdint>
#include <map>
#include <span>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace arwb::media::model {

namespace {

// Reads the .mtl files an OBJ names (mtllib) by our rules: inside the scene's folder, relative to the model's.
// A missing library is a warning (the model keeps white); one that breaks the rules refuses the model.
class MaterialLibraries final : public tinyobj::MaterialReader {
 public:
  explicit MaterialLibraries(Context& ctx) : ctx_(ctx) {}
  std::string error;

  bool operator()(const std::string& written, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* by_name, std::string* warn, std::string* err) override {
    if (!error.empty()) return false;
    const ResolvedFile file = resolve_scene_file(ctx_.scene_dir, written, ctx_.folder);
    if (!file.ok()) {
      if (file.error.ends_with(": no such file"))
        ctx_.warnings.push_back(ctx_.name + ": mtllib " + file.error);
      else
        error = ctx_.name + ": mtllib " + file.error;
      return false;
    }
    Result<Bytes> bytes = read_limited(file.path, shown_name(written), ctx_.limits.file_bytes);
    if (!bytes) {
      error = ctx_.name + ": mtllib " + bytes.error();
      return false;
    }
    std::istringstream in(std::string(bytes->begin(), bytes->end()));
    tinyobj::LoadMtl(by_name, materials, &in, warn, err);
    return true;
  }

 private:
  Context& ctx_;
};

// The face statements ("f ..."), read from the text before tinyobjloader parses it: the line of each, in order,
// so that a bad index can be reported where it was written (tinyobjloader keeps faces in file order but not their
// lines), and the triangles they make (a face of n corners is n - 2), so that the limit is checked before the
// parse (a 60 MB file of 7.5 million faces cost 52 s and 1.5 GB before it was refused).
struct FaceScan {
  std::vector<size_t> lines;
  size_t triangles = 0;
};
FaceScan scan_faces(std::string_view text) {
  FaceScan scan;
  size_t line = 1;
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  for (size_t at = 0; at < text.size();) {
    size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    std::string_view l = text.substr(at, end - at);
    const size_t s = l.find_first_not_of(" \t");
    if (s != std::string_view::npos && l[s] == 'f' && s + 1 < l.size() && (l[s + 1] == ' ' || l[s + 1] == '\t')) {
      scan.lines.push_back(line);
      size_t corners = 0;
      for (size_t i = s + 1; i < l.size(); ++i)
        if (!blank(l[i]) && blank(l[i - 1])) ++corners;
      if (corners >= 3) scan.triangles += corners - 2;
    }
    at = end + 1;
    ++line;
  }
  return scan;
}

struct CornerKey {
  int v, vt, vn;
  bool operator==(const CornerKey&) const = default;
};
struct CornerHash {
  size_t operator()(const CornerKey& k) const {
    return std::hash<uint64_t>()((static_cast<uint64_t>(static_cast<uint32_t>(k.v)) << 32) ^
                                 (static_cast<uint64_t>(static_cast<uint32_t>(k.vt)) << 16) ^
                                 static_cast<uint32_t>(k.vn));
  }
};

}  // namespace

Result<std::shared_ptr<Mesh>> load_obj(Context& ctx, const Bytes& bytes) {
  const std::string text(bytes.begin(), bytes.end());
  const FaceScan scan = scan_faces(text);
  if (scan.triangles > ctx.limits.triangles)
    return fail(ctx.name + ": " + std::to_string(scan.triangles) + " triangles, more than the limit of " +
                std::to_string(ctx.limits.triangles));
  std::istringstream in(text);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  MaterialLibraries libraries(ctx);
  // Not triangulated by the library: we fan polygons ourselves after checking their indices, so a bad index is
  // reported with its line rather than read.
  bool ok = false;
  try {
    ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &libraries,
                          /*triangulate=*/false, /*default_vcols_fallback=*/false);
  } catch (const std::exception&) {  // memory, mostly: the file's size was checked, the library's use of it not
    return fail(ctx.name + ": cannot be read as OBJ");
  }
  if (!libraries.error.empty()) return fail(libraries.error);
  if (!ok) return fail(ctx.name + ": " + (err.empty() ? std::string("cannot be read as OBJ") : first_line(err)));

  const size_t nv = attrib.vertices.size() / 3, nn = attrib.normals.size() / 3, nt = attrib.texcoords.size() / 2;
  // Counts first, before anything is built.
  size_t triangles = 0, faces = 0;
  for (const tinyobj::shape_t& s : shapes)
    for (const unsigned char n : s.mesh.num_face_vertices) {
      ++faces;
      if (n >= 3) triangles += n - 2u;
    }
  if (triangles > ctx.limits.triangles)   // as counted before the parse, unless the library read faces otherwise
    return fail(ctx.name + ": " + std::to_string(triangles) + " triangles, more than the limit of " +
                std::to_string(ctx.limits.triangles));
  const std::vector<size_t>& lines = scan.lines;
  const bool lines_known = lines.size() == faces;  // else a face was dropped on the way: no line numbers

  auto mesh = std::make_shared<Mesh>();
  std::map<int, size_t> part_of_material;  // material id (-1: none) to index in mesh->parts
  std::vector<std::unordered_map<CornerKey, uint32_t, CornerHash>> corners;
  std::vector<bool> missing_normals, missing_uvs;
  size_t vertices = 0, face = 0;

  for (const tinyobj::shape_t& shape : shapes) {
    size_t first = 0;
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f, ++face) {
      const size_t n = shape.mesh.num_face_vertices[f];
      const std::span<const tinyobj::index_t> face_corners(shape.mesh.indices.data() + first, n);
      first += n;
      const std::string where = ctx.name + (lines_known ? ":" + std::to_string(lines[face]) : std::string()) + ": ";
      for (const tinyobj::index_t& c : face_corners) {
        if (c.vertex_index < 0 || static_cast<size_t>(c.vertex_index) >= nv)
          return fail(where + "face index " + std::to_string(static_cast<long long>(c.vertex_index) + 1) +
                      " out of range (" + std::to_string(nv) + " vertices)");
        if (c.normal_index >= 0 && static_cast<size_t>(c.normal_index) >= nn)
          return fail(where + "normal index " + std::to_string(static_cast<long long>(c.normal_index) + 1) +
                      " out of range (" + std::to_string(nn) + " normals)");
        if (c.texcoord_index >= 0 && static_cast<size_t>(c.texcoord_index) >= nt)
          return fail(where + "texture coordinate index " +
                      std::to_string(static_cast<long long>(c.texcoord_index) + 1) + " out of range (" +
                      std::to_string(nt) + " texture coordinates)");
      }
      if (n < 3) continue;

      int material = f < shape.mesh.material_ids.size() ? shape.mesh.material_ids[f] : -1;
      if (material < 0 || static_cast<size_t>(material) >= materials.size()) material = -1;
      auto [it, added] = part_of_material.try_emplace(material, mesh->parts.size());
      if (added) {
        MeshPart part;
        part.name = material < 0 ? "default" : materials[static_cast<size_t>(material)].name;
        mesh->parts.push_back(std::move(part));
        corners.emplace_back();
        missing_normals.push_back(false);
        missing_uvs.push_back(false);
      }
      const size_t p = it->second;
      MeshPart& part = mesh->parts[p];

      // Each distinct v/vt/vn triple becomes one vertex of the part.
      std::vector<uint32_t> index(n);
      for (size_t k = 0; k < n; ++k) {
        const tinyobj::index_t& c = face_corners[k];
        const CornerKey key{c.vertex_index, c.texcoord_index, c.normal_index};
        auto [slot, fresh] = corners[p].try_emplace(key, static_cast<uint32_t>(part.positions.size()));
        if (fresh) {
          if (++vertices > ctx.limits.vertices)
            return fail(ctx.name + ": more than the limit of " + std::to_string(ctx.limits.vertices) + " vertices");
          const auto v = static_cast<size_t>(c.vertex_index) * 3;
          part.positions.emplace_back(static_cast<float>(attrib.vertices[v]),
                                      static_cast<float>(attrib.vertices[v + 1]),
                                      static_cast<float>(attrib.vertices[v + 2]));
          if (c.normal_index >= 0) {
            const auto i = static_cast<size_t>(c.normal_index) * 3;
            part.normals.emplace_back(static_cast<float>(attrib.normals[i]), static_cast<float>(attrib.normals[i + 1]),
                                      static_cast<float>(attrib.normals[i + 2]));
          } else {
            missing_normals[p] = true;
            part.normals.emplace_back(0.f, 0.f, 0.f);
          }
          if (c.texcoord_index >= 0) {
            const auto i = static_cast<size_t>(c.texcoord_index) * 2;
            // OBJ's v runs up the image; ours runs down from the top-left.
            part.uvs.emplace_back(static_cast<float>(attrib.texcoords[i]),
                                  static_cast<float>(1.0 - attrib.texcoords[i + 1]));
          } else {
            missing_uvs[p] = true;
            part.uvs.emplace_back(0.f, 0.f);
          }
        }
        index[k] = slot->second;
      }
      // Polygons are fanned from their first corner: (0,1,2), (0,2,3), ...
      for (size_t k = 1; k + 1 < n; ++k) {
        part.indices.push_back(index[0]);
        part.indices.push_back(index[k]);
        part.indices.push_back(index[k + 1]);
      }
    }
  }

  for (const auto& [material, p] : part_of_material) {
    MeshPart& part = mesh->parts[p];
    // Normals and texture coordinates are all or nothing within a part.
    if (missing_normals[p]) part.normals.clear();
    if (missing_uvs[p]) part.uvs.clear();
    normalise_normals(part);
    if (material < 0) continue;
    const tinyobj::material_t& m = materials[static_cast<size_t>(material)];
    part.colour = bgra(m.diffuse[0], m.diffuse[1], m.diffuse[2], m.dissolve);
    if (!m.diffuse_texname.empty()) {
      Result<std::shared_ptr<MediaContent>> texture =
          ctx.external_texture(m.diffuse_texname, "material '" + shown_name(m.name) + "' map_Kd");
      if (!texture) return fail(texture.error());
      part.texture = *texture;
      drop_texture_without_uvs(ctx, part);
    }
  }
  return mesh;
}

}  // namespace arwb::media::model
