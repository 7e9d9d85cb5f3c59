#include "render/mesh_renderer.hpp"

#include "render/gl_program.hpp"

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

#include <cstdio>

namespace arwb::render {
namespace {

// The shared shaders (mesh.vert and mesh.frag, which the phone player also draws with) as strings: kMeshVertexBody
// and kMeshFragmentBody, written by src/render/CMakeLists.txt.
#include "render/mesh_shaders.inc"

}  // namespace

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
  const std::string version = "#version 330 core\n";
  program_ = link_program((version + kMeshVertexBody).c_str(), (version + kMeshFragmentBody).c_str(), "mesh", &error_);
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
  loc_y_sign_ = loc("y_sign");
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
    g.normals = part.normals.size() == part.positions.size();
    const std::vector<float> v = interleaved_vertices(part);
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

  const MeshUniforms u = mesh_uniforms(s, frame);
  glUseProgram(program_);
  glUniformMatrix4fv(loc_model_view_, 1, GL_TRUE, u.model_view.data());
  glUniformMatrix3fv(loc_normal_matrix_, 1, GL_TRUE, u.normal_matrix.data());
  glUniform4fv(loc_intrinsics_, 1, u.intrinsics.data());
  glUniform1f(loc_skew_, u.skew);
  glUniform3fv(loc_knum_, 1, u.knum.data());
  glUniform3fv(loc_kden_, 1, u.kden.data());
  glUniform2fv(loc_tangential_, 1, u.tangential.data());
  glUniform1f(loc_r2_max_, u.r2_max);
  glUniform2fv(loc_size_, 1, u.size.data());
  glUniform2fv(loc_depth_, 1, u.depth.data());
  glUniform1f(loc_y_sign_, 1.0f);   // the image's top row at the framebuffer's row 0, as the compositor reads it
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
    glUniform4fv(loc_colour_, 1, part_colour(part, o.quad.opacity).data());
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
