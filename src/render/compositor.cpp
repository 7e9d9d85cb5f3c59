#include "render/compositor.hpp"

#include "render/gl_program.hpp"

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace arwb::render {
namespace {

// Image pixel centres are at integer coordinates (arwb's and OpenCV's convention); the framebuffer's pixel i
// spans [i, i+1]. The framebuffer's row 0 is the image's top row, so reading it back needs no flip and the
// resolved texture's t = 0 is the image's top, as ImGui::Image expects.
const char* kVertex = R"(#version 330 core
layout(location = 0) in vec2 pos;
uniform vec2 size;
void main() {
  gl_Position = vec4(2.0 * (pos + 0.5) / size - 1.0, 0.0, 1.0);
})";

// Texture coordinates per fragment, through the inverse homography: exact perspective on the whole quad.
const char* kFragment = R"(#version 330 core
uniform mat3 image_to_uv;
uniform vec2 uv_min;
uniform vec2 uv_max;
uniform float opacity;
uniform sampler2D tex;
out vec4 colour;
void main() {
  vec3 h = image_to_uv * vec3(gl_FragCoord.xy - 0.5, 1.0);
  vec2 uv = clamp(h.xy / h.z, uv_min, uv_max);
  vec4 c = texture(tex, uv);
  colour = vec4(c.rgb, c.a * opacity);
})";

}  // namespace

Compositor::Compositor(int samples) : samples_requested_(samples) {}

Compositor::~Compositor() {
  release_targets();
  if (program_) glDeleteProgram(program_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (vao_) glDeleteVertexArrays(1, &vao_);
}

bool Compositor::ensure_program() {
  if (program_) return true;
  program_ = link_program(kVertex, kFragment, "compositor", &error_);
  if (!program_) return false;
  loc_image_to_uv_ = glGetUniformLocation(program_, "image_to_uv");
  loc_uv_min_ = glGetUniformLocation(program_, "uv_min");
  loc_uv_max_ = glGetUniformLocation(program_, "uv_max");
  loc_opacity_ = glGetUniformLocation(program_, "opacity");
  loc_size_ = glGetUniformLocation(program_, "size");
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, 8 * sizeof(float), nullptr, GL_DYNAMIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), nullptr);
  glBindVertexArray(0);
  return true;
}

void Compositor::release_targets() {
  if (ms_fbo_) glDeleteFramebuffers(1, &ms_fbo_);
  if (ms_rbo_) glDeleteRenderbuffers(1, &ms_rbo_);
  if (resolved_fbo_) glDeleteFramebuffers(1, &resolved_fbo_);
  if (resolved_tex_) glDeleteTextures(1, &resolved_tex_);
  if (ms_depth_) glDeleteRenderbuffers(1, &ms_depth_);
  if (resolved_depth_) glDeleteRenderbuffers(1, &resolved_depth_);
  ms_fbo_ = ms_rbo_ = resolved_fbo_ = resolved_tex_ = ms_depth_ = resolved_depth_ = 0;
  size_ = {};
}

bool Compositor::ensure_targets(cv::Size s) {
  if (s == size_ && resolved_fbo_) return true;
  release_targets();
  GLint max_samples = 0;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  samples_ = std::min(samples_requested_, static_cast<int>(max_samples));
  glGenTextures(1, &resolved_tex_);
  glBindTexture(GL_TEXTURE_2D, resolved_tex_);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, s.width, s.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glGenFramebuffers(1, &resolved_fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, resolved_fbo_);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, resolved_tex_, 0);
  // Depth for 3D media, used when there is no multisampled target to draw into.
  glGenRenderbuffers(1, &resolved_depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, resolved_depth_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, s.width, s.height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, resolved_depth_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    error_ = "compositor: the result framebuffer is incomplete";
    release_targets();
    return false;
  }
  if (samples_ > 1) {
    glGenRenderbuffers(1, &ms_rbo_);
    glBindRenderbuffer(GL_RENDERBUFFER, ms_rbo_);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_RGBA8, s.width, s.height);
    glGenFramebuffers(1, &ms_fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, ms_rbo_);
    glGenRenderbuffers(1, &ms_depth_);
    glBindRenderbuffer(GL_RENDERBUFFER, ms_depth_);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_DEPTH_COMPONENT24, s.width, s.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, ms_depth_);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      // No MSAA then, rather than no picture.
      glDeleteFramebuffers(1, &ms_fbo_);
      glDeleteRenderbuffers(1, &ms_rbo_);
      glDeleteRenderbuffers(1, &ms_depth_);
      ms_fbo_ = ms_rbo_ = ms_depth_ = 0;
      samples_ = 0;
    }
  } else {
    samples_ = 0;
  }
  size_ = s;
  return true;
}

