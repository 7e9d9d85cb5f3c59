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

namespace arwb {
namespace {

// One face of the unit cube as a grid: `origin` its top-left as seen from outside, `right` and `down` its edges
// (unit length), the outward normal. uv (0,0) at the origin.
void add_face(MeshPart* p, cv::Vec3f origin, cv::Vec3f right, cv::Vec3f down, cv::Vec3f normal, int n) {
  const uint32_t base = static_cast<uint32_t>(p->positions.size());
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float u = float(i) / float(n), v = float(j) / float(n);
      p->positions.push_back(origin + right * u + down * v);
      p->normals.push_back(normal);
      p->uvs.push_back({u, v});
    }
  const uint32_t row = static_cast<uint32_t>(n + 1);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = base + uint32_t(j) * row + uint32_t(i), b = a + 1, c = a + row, d = c + 1;
      p->indices.insert(p->indices.end(), {a, c, b, b, c, d});
    }
}

// A box between lo and hi, flat normals, one part.
void add_box(MeshPart* p, cv::Vec3f lo, cv::Vec3f hi) {
  const cv::Vec3f d = hi - lo;
  const cv::Vec3f X(d[0], 0, 0), Y(0, d[1], 0), Z(0, 0, d[2]);
  auto face = [&](cv::Vec3f o, cv::Vec3f r, cv::Vec3f dn, cv::Vec3f nrm) {
    const uint32_t b = static_cast<uint32_t>(p->positions.size());
    for (const cv::Vec3f& q : {o, o + r, o + dn, o + r + dn}) {
      p->positions.push_back(q);
      p->normals.push_back(nrm);
    }
    p->indices.insert(p->indices.end(), {b, b + 2, b + 1, b + 1, b + 2, b + 3});
  };
  face(lo + X + Z, Y, -Z, {1, 0, 0});
  face(lo + Y + Z, -Y, -Z, {-1, 0, 0});
  face(lo + X + Y + Z, -X, -Z, {0, 1, 0});
  face(lo + Z, X, -Z, {0, -1, 0});
  face(lo + Y + Z, X, -Y, {0, 0, 1});
  face(lo, X, Y, {0, 0, -1});
}

cv::Matx44d rotation4(cv::Vec3d deg) {
  const double k = CV_PI / 180;
  const double ax = deg[0] * k, ay = deg[1] * k, az = deg[2] * k;
  const cv::Matx33d Rx(1, 0, 0, 0, std::cos(ax), -std::sin(ax), 0, std::sin(ax), std::cos(ax));
  const cv::Matx33d Ry(std::cos(ay), 0, std::sin(ay), 0, 1, 0, -std::sin(ay), 0, std::cos(ay));
  const cv::Matx33d Rz(std::cos(az), -std::sin(az), 0, std::sin(az), std::cos(az), 0, 0, 0, 1);
  const cv::Matx33d R = Rz * Ry * Rx;   // about x first, then y, then z
  return cv::Matx44d(R(0, 0), R(0, 1), R(0, 2), 0, R(1, 0), R(1, 1), R(1, 2), 0, R(2, 0), R(2, 1), R(2, 2), 0,
                     0, 0, 0, 1);
}

}  // namespace

const char* cube_face_name(CubeFace f) {
  switch (f) {
    case CubeFace::right: return "right";
    case CubeFace::left: return "left";
    case CubeFace::back: return "back";
    case CubeFace::front: return "front";
    case CubeFace::top: return "top";
    case CubeFace::bottom: return "bottom";
  }
  return "top";
}

