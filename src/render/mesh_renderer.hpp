// The compositor's 3D pass: meshes (track/mesh.hpp) in a marker's frame, projected through the camera's lens
// model (pinhole, radial and tangential distortion: OpenCV's k1 k2 p1 p2 k3 k4 k5 k6) vertex by vertex, with a
// depth buffer and a simple light. Meshes are tessellated finely enough (the cube's faces and flat media are
// grids) that straight edges bend as the lens bends them; a vertex lands exactly where cv::projectPoints puts it.
//
// The shaders are mesh.vert and mesh.frag, and their uniforms mesh_uniforms.hpp's, which the phone player draws
// with too. Depth: kMeshNear to kMeshFar. Light: a lamp above and to the left of the camera, plus ambient.
// Transparency is blended in drawing order without sorting.
//
// Needs the current OpenGL 3.3 core context the compositor draws with; called only by Compositor::draw, inside
// its framebuffer and state.
#pragma once

#include "render/mesh_uniforms.hpp"
#include "render/texture.hpp"
#include "track/overlay.hpp"

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace arwb::render {

class MeshRenderer {
 public:
  MeshRenderer() = default;
  ~MeshRenderer();
  MeshRenderer(const MeshRenderer&) = delete;
  MeshRenderer& operator=(const MeshRenderer&) = delete;

  // Draws `o.solid` into the bound framebuffer of size `frame` (depth test on, blending as set by the caller).
  // Parts textured with the overlay's media take o.content, cropped to o.quad's uv_min..uv_max. False (error()
  // says why) when the program cannot be made.
  bool draw(const Overlay& o, cv::Size frame, TextureCache& textures);
  // Frees meshes not drawn in the last `keep_frames` calls of end_frame.
  void end_frame(int keep_frames = 240);
  const std::string& error() const { return error_; }
  size_t meshes() const { return meshes_.size(); }

 private:
  struct PartGL {
    unsigned vao = 0, vbo = 0, ebo = 0;
    int count = 0;
    bool normals = false;
  };
  struct MeshGL {
    std::shared_ptr<const Mesh> hold;   // keeps the address from being reused while cached
    std::vector<PartGL> parts;
    uint64_t last_used = 0;
  };
  bool ensure_program();
  MeshGL& upload(const std::shared_ptr<const Mesh>& mesh);
  static void release(MeshGL& m);

  unsigned program_ = 0;
  int loc_model_view_ = -1, loc_normal_matrix_ = -1, loc_intrinsics_ = -1, loc_skew_ = -1, loc_knum_ = -1,
      loc_kden_ = -1, loc_tangential_ = -1, loc_r2_max_ = -1, loc_size_ = -1, loc_depth_ = -1, loc_y_sign_ = -1,
      loc_colour_ = -1,
      loc_textured_ = -1, loc_lit_ = -1, loc_normals_ = -1, loc_uv_window_ = -1, loc_tex_ = -1;
  std::unordered_map<const Mesh*, MeshGL> meshes_;
  uint64_t frame_ = 0;
  std::string error_;
};

}  // namespace arwb::render
