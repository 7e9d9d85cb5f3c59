// glTF 2.0 and GLB through tinygltf, fenced in by our own checks: the JSON is read first by nlohmann (every file
// it names must pass our rules, every image's buffer view must lie inside its buffer), tinygltf asks for files
// and images through callbacks of ours, and every accessor's extent and every index is checked here before it
// is used, since the library trusts them.
#include "media/model_loader.hpp"

#include "base/files.hpp"
#include "base/json_depth.hpp"
#include "media/media_path.hpp"

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string_view>
#include <vector>

namespace fs = std::filesystem;

namespace arwb::media::model {

namespace {

// "%20" and friends in a uri, as tinygltf decodes them before it asks for the file.
std::string percent_decoded(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    const auto hex = [](char c) -> int {
      if (c >= '0' && c <= '9') return c - '0';
      if (c >= 'a' && c <= 'f') return c - 'a' + 10;
      if (c >= 'A' && c <= 'F') return c - 'A' + 10;
      return -1;
    };
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out += static_cast<char>(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

// tinygltf asks for files as JoinPath(base_dir, uri) and then, failing that, "./" + uri. Our base_dir is this
// marker, so a request without it (the second try, relative to the process's folder) is refused, and the rest is
// resolved by our rules relative to the model's folder.
constexpr std::string_view kBaseMarker = "\x01model-folder\x01";

struct GltfFiles {
  Context* ctx = nullptr;
};

std::optional<std::string> requested_uri(const std::string& path) {
  const std::string prefix = std::string(kBaseMarker) + "/";
  if (!path.starts_with(prefix)) return std::nullopt;
  return path.substr(prefix.size());
}

bool gltf_file_exists(const std::string& path, void* user) {
  auto* files = static_cast<GltfFiles*>(user);
  const std::optional<std::string> uri = requested_uri(path);
  return uri && resolve_scene_file(files->ctx->scene_dir, *uri, files->ctx->folder).ok();
}

std::string gltf_expand_path(const std::string& path, void*) { return path; }  // no "~" or variables

bool gltf_read_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto* files = static_cast<GltfFiles*>(user);
  const std::optional<std::string> uri = requested_uri(path);
  if (!uri) return false;
  const ResolvedFile file = resolve_scene_file(files->ctx->scene_dir, *uri, files->ctx->folder);
  if (!file.ok()) {
    if (err) *err = file.error;
    return false;
  }
  // A buffer beyond the limit was refused by precheck_gltf_json; an image beyond it is a warning there, and this
  // refusal leaves its material's colour.
  Result<Bytes> bytes = read_limited(file.path, shown_name(*uri), files->ctx->limits.file_bytes);
  if (!bytes) {
    if (err) *err = bytes.error();
    return false;
  }
  *out = std::move(*bytes);
  return true;
}

bool gltf_write_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not allowed";
  return false;
}

// Images arrive here as bytes (embedded, in a buffer view, or read through gltf_read_file) and are decoded by
// ours, not by stb; the pixels wait in `decoded` by image index.
struct GltfImages {
  Context* ctx = nullptr;
  std::map<int, std::shared_ptr<MediaContent>> decoded;
};

bool gltf_load_image(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                     const unsigned char* bytes, int size, void* user) {
  auto* images = static_cast<GltfImages*>(user);
  const std::string what = "image " + std::to_string(index);
  const std::string shown = image && !image->uri.empty() ? shown_name(image->uri) : what;
  if (!bytes || size <= 0) {
    images->ctx->warnings.push_back(images->ctx->name + ": " + what + ": no data");
    return true;  // the model stays; the material keeps its colour
  }
  images->decoded[index] =
      images->ctx->decode_texture(std::span<const uint8_t>(bytes, static_cast<size_t>(size)), shown, what);
  return true;
}

// Before tinygltf sees the JSON: it must nest no deeper than kMaxJsonDepth (tinygltf copies `extras` into its own
// values recursively: 20,000 nested arrays overflowed the stack), be a glTF (an object with "asset"), and every file
// it names must pass our rules, so that the message can say which buffer or image and why.
Status precheck_gltf_json(Context& ctx, std::string_view json_text) {
  if (Status depth = check_json_depth(json_text, ctx.name); !depth) return depth;
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::parse_error& e) {
    return fail(ctx.name + ": invalid JSON at byte " + std::to_string(e.byte));
  } catch (const nlohmann::json::exception& e) {
    // Valid syntax the parser still refuses: a number beyond a double ("1e999"), found by fuzz/model_file.
    std::string reason = e.what();
    if (const size_t end = reason.find("] "); reason.starts_with('[') && end != std::string::npos)
      reason = reason.substr(end + 2);
    return fail(ctx.name + ": invalid JSON (" + shown_name(reason) + ")");
  }
  if (!doc.is_object() || !doc.contains("asset")) return fail(ctx.name + ": not a 3D model (OBJ, glTF or GLB)");
  const auto uris = [&](const char* array, const char* what) -> Status {
    const auto it = doc.find(array);
    if (it == doc.end() || !it->is_array()) return {};
    for (size_t i = 0; i < it->size(); ++i) {
      const nlohmann::json& item = (*it)[i];
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      const std::string uri = item["uri"].get<std::string>();
      if (uri.starts_with("data:")) continue;
      const ResolvedFile file = resolve_scene_file(ctx.scene_dir, percent_decoded(uri), ctx.folder);
      const std::string prefix = ctx.name + ": " + what + " " + std::to_string(i) + ": ";
      const bool buffer = std::string_view(what) == "buffer";
      if (file.ok()) {
        std::error_code ec;
        const auto size = fs::file_size(file.path, ec);
        if (ec) continue;  // gone since: tinygltf's read will say so
        if (size > ctx.limits.file_bytes) {
          const std::string message = prefix + shown_name(uri) + ": " + size_text(size) + ", more than the limit of " +
                                      size_text(ctx.limits.file_bytes);
          if (!buffer) {
            ctx.warnings.push_back(message);
            continue;
          }
          return fail(message);
        }
        // tinygltf wants a buffer's file exactly as long as its byteLength; say so in our words first.
        const auto length = item.find("byteLength");
        if (buffer && length != item.end() && length->is_number_unsigned() && length->get<uint64_t>() != size)
          return fail(prefix + shown_name(uri) + ": " + size_text(size) + ", its byteLength says " +
                      std::to_string(length->get<uint64_t>()));
        continue;
      }
      const std::string message = prefix + file.error;
      // A missing image leaves its material's colour; a missing buffer leaves nothing to draw.
      if (!buffer && file.error.ends_with(": no such file"))
        ctx.warnings.push_back(message);
      else
        return fail(message);
    }
    return {};
  };
  if (Status s = uris("buffers", "buffer"); !s) return s;
  // tinygltf hands an image's buffer view to the image loader without checking that the view lies inside its
  // buffer (tinygltf 2.7, LoadFromString): checked here against the buffers' declared lengths, which tinygltf
  // does hold the data to (a file or data URI of exactly that length; a GLB chunk at least that long).
  if (const auto images = doc.find("images"); images != doc.end() && images->is_array()) {
    const auto unsigned_at = [](const nlohmann::json& o, const char* key,
                                uint64_t fallback) -> std::optional<uint64_t> {
      const auto it = o.find(key);
      if (it == o.end()) return fallback;
      if (!it->is_number_unsigned()) return std::nullopt;
      return it->get<uint64_t>();
    };
    const nlohmann::json* views =
        doc.contains("bufferViews") && doc["bufferViews"].is_array() ? &doc["bufferViews"] : nullptr;
    const nlohmann::json* buffers = doc.contains("buffers") && doc["buffers"].is_array() ? &doc["buffers"] : nullptr;
    for (size_t i = 0; i < images->size(); ++i) {
      const nlohmann::json& image = (*images)[i];
      if (!image.is_object() || !image.contains("bufferView")) continue;
      const std::string where = ctx.name + ": image " + std::to_string(i) + ": ";
      const std::optional<uint64_t> v = unsigned_at(image, "bufferView", 0);
      if (!v || !views || *v >= views->size() || !(*views)[*v].is_object())
        return fail(where + "its buffer view does not exist");
      const nlohmann::json& view = (*views)[*v];
      const std::optional<uint64_t> b = unsigned_at(view, "buffer", std::numeric_limits<uint64_t>::max());
      const std::optional<uint64_t> offset = unsigned_at(view, "byteOffset", 0);
      const std::optional<uint64_t> length = unsigned_at(view, "byteLength", 0);
      if (!b || !buffers || *b >= buffers->size() || !(*buffers)[*b].is_object())
        return fail(where + "buffer view " + std::to_string(*v) + " names no buffer");
      const std::optional<uint64_t> buffer_length = unsigned_at((*buffers)[*b], "byteLength", 0);
      if (!offset || !length || !buffer_length || *length == 0 || *offset > *buffer_length ||
          *length > *buffer_length - *offset)
        return fail(where + "buffer view " + std::to_string(*v) + " reaches past the end of its buffer");
    }
  }
  if (Status s = uris("images", "image"); !s) return s;
  if (const auto it = doc.find("images");
      it != doc.end() && it->is_array() && it->size() > static_cast<size_t>(ctx.limits.textures))
    return fail(ctx.name + ": " + std::to_string(it->size()) + " images, more than the limit of " +
                std::to_string(ctx.limits.textures) + " textures");
  return {};
}

// The JSON chunk of a GLB, after checking the header against the bytes really there.
Result<std::string_view> glb_json(const Context& ctx, const Bytes& bytes) {
  const auto u32 = [&](size_t at) {
    return static_cast<uint32_t>(bytes[at]) | static_cast<uint32_t>(bytes[at + 1]) << 8 |
           static_cast<uint32_t>(bytes[at + 2]) << 16 | static_cast<uint32_t>(bytes[at + 3]) << 24;
  };
  if (bytes.size() < 20) return fail(ctx.name + ": truncated GLB (" + std::to_string(bytes.size()) + " bytes)");
  if (u32(4) != 2) return fail(ctx.name + ": GLB version " + std::to_string(u32(4)) + ", only 2 is read");
  const uint32_t length = u32(8);
  if (length > bytes.size())
    return fail(ctx.name + ": truncated GLB (the header says " + std::to_string(length) + " bytes, the file has " +
                std::to_string(bytes.size()) + ")");
  const uint32_t json_length = u32(12);
  if (std::memcmp(bytes.data() + 16, "JSON", 4) != 0) return fail(ctx.name + ": GLB without a JSON chunk first");
  if (json_length > length - 20)
    return fail(ctx.name + ": truncated GLB (its JSON chunk of " + std::to_string(json_length) +
                " bytes goes past the end)");
  return std::string_view(reinterpret_cast<const char*>(bytes.data()) + 20, json_length);
}

// One accessor's elements as doubles, `width` per element, after checking that every byte it names lies
// inside its buffer. Integer components are normalised when the accessor says so.
Status read_accessor(const Context& ctx, const tinygltf::Model& model, int index, int type, std::size_t max_count,
                     const std::string& what, std::vector<double>* out, std::size_t* count) {
  const std::string where = ctx.name + ": " + what + ": ";
  if (index < 0 || static_cast<size_t>(index) >= model.accessors.size())
    return fail(where + "accessor " + std::to_string(index) + " does not exist");
  const tinygltf::Accessor& a = model.accessors[static_cast<size_t>(index)];
  if (a.sparse.isSparse) return fail(where + "sparse accessors are not read");
  if (a.type != type) return fail(where + "accessor " + std::to_string(index) + " has the wrong type");
  const int csize = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(a.componentType));
  if (csize <= 0 || a.componentType == TINYGLTF_COMPONENT_TYPE_DOUBLE)
    return fail(where + "accessor " + std::to_string(index) + " has an unknown component type");
  if (a.count > max_count)
    return fail(where + std::to_string(a.count) + " elements, more than the limit of " + std::to_string(max_count));
  if (a.bufferView < 0 || static_cast<size_t>(a.bufferView) >= model.bufferViews.size())
    return fail(where + "accessor " + std::to_string(index) + " has no buffer view");
  const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(a.bufferView)];
  if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model.buffers.size())
    return fail(where + "buffer view " + std::to_string(a.bufferView) + " names no buffer");
  const Bytes& data = model.buffers[static_cast<size_t>(view.buffer)].data;
  const auto width = static_cast<size_t>(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(type)));
  const size_t element = width * static_cast<size_t>(csize);
  const size_t stride = view.byteStride ? view.byteStride : element;
  // Every bound in 64 bits against numbers the file chose: no sum may wrap.
  const auto too_far = [&] {
    return fail(where + "accessor " + std::to_string(index) + " reaches past the end of its buffer");
  };
  if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) return too_far();
  if (stride < element) return fail(where + "buffer view " + std::to_string(a.bufferView) + " has a stride too small");
  if (a.count > 0) {
    if (a.byteOffset > view.byteLength) return too_far();
    const size_t room = view.byteLength - a.byteOffset;
    if (element > room || (a.count - 1) > (room - element) / stride) return too_far();
  }
  out->resize(a.count * width);
  const uint8_t* base = data.data() + view.byteOffset + a.byteOffset;
  for (size_t i = 0; i < a.count; ++i)
    for (size_t k = 0; k < width; ++k) {
      const uint8_t* p = base + i * stride + k * static_cast<size_t>(csize);
      double v = 0;
      switch (a.componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
          float f;
          std::memcpy(&f, p, 4);
          v = f;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
          int8_t x;
          std::memcpy(&x, p, 1);
          v = a.normalized ? std::max(x / 127.0, -1.0) : x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          v = a.normalized ? *p / 255.0 : *p;
          break;
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
          int16_t x;
          std::memcpy(&x, p, 2);
          v = a.normalized ? std::max(x / 32767.0, -1.0) : x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          uint16_t x;
          std::memcpy(&x, p, 2);
          v = a.normalized ? x / 65535.0 : x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_INT: {
          int32_t x;
          std::memcpy(&x, p, 4);
          v = x;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
          uint32_t x;
          std::memcpy(&x, p, 4);
          v = x;
          break;
        }
        default:
          break;
      }
      (*out)[i * width + k] = v;
    }
  *count = a.count;
  return {};
}

