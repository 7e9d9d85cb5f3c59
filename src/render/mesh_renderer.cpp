#include "render/mesh_renderer.hpp"

#include "render/gl_program.hpp"

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace arwb::render {
namespace {

// Pixel centres at integer coordinates, the framebuffer's row 0 the image's top row (as the quad pass). The
// clip position is the pinhole's, linear in the camera point, so clipping against the near plane is exact; in
// front of the camera its x and y are replaced by the distorted projection's (times z, so the division gives it).
const char* kMeshVertex = R"(#version 330 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 nrm;
layout(location = 2) in vec2 uv;
uniform mat4 model_view;
uniform mat3 normal_matrix;
uniform vec4 intrinsics;   // fx fy cx cy
uniform float skew;
uniform vec3 knum;         // k1 k2 k3
uniform vec3 kden;         // k4 k5 k6
uniform vec2 tangential;   // p1 p2
uniform float r2_max;
uniform vec2 size;
uniform vec2 depth;        // clip z = depth.x * z + depth.y
out vec3 v_pos;
out vec3 v_normal;
out vec2 v_uv;
void main() {
  vec4 c = model_view * vec4(pos, 1.0);
  v_pos = c.xyz;
  v_normal = normal_matrix * nrm;
  v_uv = uv;
  float z = c.z;
  vec2 px_z = vec2(intrinsics.x * c.x + skew * c.y + intrinsics.z * z, intrinsics.y * c.y + intrinsics.w * z);
  if (z > 1e-6) {
    vec2 xy = c.xy / z;
    float r2 = dot(xy, xy);
    if (r2 > r2_max) { xy *= sqrt(r2_max / r2); r2 = r2_max; }
    float r4 = r2 * r2, r6 = r4 * r2;
    float radial = (1.0 + knum.x * r2 + knum.y * r4 + knum.z * r6) / (1.0 + kden.x * r2 + kden.y * r4 + kden.z * r6);
    vec2 d = xy * radial + vec2(2.0 * tangential.x * xy.x * xy.y + tangential.y * (r2 + 2.0 * xy.x * xy.x),
                                tangential.x * (r2 + 2.0 * xy.y * xy.y) + 2.0 * tangential.y * xy.x * xy.y);
    // Held at the limit's radius, a far vertex keeps its direction from the centre.
    if (dot(c.xy / z, c.xy / z) > r2_max) d *= sqrt(dot(c.xy / z, c.xy / z) / r2_max);
    px_z = vec2(intrinsics.x * d.x + skew * d.y + intrinsics.z, intrinsics.y * d.y + intrinsics.w) * z;
  }
  gl_Position = vec4(2.0 * (px_z + 0.5 * z) / size - z, depth.x * z + depth.y, z);
})";

const char* kMeshFragment = R"(#version 330 core
in vec3 v_pos;
in vec3 v_normal;
in vec2 v_uv;
uniform vec4 colour;
uniform int textured;
uniform int lit;
uniform int normals;
uniform vec4 uv_window;    // the texture's part drawn: min.xy, max.xy
uniform sampler2D tex;
out vec4 result;
void main() {
  vec4 c = colour;
  if (textured != 0) c *= texture(tex, mix(uv_window.xy, uv_window.zw, v_uv));
  if (lit != 0) {
    vec3 n = normals != 0 ? normalize(v_normal) : normalize(cross(dFdx(v_pos), dFdy(v_pos)));
    if (dot(n, -v_pos) < 0.0) n = -n;
    // Camera coordinates: x right, y down, z forward. The lamp is above and left of the camera.
    vec3 to_light = normalize(vec3(-0.35, -0.6, -1.0));
    c.rgb *= 0.4 + 0.6 * max(dot(n, to_light), 0.0);
  }
  result = c;
})";

double radial_factor(const std::vector<double>& d, double r2) {
  auto k = [&](size_t i) { return i < d.size() ? d[i] : 0.0; };
  const double r4 = r2 * r2, r6 = r4 * r2;
  return (1 + k(0) * r2 + k(1) * r4 + k(4) * r6) / (1 + k(5) * r2 + k(6) * r4 + k(7) * r6);
}

}  // namespace