std::shared_ptr<Mesh> make_cube(const CubeLook& look, int subdivisions) {
  const int n = std::clamp(subdivisions, 1, 64);
  auto m = std::make_shared<Mesh>();
  m->source = "cube";
  // Each face's top-left corner and edges as seen from outside (mesh.hpp says which way is up).
  struct F { cv::Vec3f origin, right, down, normal; };
  const F faces[kCubeFaces] = {
      {{0.5f, -0.5f, 1}, {0, 1, 0}, {0, 0, -1}, {1, 0, 0}},     // right (+x)
      {{-0.5f, 0.5f, 1}, {0, -1, 0}, {0, 0, -1}, {-1, 0, 0}},   // left
      {{0.5f, 0.5f, 1}, {-1, 0, 0}, {0, 0, -1}, {0, 1, 0}},     // back (+y)
      {{-0.5f, -0.5f, 1}, {1, 0, 0}, {0, 0, -1}, {0, -1, 0}},   // front (-y)
      {{-0.5f, 0.5f, 1}, {1, 0, 0}, {0, -1, 0}, {0, 0, 1}},     // top (+z), +y up
      {{-0.5f, -0.5f, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}},    // bottom (-z), seen from below, -y up
  };
  for (int i = 0; i < kCubeFaces; ++i) {
    MeshPart p;
    p.name = cube_face_name(static_cast<CubeFace>(i));
    p.colour = look.colour[size_t(i)];
    p.texture = look.texture[size_t(i)];
    p.lit = look.lit;
    add_face(&p, faces[i].origin, faces[i].right, faces[i].down, faces[i].normal, n);
    m->parts.push_back(std::move(p));
  }
  m->compute_bounds();
  return m;
}

std::shared_ptr<Mesh> make_axes(double thickness) {
  const float t = static_cast<float>(std::clamp(thickness, 0.001, 0.5)) / 2;
  auto m = std::make_shared<Mesh>();
  m->source = "axes";
  const cv::Scalar colour[3] = {{40, 40, 230, 255}, {40, 200, 40, 255}, {230, 90, 30, 255}};   // BGRA: x red, y green, z blue
  const char* names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    MeshPart p;
    p.name = names[a];
    p.colour = colour[a];
    p.lit = false;
    cv::Vec3f lo(-t, -t, -t), hi(t, t, t);
    hi[a] = 1;
    lo[a] = 0;
    add_box(&p, lo, hi);
    m->parts.push_back(std::move(p));
  }
  m->compute_bounds();
  return m;
}

std::shared_ptr<const Mesh> flat_media_mesh(int subdivisions) {
  const int n = std::clamp(subdivisions, 1, 64);
  auto m = std::make_shared<Mesh>();
  m->source = "flat media";
  MeshPart p;
  p.name = "media";
  p.overlay_texture = true;
  p.lit = false;
  add_face(&p, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}, n);
  m->parts.push_back(std::move(p));
  m->compute_bounds();
  return m;
}

cv::Matx44d model_to_marker(const Mesh& model) {
  // Model (x, y, z) -> marker (x, -z, y): y up becomes z out of the marker, the model's front faces -y.
  const cv::Matx44d axes(1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1);
  const cv::Vec3f ext = model.max - model.min;
  const double largest = std::max({double(ext[0]), double(ext[1]), double(ext[2])});
  const double s = largest > 0 ? 1.0 / largest : 1.0;
  // The base's centre in model units: x and z centred, y at the bottom.
  const double cx = 0.5 * (model.min[0] + model.max[0]), cz = 0.5 * (model.min[2] + model.max[2]);
  const cv::Matx44d centre(1, 0, 0, -cx, 0, 1, 0, -double(model.min[1]), 0, 0, 1, -cz, 0, 0, 0, 1);
  const cv::Matx44d scale(s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, 0, 0, 0, 1);
  return scale * axes * centre;
}

cv::Matx44d place_in_marker(const cv::Matx44d& inner, cv::Vec3d offset, cv::Vec3d rotate_deg, double scale) {
  const cv::Matx44d S(scale, 0, 0, 0, 0, scale, 0, 0, 0, 0, scale, 0, 0, 0, 0, 1);
  const cv::Matx44d T(1, 0, 0, offset[0], 0, 1, 0, offset[1], 0, 0, 1, offset[2], 0, 0, 0, 1);
  return T * rotation4(rotate_deg) * S * inner;
}

}  // namespace arwb