cv::Matx44d node_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    cv::Matx44d m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m(r, c) = node.matrix[static_cast<size_t>(c * 4 + r)];  // column-major
    return m;
  }
  cv::Matx44d t = cv::Matx44d::eye(), r = cv::Matx44d::eye(), s = cv::Matx44d::eye();
  if (node.translation.size() == 3)
    for (int i = 0; i < 3; ++i) t(i, 3) = node.translation[static_cast<size_t>(i)];
  if (node.rotation.size() == 4) {  // quaternion x, y, z, w
    double x = node.rotation[0], y = node.rotation[1], z = node.rotation[2], w = node.rotation[3];
    const double len = std::sqrt(x * x + y * y + z * z + w * w);
    if (std::isfinite(len) && len > 0) {
      x /= len, y /= len, z /= len, w /= len;
      r = cv::Matx44d(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), 0, 2 * (x * y + z * w),
                      1 - 2 * (x * x + z * z), 2 * (y * z - x * w), 0, 2 * (x * z - y * w), 2 * (y * z + x * w),
                      1 - 2 * (x * x + y * y), 0, 0, 0, 0, 1);
    }
  }
  if (node.scale.size() == 3)
    for (int i = 0; i < 3; ++i) s(i, i) = node.scale[static_cast<size_t>(i)];
  return t * r * s;
}