void Compositor::draw_quad(unsigned texture, const cv::Matx33d& image_to_uv, const std::array<cv::Point2d, 4>& c,
                           cv::Point2d uv_min, cv::Point2d uv_max, double opacity) {
  // Triangle fan order 0 1 2 3 as a strip: 0 1 3 2.
  const float v[8] = {float(c[0].x), float(c[0].y), float(c[1].x), float(c[1].y),
                      float(c[3].x), float(c[3].y), float(c[2].x), float(c[2].y)};
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferSubData(GL_ARRAY_BUFFER, 0, sizeof v, v);
  float m[9];
  for (int i = 0; i < 9; ++i) m[i] = static_cast<float>(image_to_uv.val[i]);
  glUniformMatrix3fv(loc_image_to_uv_, 1, GL_TRUE, m);
  glUniform2f(loc_uv_min_, float(uv_min.x), float(uv_min.y));
  glUniform2f(loc_uv_max_, float(uv_max.x), float(uv_max.y));
  glUniform1f(loc_opacity_, float(opacity));
  glBindTexture(GL_TEXTURE_2D, texture);
  glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

bool Compositor::draw(const cv::Mat& frame, uint64_t frame_version, const std::vector<Overlay>& overlays) {
  if (frame.empty()) return false;
  // Nothing new (the same frame, no video moved on): the last result stands. In the workbench the UI draws two
  // or three times per detected frame, and a software renderer pays for every composite.
  uint64_t sig = frame_version * 0x9E3779B97F4A7C15ull ^ uint64_t(frame.cols) << 32 ^ uint64_t(frame.rows);
  for (const Overlay& o : overlays) {
    uint64_t v = 0;
    if (o.content) o.content->current(&v);
    sig = (sig ^ (v + 0x9E3779B97F4A7C15ull + (sig << 6) + (sig >> 2))) * 0x100000001B3ull;
    sig ^= reinterpret_cast<uintptr_t>(o.content.get());
    for (const cv::Point2d& c : o.quad.corners) {
      uint64_t bits[2];
      std::memcpy(bits, &c, sizeof bits);
      sig = (sig ^ bits[0] ^ (bits[1] << 1)) * 0x100000001B3ull;
    }
    uint64_t op = 0;
    std::memcpy(&op, &o.quad.opacity, sizeof op);
    sig ^= op;
    if (o.solid) {
      // A 3D media moves with its pose (its corners' quad may stay put when only the marker's tilt changes).
      sig ^= reinterpret_cast<uintptr_t>(o.solid->mesh.get());
      for (int k = 0; k < 3; ++k) {
        uint64_t bits[2];
        std::memcpy(&bits[0], &o.solid->rvec[k], sizeof bits[0]);
        std::memcpy(&bits[1], &o.solid->tvec[k], sizeof bits[1]);
        sig = (sig ^ bits[0] ^ (bits[1] << 1)) * 0x100000001B3ull;
      }
      if (o.solid->mesh)   // (a conditional expression here copied every part's vertices on every frame)
        for (const MeshPart& part : o.solid->mesh->parts) {
          uint64_t pv = 0;
          if (part.texture) part.texture->current(&pv);
          sig = (sig ^ pv) * 0x100000001B3ull;
        }
    }
  }
  sig ^= overlays.size();
  if (resolved_fbo_ && size_ == frame.size() && have_sig_ && sig == last_sig_) return true;
  last_sig_ = sig;
  have_sig_ = true;
  // Leave the caller's state (ImGui's backend, a window) as it was; saved before anything here binds objects,
  // creating the framebuffers included.
  GLint prev_fbo = 0, prev_viewport[4] = {}, prev_program = 0, prev_vao = 0, prev_tex = 0, prev_active = 0;
  glGetIntegerv(GL_FRAMEBUFFER_BINDING, &prev_fbo);
  glGetIntegerv(GL_VIEWPORT, prev_viewport);
  glGetIntegerv(GL_CURRENT_PROGRAM, &prev_program);
  glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &prev_vao);
  glGetIntegerv(GL_ACTIVE_TEXTURE, &prev_active);
  glActiveTexture(GL_TEXTURE0);
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &prev_tex);
  const GLboolean blend = glIsEnabled(GL_BLEND), scissor = glIsEnabled(GL_SCISSOR_TEST),
                  depth = glIsEnabled(GL_DEPTH_TEST), cull = glIsEnabled(GL_CULL_FACE);
  GLint prev_array_buffer = 0;
  glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &prev_array_buffer);
  auto restore = [&] {
    glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(prev_fbo));
    glViewport(prev_viewport[0], prev_viewport[1], prev_viewport[2], prev_viewport[3]);
    glUseProgram(static_cast<GLuint>(prev_program));
    glBindVertexArray(static_cast<GLuint>(prev_vao));
    glBindBuffer(GL_ARRAY_BUFFER, static_cast<GLuint>(prev_array_buffer));
    glBindTexture(GL_TEXTURE_2D, static_cast<GLuint>(prev_tex));
    glActiveTexture(static_cast<GLenum>(prev_active));
    blend ? glEnable(GL_BLEND) : glDisable(GL_BLEND);
    scissor ? glEnable(GL_SCISSOR_TEST) : glDisable(GL_SCISSOR_TEST);
    depth ? glEnable(GL_DEPTH_TEST) : glDisable(GL_DEPTH_TEST);
    cull ? glEnable(GL_CULL_FACE) : glDisable(GL_CULL_FACE);
  };
  if (!ensure_program() || !ensure_targets(frame.size())) {
    restore();
    return false;
  }

  frame_tex_.upload(frame, frame_version, true, false);
  const int W = size_.width, H = size_.height;
  glBindFramebuffer(GL_FRAMEBUFFER, ms_fbo_ ? ms_fbo_ : resolved_fbo_);
  glViewport(0, 0, W, H);
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glClearColor(0, 0, 0, 1);
  glClearDepth(1.0);
  glDepthMask(GL_TRUE);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glUseProgram(program_);
  glBindVertexArray(vao_);
  glUniform2f(loc_size_, float(W), float(H));
  glUniform1i(glGetUniformLocation(program_, "tex"), 0);
  glDisable(GL_BLEND);
  const cv::Matx33d frame_uv(1.0 / W, 0, 0.5 / W, 0, 1.0 / H, 0.5 / H, 0, 0, 1);
  draw_quad(frame_tex_.id(), frame_uv, {{{-0.5, -0.5}, {W - 0.5, -0.5}, {W - 0.5, H - 0.5}, {-0.5, H - 0.5}}},
            {0, 0}, {1, 1}, 1.0);

  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  for (const Overlay& o : overlays) {
    if (o.solid) {
      glEnable(GL_DEPTH_TEST);
      glDepthFunc(GL_LESS);
      if (!meshes_.draw(o, size_, media_)) error_ = meshes_.error();
      glDisable(GL_DEPTH_TEST);
      glUseProgram(program_);
      glBindVertexArray(vao_);
      continue;
    }
    if (!o.content) continue;
    uint64_t version = 0;
    const std::shared_ptr<const cv::Mat> pixels = o.content->current(&version);
    if (!pixels || pixels->empty()) continue;
    // Images by path (shared by every marker showing them); videos and cards by their content object.
    char key[64];
    std::snprintf(key, sizeof key, "content:%p", static_cast<const void*>(o.content.get()));
    const std::string name = o.media.kind == MediaKind::image ? "image:" + o.media.path : key;
    const Texture& t = media_.get(name, *pixels, version, false, true);
    const cv::Matx33d inv = o.quad.H.inv();
    draw_quad(t.id(), inv, o.quad.corners, o.quad.uv_min, o.quad.uv_max, o.quad.opacity);
  }
  media_.end_frame(240);
  meshes_.end_frame(240);

  if (ms_fbo_) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, ms_fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolved_fbo_);
    glBlitFramebuffer(0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }

  restore();
  return true;
}

cv::Mat Compositor::read() const {
  if (!resolved_fbo_) return {};
  GLint prev = 0;
  glGetIntegerv(GL_FRAMEBUFFER_BINDING, &prev);
  glBindFramebuffer(GL_FRAMEBUFFER, resolved_fbo_);
  cv::Mat rgba(size_, CV_8UC4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, size_.width, size_.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  glBindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(prev));
  cv::Mat bgr;
  cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
  return bgr;
}

}  // namespace arwb::render
