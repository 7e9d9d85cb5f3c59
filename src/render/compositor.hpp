// The paper's texture building and projection: the camera frame and every overlay's media as OpenGL textures,
// drawn into an offscreen multisampled framebuffer of the frame's size and resolved into a texture the UI shows
// (or read back as pixels by `arwb render`). The workbench and `arwb render` use this one class, fed by the same
// placement code (track/placement.hpp), so a media lands on the same pixels on screen and in a rendered video.
//
// True perspective: the quad's two triangles only say which pixels to shade. Each fragment maps its own pixel
// position through the inverse of the placement's homography to texture coordinates, so there is no seam or
// bend along the diagonal (interpolating texture coordinates per triangle would bend straight lines there).
// MSAA (4 samples where the driver has them) smooths the quad's edges.
//
// Overlays with a solid (3D media, and flat media when a calibration is loaded) are drawn by MeshRenderer
// through the lens model with a depth buffer; the others as quads, without depth, in order.
//
// Needs a current OpenGL 3.3 core context (the window's, or OffscreenContext's); everything is called on the
// thread that owns it. Textures: the frame by its version; images by path, so markers showing the same picture
// share one texture; videos and cards by content, uploaded only when their version changes. Unused textures are
// freed after a while.
#pragma once

#include "track/overlay.hpp"
#include "render/mesh_renderer.hpp"
#include "render/texture.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace arwb::render {

class Compositor {
 public:
  explicit Compositor(int samples = 4);
  ~Compositor();
  Compositor(const Compositor&) = delete;
  Compositor& operator=(const Compositor&) = delete;

  // Draws `frame` (BGR or grey; `frame_version` changes when its pixels do) with the overlays on top, in order.
  // When neither the frame version nor any media's version changed since the last call, keeps the last result.
  // False (and error() says why) if the GL objects could not be made; the frame is then not drawn.
  bool draw(const cv::Mat& frame, uint64_t frame_version, const std::vector<Overlay>& overlays);
  // The resolved result as a texture (for ImGui::Image) and its size; 0 before the first draw.
  unsigned texture() const { return resolved_tex_; }
  cv::Size size() const { return size_; }
  // The result's pixels, BGR, top row first.
  cv::Mat read() const;
  int samples() const { return samples_; }
  const std::string& error() const { return error_; }

 private:
  bool ensure_program();
  bool ensure_targets(cv::Size s);
  void release_targets();
  void draw_quad(unsigned texture, const cv::Matx33d& image_to_uv, const std::array<cv::Point2d, 4>& corners,
                 cv::Point2d uv_min, cv::Point2d uv_max, double opacity);

  int samples_requested_ = 4, samples_ = 0;
  cv::Size size_{};
  unsigned program_ = 0, vao_ = 0, vbo_ = 0;
  int loc_image_to_uv_ = -1, loc_uv_min_ = -1, loc_uv_max_ = -1, loc_opacity_ = -1, loc_size_ = -1;
  unsigned ms_fbo_ = 0, ms_rbo_ = 0, ms_depth_ = 0, resolved_fbo_ = 0, resolved_tex_ = 0, resolved_depth_ = 0;
  Texture frame_tex_;
  TextureCache media_;
  MeshRenderer meshes_;
  uint64_t last_sig_ = 0;   // the frame version and content versions of the last composite
  bool have_sig_ = false;
  std::string error_;
};

}  // namespace arwb::render