struct GltfBuild {
  std::map<int, size_t> part_of_material;  // material index (-1: none) to index in mesh->parts
  std::vector<bool> missing_normals, missing_uvs;
  std::set<int> skipped_modes;
  size_t vertices = 0, triangles = 0;
};

Status add_primitive(Context& ctx, const tinygltf::Model& model, const tinygltf::Primitive& prim,
                     const std::string& what, const cv::Matx44d& transform, Mesh& mesh, GltfBuild& build) {
  const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode != TINYGLTF_MODE_TRIANGLES) {
    build.skipped_modes.insert(mode);
    return {};
  }
  const auto position = prim.attributes.find("POSITION");
  if (position == prim.attributes.end()) return fail(ctx.name + ": " + what + ": no POSITION");
  std::vector<double> pos, nrm, uv, idx;
  size_t count = 0, n = 0;
  // The limits are checked on the accessors' counts, before anything is copied.
  const auto declared = [&](int accessor) -> size_t {
    return accessor >= 0 && static_cast<size_t>(accessor) < model.accessors.size()
               ? model.accessors[static_cast<size_t>(accessor)].count
               : 0;
  };
  if (declared(position->second) > ctx.limits.vertices - std::min(ctx.limits.vertices, build.vertices))
    return fail(ctx.name + ": " + std::to_string(build.vertices + declared(position->second)) +
                " vertices, more than the limit of " + std::to_string(ctx.limits.vertices));
  const size_t triangle_room = ctx.limits.triangles - std::min(ctx.limits.triangles, build.triangles);
  const size_t corners = prim.indices >= 0 ? declared(prim.indices) : declared(position->second);
  if (corners / 3 > triangle_room)
    return fail(ctx.name + ": " + std::to_string(build.triangles + corners / 3) +
                " triangles, more than the limit of " + std::to_string(ctx.limits.triangles));
  if (Status s = read_accessor(ctx, model, position->second, TINYGLTF_TYPE_VEC3, ctx.limits.vertices,
                               what + " POSITION", &pos, &count);
      !s)
    return s;
  bool has_normals = false, has_uvs = false;
  if (const auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
    if (Status s = read_accessor(ctx, model, it->second, TINYGLTF_TYPE_VEC3, count, what + " NORMAL", &nrm, &n); !s)
      return s;
    if (n != count)
      return fail(ctx.name + ": " + what + ": NORMAL has " + std::to_string(n) + " elements, POSITION " +
                  std::to_string(count));
    has_normals = true;
  }
  if (const auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
    if (Status s = read_accessor(ctx, model, it->second, TINYGLTF_TYPE_VEC2, count, what + " TEXCOORD_0", &uv, &n); !s)
      return s;
    if (n != count)
      return fail(ctx.name + ": " + what + ": TEXCOORD_0 has " + std::to_string(n) + " elements, POSITION " +
                  std::to_string(count));
    has_uvs = true;
  }
  if (prim.indices >= 0) {
    if (Status s = read_accessor(ctx, model, prim.indices, TINYGLTF_TYPE_SCALAR, triangle_room * 3 + 2,
                                 what + " indices", &idx, &n);
        !s)
      return s;
    const int ct = model.accessors[static_cast<size_t>(prim.indices)].componentType;
    if (ct == TINYGLTF_COMPONENT_TYPE_FLOAT) return fail(ctx.name + ": " + what + ": indices are not integers");
  } else {
    idx.resize(count);
    for (size_t i = 0; i < count; ++i) idx[i] = static_cast<double>(i);
  }
  if (idx.size() % 3 != 0) {
    ctx.warnings.push_back(ctx.name + ": " + what + ": " + std::to_string(idx.size()) +
                           " indices, not a multiple of three; the last are ignored");
    idx.resize(idx.size() - idx.size() % 3);
  }
  for (const double i : idx)
    if (i < 0 || i >= static_cast<double>(count))
      return fail(ctx.name + ": " + what + ": index " + std::to_string(static_cast<long long>(i)) + " out of range (" +
                  std::to_string(count) + " vertices)");

  const int material =
      prim.material >= 0 && static_cast<size_t>(prim.material) < model.materials.size() ? prim.material : -1;
  auto [it, added] = build.part_of_material.try_emplace(material, mesh.parts.size());
  if (added) {
    MeshPart part;
    part.name = material < 0 ? "default" : model.materials[static_cast<size_t>(material)].name;
    if (part.name.empty()) part.name = material < 0 ? "default" : "material " + std::to_string(material);
    mesh.parts.push_back(std::move(part));
    build.missing_normals.push_back(false);
    build.missing_uvs.push_back(false);
  }
  const size_t p = it->second;
  MeshPart& part = mesh.parts[p];
  if (!has_normals) build.missing_normals[p] = true;
  if (!has_uvs) build.missing_uvs[p] = true;

  // Normals go through the inverse transpose of the transform's linear part; a mirroring transform turns
  // faces inside out, so their winding is reversed to keep them facing out.
  const cv::Matx33d linear(transform(0, 0), transform(0, 1), transform(0, 2), transform(1, 0), transform(1, 1),
                           transform(1, 2), transform(2, 0), transform(2, 1), transform(2, 2));
  const double det = cv::determinant(linear);
  const cv::Matx33d normal_matrix = std::abs(det) > 1e-300 ? cv::Matx33d(linear.inv().t()) : linear;
  const auto base = static_cast<uint32_t>(part.positions.size());
  for (size_t i = 0; i < count; ++i) {
    const cv::Vec4d q = transform * cv::Vec4d(pos[i * 3], pos[i * 3 + 1], pos[i * 3 + 2], 1.0);
    part.positions.emplace_back(static_cast<float>(q[0]), static_cast<float>(q[1]), static_cast<float>(q[2]));
    if (has_normals) {
      const cv::Vec3d m = normal_matrix * cv::Vec3d(nrm[i * 3], nrm[i * 3 + 1], nrm[i * 3 + 2]);
      part.normals.emplace_back(static_cast<float>(m[0]), static_cast<float>(m[1]), static_cast<float>(m[2]));
    } else {
      part.normals.emplace_back(0.f, 0.f, 0.f);
    }
    part.uvs.emplace_back(has_uvs ? cv::Vec2f(static_cast<float>(uv[i * 2]), static_cast<float>(uv[i * 2 + 1]))
                                  : cv::Vec2f(0.f, 0.f));
  }
  for (size_t t = 0; t < idx.size(); t += 3) {
    const auto a = static_cast<uint32_t>(idx[t]), b = static_cast<uint32_t>(idx[t + 1]),
               c = static_cast<uint32_t>(idx[t + 2]);
    part.indices.push_back(base + a);
    part.indices.push_back(base + (det < 0 ? c : b));
    part.indices.push_back(base + (det < 0 ? b : c));
  }
  build.vertices += count;
  build.triangles += idx.size() / 3;
  return {};
}
}  // namespace

