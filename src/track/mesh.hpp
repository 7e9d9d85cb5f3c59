// 3D content of scenes as triangle meshes: the paper's cube, axes, flat media drawn through the lens model, and
// models read from OBJ and glTF files (media/model_file.hpp). Meshes are plain data, made on the worker and
// never changed once published: the scene hands them to the renderer through Overlay::solid, and src/render
// uploads each one once (keyed by its address, held alive by its shared_ptr).
//
// Where a mesh is drawn: Overlay::solid gives the mesh-to-marker transform and the marker's pose. The marker
// frame is OpenCV's (pose/marker_pose.hpp): origin at the marker's centre, x towards corner 1, y up, z out of
// the marker towards the camera, one unit the marker's side.
#pragma once

#include "track/media_spec.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace arwb {

// One material's triangles.
struct MeshPart {
  std::vector<cv::Vec3f> positions;
  std::vector<cv::Vec3f> normals;   // one per position, unit length; empty: the renderer shades each face flat
  std::vector<cv::Vec2f> uvs;       // one per position, (0,0) the texture's top-left; empty when untextured
  std::vector<uint32_t> indices;    // three per triangle, each < positions.size()
  cv::Scalar colour{255, 255, 255, 255};    // BGRA 0..255, multiplied with the texture
  std::shared_ptr<MediaContent> texture;    // null: the colour alone
  bool overlay_texture = false;   // textured with the overlay's own media (a flat media drawn through the lens)
  bool lit = true;                // shaded by the light; false: the colour as it is (axes)
  std::string name;               // the material's name, for messages
};

struct Mesh {
  std::vector<MeshPart> parts;
  std::string source;                         // what the scene named: "models/duck.gltf", "cube", "axes"
  cv::Vec3f min{0, 0, 0}, max{0, 0, 0};       // bounds of every position (compute_bounds)
  size_t triangle_count() const;
  size_t vertex_count() const;
  void compute_bounds();
  // "" when every part is consistent (normals and uvs empty or one per position, indices in range and a multiple
  // of three, positions finite), else the first problem: "part 'wood': index 907 out of range (412 positions)".
  std::string validate() const;
};

// Limits on what a model may hold; a file beyond them is refused with its numbers.
inline constexpr size_t kMaxMeshTriangles = 2'000'000;
inline constexpr size_t kMaxMeshVertices = 2'000'000;

// The cube's faces by the marker frame's axes.
enum class CubeFace { right, left, back, front, top, bottom };   // +x -x +y -y +z -z
inline constexpr int kCubeFaces = 6;
const char* cube_face_name(CubeFace f);   // "right", "left", "back", "front", "top", "bottom"

struct CubeLook {
  std::array<cv::Scalar, kCubeFaces> colour;                        // BGRA per face
  std::array<std::shared_ptr<MediaContent>, kCubeFaces> texture{};  // null: colour only
  bool lit = true;
};

// A cube of side 1 standing on the marker: x and y in [-0.5, 0.5], z in [0, 1]. Each face is a grid of
// `subdivisions` x `subdivisions` squares, so that through a distorting lens its edges bend as the image does.
// A face's texture is upright when the face is seen from outside: a side face with +z (away from the marker) up,
// the top face with the marker's top (+y) up, the bottom face (seen from below) with -y up.
std::shared_ptr<Mesh> make_cube(const CubeLook& look, int subdivisions = 8);

// Three bars from the origin along x (red), y (green) and z (blue), of length 1 and the given thickness,
// unlit.
std::shared_ptr<Mesh> make_axes(double thickness = 0.04);

// The square [0,1]^2 (x right, y down: a media's texture coordinates) at z = 0, a grid of `subdivisions`
// squares a side, uvs equal to positions, textured with the overlay's media (overlay_texture), unlit.
std::shared_ptr<const Mesh> flat_media_mesh(int subdivisions = 16);

// A model's own frame to the marker frame: models are written with y up (glTF's convention, and most OBJ
// files'), so the model's +y becomes the marker's +z and its +z (its front) the marker's -y (the marker's
// bottom edge); the model is then scaled so its largest extent is 1 and moved so the centre of its base sits on
// the origin.
cv::Matx44d model_to_marker(const Mesh& model);

// Offset (in marker sides, marker frame), rotation (degrees about x, then y, then z of the marker frame) and a
// uniform scale, as one transform applied after `inner`.
cv::Matx44d place_in_marker(const cv::Matx44d& inner, cv::Vec3d offset, cv::Vec3d rotate_deg, double scale);

}  // namespace arwb