double distortion_r2_limit(const cv::Matx33d& K, const std::vector<double>& dist, cv::Size frame) {
  // The image's farthest corner in normalised coordinates, without distortion.
  double rmax = 0;
  const double fx = K(0, 0) > 0 ? K(0, 0) : 1, fy = K(1, 1) > 0 ? K(1, 1) : 1;
  for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(frame.width, 0), cv::Point2d(frame.width, frame.height),
                              cv::Point2d(0, frame.height)})
    rmax = std::max(rmax, std::hypot((p.x - K(0, 2)) / fx, (p.y - K(1, 2)) / fy));
  bool any = false;
  for (const double v : dist) any = any || v != 0;
  if (any && dist.size() >= 4) {
    try {
      std::vector<cv::Point2d> in, out;
      for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(frame.width, 0),
                                  cv::Point2d(frame.width, frame.height), cv::Point2d(0, frame.height)})
        in.push_back(p);
      cv::undistortPoints(in, out, K, dist);
      for (const cv::Point2d& p : out)
        if (std::isfinite(p.x) && std::isfinite(p.y)) rmax = std::max(rmax, std::hypot(p.x, p.y));
    } catch (const cv::Exception&) {
      // The pinhole's corners stand.
    }
  }
  const double cap = 2 * std::max(rmax, 0.1);
  if (!any) return cap * cap;
  // r * radial(r^2) must keep growing: stop before it turns.
  constexpr int kSteps = 4000;
  double prev = 0;
  for (int i = 1; i <= kSteps; ++i) {
    const double r = cap * i / kSteps, v = r * radial_factor(dist, r * r);
    if (!(v > prev) || !std::isfinite(v)) {
      const double rr = cap * (i - 1) / kSteps;
      return std::max(rr * rr, 1e-6);
    }
    prev = v;
  }
  return cap * cap;
}

MeshRenderer::~MeshRenderer() {
  for (auto& [key, m] : meshes_) release(m);
  if (program_) glDeleteProgram(program_);
}

void MeshRenderer::release(MeshGL& m) {
  for (PartGL& p : m.parts) {
    if (p.vao) glDeleteVertexArrays(1, &p.vao);
    if (p.vbo) glDeleteBuffers(1, &p.vbo);
    if (p.ebo) glDeleteBuffers(1, &p.ebo);
  }
  m.parts.clear();
}

bool MeshRenderer::ensure_program() {
  if (program_) return true;
  program_ = link_program(kMeshVertex, kMeshFragment, "mesh", &error_);
  if (!program_) return false;
  auto loc = [&](const char* n) { return glGetUniformLocation(program_, n); };
  loc_model_view_ = loc("model_view");
  loc_normal_matrix_ = loc("normal_matrix");
  loc_intrinsics_ = loc("intrinsics");
  loc_skew_ = loc("skew");
  loc_knum_ = loc("knum");
  loc_kden_ = loc("kden");
  loc_tangential_ = loc("tangential");
  loc_r2_max_ = loc("r2_max");
  loc_size_ = loc("size");
  loc_depth_ = loc("depth");
  loc_colour_ = loc("colour");
  loc_textured_ = loc("textured");
  loc_lit_ = loc("lit");
  loc_normals_ = loc("normals");
  loc_uv_window_ = loc("uv_window");
  loc_tex_ = loc("tex");
  return true;
}

MeshRenderer::MeshGL& MeshRenderer::upload(const std::shared_ptr<const Mesh>& mesh) {
  MeshGL& m = meshes_[mesh.get()];
  m.last_used = frame_;
  if (m.hold == mesh) return m;
  release(m);
  m.hold = mesh;
  for (const MeshPart& part : mesh->parts) {
    PartGL g;
    const size_t n = part.positions.size();
    g.normals = part.normals.size() == n;
    const bool uvs = part.uvs.size() == n;
    std::vector<float> v;
    v.reserve(n * 8);
    for (size_t i = 0; i < n; ++i) {
      const cv::Vec3f& p = part.positions[i];
      const cv::Vec3f nr = g.normals ? part.normals[i] : cv::Vec3f(0, 0, 0);
      const cv::Vec2f t = uvs ? part.uvs[i] : cv::Vec2f(0, 0);
      v.insert(v.end(), {p[0], p[1], p[2], nr[0], nr[1], nr[2], t[0], t[1]});
    }
    glGenVertexArrays(1, &g.vao);
    glGenBuffers(1, &g.vbo);
    glGenBuffers(1, &g.ebo);
    glBindVertexArray(g.vao);
    glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(v.size() * sizeof(float)), v.data(), GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(part.indices.size() * sizeof(uint32_t)), part.indices.data(),
                 GL_STATIC_DRAW);
    const GLsizei stride = 8 * sizeof(float);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(3 * sizeof(float)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(6 * sizeof(float)));
    glBindVertexArray(0);
    g.count = static_cast<int>(part.indices.size());
    m.parts.push_back(g);
  }
  return m;
}