Result<std::shared_ptr<Mesh>> load_gltf(Context& ctx, const Bytes& bytes, bool binary) {
  std::string_view json_text;
  if (binary) {
    Result<std::string_view> json = glb_json(ctx, bytes);
    if (!json) return fail(json.error());
    json_text = *json;
  } else {
    json_text = std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  }
  if (Status s = precheck_gltf_json(ctx, json_text); !s) return fail(s.error());

  tinygltf::TinyGLTF loader;
  GltfFiles files{&ctx};
  GltfImages images{&ctx, {}};
  loader.SetFsCallbacks(
      tinygltf::FsCallbacks{&gltf_file_exists, &gltf_expand_path, &gltf_read_file, &gltf_write_file, &files});
  loader.SetImageLoader(&gltf_load_image, &images);
  tinygltf::Model model;
  std::string err, warn;
  if (bytes.size() > std::numeric_limits<unsigned int>::max())
    return fail(ctx.name + ": " + size_text(bytes.size()) + ", too large");
  const std::string base_dir(kBaseMarker);
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                              static_cast<unsigned int>(bytes.size()), base_dir)
                : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                             static_cast<unsigned int>(bytes.size()), base_dir);
  } catch (const std::exception&) {  // the JSON was checked above; this is the library's own surprise
    return fail(ctx.name + ": cannot be read as glTF");
  }
  if (!ok) {
    // tinygltf names files as it asked for them, with our marker in front.
    for (size_t at; (at = err.find(std::string(kBaseMarker) + "/")) != std::string::npos;)
      err.erase(at, kBaseMarker.size() + 1);
    return fail(ctx.name + ": " + (err.empty() ? std::string("cannot be read as glTF") : first_line(err)));
  }

  // Which nodes to draw: the default scene's, else every root (a node no other node names as a child).
  std::vector<int> roots;
  if (model.defaultScene >= 0 && static_cast<size_t>(model.defaultScene) < model.scenes.size()) {
    roots = model.scenes[static_cast<size_t>(model.defaultScene)].nodes;
  } else {
    std::vector<bool> is_child(model.nodes.size(), false);
    for (const tinygltf::Node& node : model.nodes)
      for (const int c : node.children)
        if (c >= 0 && static_cast<size_t>(c) < model.nodes.size()) is_child[static_cast<size_t>(c)] = true;
    for (size_t i = 0; i < model.nodes.size(); ++i)
      if (!is_child[i]) roots.push_back(static_cast<int>(i));
  }

  auto mesh = std::make_shared<Mesh>();
  GltfBuild build;
  // Depth first without recursion (a chain of a million nodes must not overflow the stack); a node reached a
  // second time (a cycle, or two parents) is drawn once.
  std::vector<bool> visited(model.nodes.size(), false);
  std::vector<std::pair<int, cv::Matx44d>> stack;
  for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.emplace_back(*r, cv::Matx44d::eye());
  while (!stack.empty()) {
    const auto [index, parent] = stack.back();
    stack.pop_back();
    if (index < 0 || static_cast<size_t>(index) >= model.nodes.size() || visited[static_cast<size_t>(index)]) continue;
    visited[static_cast<size_t>(index)] = true;
    const tinygltf::Node& node = model.nodes[static_cast<size_t>(index)];
    const cv::Matx44d transform = parent * node_transform(node);
    if (node.mesh >= 0 && static_cast<size_t>(node.mesh) < model.meshes.size()) {
      const tinygltf::Mesh& m = model.meshes[static_cast<size_t>(node.mesh)];
      for (size_t i = 0; i < m.primitives.size(); ++i) {
        const std::string what = "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(i);
        if (Status s = add_primitive(ctx, model, m.primitives[i], what, transform, *mesh, build); !s)
          return fail(s.error());
      }
    }
    for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.emplace_back(*c, transform);
  }
  for (const int mode : build.skipped_modes)
    ctx.warnings.push_back(ctx.name + ": primitives of mode " + std::to_string(mode) +
                           " skipped (only triangles are drawn)");

  for (const auto& [material, p] : build.part_of_material) {
    MeshPart& part = mesh->parts[p];
    if (build.missing_normals[p]) part.normals.clear();
    if (build.missing_uvs[p]) part.uvs.clear();
    normalise_normals(part);
    if (material < 0) continue;
    const tinygltf::PbrMetallicRoughness& pbr = model.materials[static_cast<size_t>(material)].pbrMetallicRoughness;
    // baseColorFactor is linear RGBA; kept as it is, in 0..255 BGRA.
    if (pbr.baseColorFactor.size() == 4)
      part.colour =
          bgra(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
    const int texture = pbr.baseColorTexture.index;
    if (texture < 0) continue;
    if (pbr.baseColorTexture.texCoord != 0) {
      ctx.warnings.push_back(ctx.name + ": material '" + shown_name(part.name) + "': its texture uses TEXCOORD_" +
                             std::to_string(pbr.baseColorTexture.texCoord) + ", only TEXCOORD_0 is read");
      continue;
    }
    if (static_cast<size_t>(texture) >= model.textures.size()) continue;
    const int source = model.textures[static_cast<size_t>(texture)].source;
    if (const auto it = images.decoded.find(source); it != images.decoded.end()) part.texture = it->second;
    drop_texture_without_uvs(ctx, part);
  }
  return mesh;
}

}  // namespace arwb::media::model
