// load_model: the format told by the model's bytes, read by its loader (model_obj.cpp, model_gltf.cpp), and the
// mesh checked against the limits once more, its empty parts dropped and its bounds computed.
#include "media/model_file.hpp"

#include "base/files.hpp"
#include "media/media_path.hpp"
#include "media/model_loader.hpp"

#include <cstring>
#include <set>
#include <string_view>

namespace fs = std::filesystem;

namespace arwb::media {

namespace {

using model::Bytes;

std::string join(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) {
    if (!out.empty()) out += "; ";
    out += l;
  }
  return out;
}

// The format by its bytes, never by the name (model_file.hpp).
enum class Format { obj, gltf, glb, unknown };

bool is_obj_statement(std::string_view word) {
  static const std::set<std::string_view> kStatements = {"v", "vt", "vn", "vp",     "f",      "l", "p",
                                                         "o", "g",  "s",  "usemtl", "mtllib", "#"};
  if (word.starts_with('#')) return true;
  return kStatements.contains(word);
}

Format recognise(const Bytes& bytes) {
  if (bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0) return Format::glb;
  std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
  // Binary files (images, archives) have NUL bytes early; text has none.
  if (text.substr(0, 4096).find('\0') != std::string_view::npos) return Format::unknown;
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return Format::unknown;
  if (text[first] == '{') return Format::gltf;  // whether it has an "asset" is decided once it is parsed
  // OBJ: the first line that says anything is an OBJ statement.
  const std::string_view line = text.substr(first, text.find_first_of("\r\n", first) - first);
  return is_obj_statement(line.substr(0, line.find_first_of(" \t"))) ? Format::obj : Format::unknown;
}

}  // namespace

Result<std::shared_ptr<Mesh>> load_model(const fs::path& scene_dir, const std::string& relative,
                                         const ModelLimits& limits, std::string* warning) {
  if (warning) warning->clear();
  model::Context ctx;
  ctx.scene_dir = scene_dir;
  ctx.relative = relative;
  ctx.name = shown_name(relative);
  ctx.limits = limits;

  const ResolvedFile file = resolve_scene_file(scene_dir, relative);
  if (!file.ok()) return fail(file.error);
  // The model's references are relative to its folder as written; resolve_scene_file keeps them inside the scene.
  ctx.folder = fs::path(relative).parent_path();
  Result<Bytes> bytes = model::read_limited(file.path, ctx.name, limits.file_bytes);
  if (!bytes) return fail(bytes.error());

  Result<std::shared_ptr<Mesh>> mesh = fail("");
  switch (recognise(*bytes)) {
    case Format::obj:
      mesh = model::load_obj(ctx, *bytes);
      break;
    case Format::gltf:
      mesh = model::load_gltf(ctx, *bytes, false);
      break;
    case Format::glb:
      mesh = model::load_gltf(ctx, *bytes, true);
      break;
    case Format::unknown:
      if (bytes->empty()) return fail(ctx.name + ": empty file (0 bytes)");
      return fail(ctx.name + ": not a 3D model (OBJ, glTF or GLB)");
  }
  if (!mesh) return mesh;
  Mesh& m = **mesh;
  std::erase_if(m.parts, [](const MeshPart& p) { return p.indices.empty(); });
  if (m.triangle_count() == 0) return fail(ctx.name + ": no triangles");
  if (m.triangle_count() > limits.triangles)
    return fail(ctx.name + ": " + std::to_string(m.triangle_count()) + " triangles, more than the limit of " +
                std::to_string(limits.triangles));
  if (m.vertex_count() > limits.vertices)
    return fail(ctx.name + ": " + std::to_string(m.vertex_count()) + " vertices, more than the limit of " +
                std::to_string(limits.vertices));
  m.source = relative;
  m.compute_bounds();
  if (const std::string problem = m.validate(); !problem.empty()) return fail(ctx.name + ": " + problem);
  if (warning) *warning = join(ctx.warnings);
  return mesh;
}

}  // namespace arwb::media