bool MeshRenderer::draw(const Overlay& o, cv::Size frame, TextureCache& textures) {
  if (!o.solid || !o.solid->mesh) return true;
  if (!ensure_program()) return false;
  const SolidDraw& s = *o.solid;
  const MeshGL& gl = upload(s.mesh);

  cv::Matx33d R;
  cv::Rodrigues(s.rvec, R);
  const cv::Matx44d pose(R(0, 0), R(0, 1), R(0, 2), s.tvec[0], R(1, 0), R(1, 1), R(1, 2), s.tvec[1], R(2, 0),
                         R(2, 1), R(2, 2), s.tvec[2], 0, 0, 0, 1);
  const cv::Matx44d mv = pose * s.mesh_to_marker;
  const cv::Matx33d lin = mv.get_minor<3, 3>(0, 0);
  const cv::Matx33d nm = lin.inv().t();
  float mvf[16], nmf[9];
  for (int i = 0; i < 16; ++i) mvf[i] = static_cast<float>(mv.val[i]);
  for (int i = 0; i < 9; ++i) nmf[i] = static_cast<float>(nm.val[i]);
  auto k = [&](size_t i) { return static_cast<float>(i < s.distortion.size() ? s.distortion[i] : 0.0); };

  glUseProgram(program_);
  glUniformMatrix4fv(loc_model_view_, 1, GL_TRUE, mvf);
  glUniformMatrix3fv(loc_normal_matrix_, 1, GL_TRUE, nmf);
  const cv::Matx33d& K = s.camera_matrix;
  glUniform4f(loc_intrinsics_, float(K(0, 0)), float(K(1, 1)), float(K(0, 2)), float(K(1, 2)));
  glUniform1f(loc_skew_, float(K(0, 1)));
  glUniform3f(loc_knum_, k(0), k(1), k(4));
  glUniform3f(loc_kden_, k(5), k(6), k(7));
  glUniform2f(loc_tangential_, k(2), k(3));
  glUniform1f(loc_r2_max_, float(distortion_r2_limit(K, s.distortion, frame)));
  glUniform2f(loc_size_, float(frame.width), float(frame.height));
  const double A = (kFar + kNear) / (kFar - kNear), B = -2 * kFar * kNear / (kFar - kNear);
  glUniform2f(loc_depth_, float(A), float(B));
  glUniform1i(loc_tex_, 0);

  for (size_t i = 0; i < gl.parts.size() && i < s.mesh->parts.size(); ++i) {
    const MeshPart& part = s.mesh->parts[i];
    const PartGL& g = gl.parts[i];
    if (g.count == 0) continue;
    const MediaContent* content = part.overlay_texture ? o.content.get() : part.texture.get();
    bool textured = false;
    if (content && !part.uvs.empty()) {
      uint64_t version = 0;
      const std::shared_ptr<const cv::Mat> pixels = content->current(&version);
      if (pixels && !pixels->empty()) {
        char key[64];
        std::snprintf(key, sizeof key, "content:%p", static_cast<const void*>(content));
        const std::string name = part.overlay_texture && o.media.kind == MediaKind::image ? "image:" + o.media.path
                                                                                            : std::string(key);
        const Texture& t = textures.get(name, *pixels, version, false, true);
        glBindTexture(GL_TEXTURE_2D, t.id());
        // Models' texture coordinates may run past 0..1 and repeat; a flat media stays clamped at its edges.
        const GLint wrap = part.overlay_texture ? GL_CLAMP_TO_EDGE : GL_REPEAT;
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
        textured = true;
      }
    }
    if (!textured && part.overlay_texture) continue;   // a flat media without its picture yet
    const double op = o.quad.opacity;
    glUniform4f(loc_colour_, float(part.colour[2] / 255), float(part.colour[1] / 255), float(part.colour[0] / 255),
                float(part.colour[3] / 255 * op));
    glUniform1i(loc_textured_, textured ? 1 : 0);
    if (!part.overlay_texture) glUniform4f(loc_uv_window_, 0, 0, 1, 1);
    else glUniform4f(loc_uv_window_, float(o.quad.uv_min.x), float(o.quad.uv_min.y), float(o.quad.uv_max.x),
                     float(o.quad.uv_max.y));
    glUniform1i(loc_lit_, part.lit ? 1 : 0);
    glUniform1i(loc_normals_, g.normals ? 1 : 0);
    glBindVertexArray(g.vao);
    glDrawElements(GL_TRIANGLES, g.count, GL_UNSIGNED_INT, nullptr);
  }
  glBindVertexArray(0);
  return true;
}

void MeshRenderer::end_frame(int keep_frames) {
  ++frame_;
  for (auto it = meshes_.begin(); it != meshes_.end();) {
    if (frame_ - it->second.last_used > uint64_t(keep_frames)) {
      release(it->second);
      it = meshes_.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace arwb::render
