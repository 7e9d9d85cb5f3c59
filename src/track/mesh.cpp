#include "track/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace arwb {

size_t Mesh::triangle_count() const {
  size_t n = 0;
  for (const MeshPart& p : parts) n += p.indices.size() / 3;
  return n;
}

size_t Mesh::vertex_count() const {
  size_t n = 0;
  for (const MeshPart& p : parts) n += p.positions.size();
  return n;
}

void Mesh::compute_bounds() {
  constexpr float inf = std::numeric_limits<float>::infinity();
  cv::Vec3f lo(inf, inf, inf), hi(-inf, -inf, -inf);
  for (const MeshPart& p : parts)
    for (const cv::Vec3f& v : p.positions)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], v[k]);
        hi[k] = std::max(hi[k], v[k]);
      }
  if (lo[0] > hi[0]) lo = hi = cv::Vec3f(0, 0, 0);
  min = lo;
  max = hi;
}

std::string Mesh::validate() const {
  for (const MeshPart& p : parts) {
    const std::string part = "part '" + p.name + "': ";
    const size_t n = p.positions.size();
    if (!p.normals.empty() && p.normals.size() != n)
      return part + std::to_string(p.normals.size()) + " normals for " + std::to_string(n) + " positions";
    if (!p.uvs.empty() && p.uvs.size() != n)
      return part + std::to_string(p.uvs.size()) + " texture coordinates for " + std::to_string(n) + " positions";
    if (p.indices.size() % 3 != 0)
      return part + std::to_string(p.indices.size()) + " indices, not a multiple of three";
    for (const uint32_t i : p.indices)
      if (i >= n) return part + "index " + std::to_string(i) + " out of range (" + std::to_string(n) + " positions)";
    for (const cv::Vec3f& v : p.positions)
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) return part + "a position is not finite";
    for (const cv::Vec3f& v : p.normals)
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) return part + "a normal is not finite";
    for (const cv::Vec2f& v : p.uvs)
      if (!std::isfinite(v[0]) || !std::isfinite(v[1])) return part + "a texture coordinate is not finite";
  }
  return {};
}

}  // namespace arwb
