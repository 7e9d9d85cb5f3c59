// What the mesh shaders (render/mesh.vert and mesh.frag) are given to draw a solid (track/overlay.hpp's
// SolidDraw): its uniforms, and a part's vertices as the shaders' attributes read them. Computed here once for
// the desktop's MeshRenderer and for the phone player's core, which hands them to the page's WebGL: the same
// numbers into the same shaders. Plain C++, no OpenGL.
#pragma once

#include "track/overlay.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <vector>

namespace arwb::render {

// Depth: camera z between these, in marker sides, the usual perspective depth, so that triangles of several
// markers' media hide each other correctly.
inline constexpr double kMeshNear = 0.01, kMeshFar = 1e4;

struct MeshUniforms {
  std::array<float, 16> model_view{};     // row-major: mesh units to camera (marker sides)
  std::array<float, 9> normal_matrix{};   // row-major: the inverse transpose of model_view's linear part
  std::array<float, 4> intrinsics{};      // fx fy cx cy
  float skew = 0;
  std::array<float, 3> knum{};            // k1 k2 k3
  std::array<float, 3> kden{};            // k4 k5 k6
  std::array<float, 2> tangential{};      // p1 p2
  float r2_max = 0;                       // distortion_r2_limit
  std::array<float, 2> size{};            // the frame's width and height
  std::array<float, 2> depth{};           // clip z = depth[0] * z + depth[1]
};

// The uniforms of `s` drawn into a frame of size `frame`.
MeshUniforms mesh_uniforms(const SolidDraw& s, cv::Size frame);

// A part's colour as the shaders take it: RGBA in 0..1 (the part's is BGRA in 0..255), alpha times `opacity`.
std::array<float, 4> part_colour(const MeshPart& part, double opacity);

// A part's vertices interleaved as the shaders' attributes read them: position (3), normal (3), uv (2), eight
// floats each; a normal or uv the part does not have is zeros.
std::vector<float> interleaved_vertices(const MeshPart& part);

// The largest squared radius (in normalised image coordinates) up to which the lens model keeps growing, capped
// at twice the image's farthest corner: beyond it OpenCV's polynomial turns back and would fold far-away
// vertices into the picture, so the shaders hold the distortion there. Exposed for tests.
double distortion_r2_limit(const cv::Matx33d& camera_matrix, const std::vector<double>& distortion, cv::Size frame);

}  // namespace arwb::render
