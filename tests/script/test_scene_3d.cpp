// 3D media in scenes: cube, axes and model become overlays with a mesh in the marker's frame and the marker's
// pose; their options are checked with the line; flat media go through the lens model when a calibration is
// loaded. The pixels are tested in tests/render/test_mesh_render.cpp.
#include "scene_test_util.hpp"

#include "pose/marker_pose.hpp"

#include <cmath>

namespace arwb::script::test {
namespace {

// The track with its pose from its corners, a marker side of 1.
TrackedMarker posed(TrackedMarker t, const Calibration& camera) {
  t.pose = estimate_marker_pose(t.corners, 1.0, camera);
  EXPECT_TRUE(t.pose);
  return t;
}

cv::Vec3d apply(const cv::Matx44d& m, cv::Vec3d p) {
  const cv::Vec4d r = m * cv::Vec4d(p[0], p[1], p[2], 1);
  return {r[0], r[1], r[2]};
}

struct Scene3D : SceneFixture {
  Scene3D() {
    calib = default_calibration(frame);
    camera = &calib;
  }
  Calibration calib;
};

TEST(Scene3D, CubeAndAxesStandOnTheirMarkersThroughThePose) {
  Scene3D s;
  ASSERT_TRUE(s.runtime.load(s.write("scene.lua", R"(
marker(1, { media = cube { size = 0.5, offset = {0.1, 0, 0}, rotate = {0, 0, 90} } })
marker(2, { media = axes { length = 2 } })
)"))) << s.runtime.status().error;
  const auto t1 = posed(track(1, 200, 240, 80), s.calib), t2 = posed(track(2, 440, 240, 80), s.calib);
  const auto o = s.update({t1, t2}, enters({1, 2}));
  const Overlay* c = find_overlay(o, 1);
  const Overlay* a = find_overlay(o, 2);
  ASSERT_TRUE(c && a) << s.console();
  ASSERT_TRUE(c->solid && c->solid->mesh);
  ASSERT_TRUE(a->solid && a->solid->mesh);
  EXPECT_EQ(c->solid->mesh->parts.size(), 6u);
  EXPECT_EQ(a->solid->mesh->parts.size(), 3u);
  EXPECT_EQ(c->media.kind, MediaKind::cube);
  // The cube's base centre at the offset; its top-right-back corner turned 90 degrees about z and halved.
  const cv::Vec3d base = apply(c->solid->mesh_to_marker, {0, 0, 0});
  EXPECT_NEAR(cv::norm(base - cv::Vec3d(0.1, 0, 0)), 0, 1e-9);
  const cv::Vec3d corner = apply(c->solid->mesh_to_marker, {0.5, 0.5, 1});
  EXPECT_NEAR(cv::norm(corner - cv::Vec3d(0.1 - 0.25, 0.25, 0.5)), 0, 1e-9);
  // The axes reach 2 sides along x.
  EXPECT_NEAR(cv::norm(apply(a->solid->mesh_to_marker, {1, 0, 0}) - cv::Vec3d(2, 0, 0)), 0, 1e-9);
  // The marker's pose and camera, tvec in marker sides.
  EXPECT_NEAR(cv::norm(c->solid->tvec - t1.pose->pose.tvec), 0, 1e-12);
  EXPECT_NEAR(cv::norm(c->solid->rvec - t1.pose->pose.rvec), 0, 1e-12);
  EXPECT_EQ(c->solid->camera_matrix, s.calib.camera_matrix);
  // On screen the overlay's box holds the marker's centre (the cube stands on it) and the axes reach right.
  EXPECT_TRUE(c->quad.contains({200, 240}));
  EXPECT_GT(a->quad.corners[1].x, 440 + 80 * 1.5);
  // The Scene panel describes them.
  EXPECT_EQ(s.runtime.status().mappings[0].media, "cube size 0.5 offset 0.1,0,0 rotate 0,0,90");
  EXPECT_EQ(s.runtime.status().mappings[1].media, "axes size 2");
}

TEST(Scene3D, BesideMovesTheMediaAlongTheMarkersPlane) {
  Scene3D s;
  ASSERT_TRUE(s.runtime.load(s.write("scene.lua", R"(
marker(1, { media = cube { size = 0.6 }, place = beside { side = "left", gap = 0.2 } })
marker(1, { media = cube(), place = beside { side = "top" } })
)"))) << s.runtime.status().error;
  const auto o = s.update({posed(track(1, 320, 240, 60), s.calib)}, enters({1}));
  ASSERT_EQ(o.size(), 2u) << s.console();
  EXPECT_NEAR(cv::norm(apply(o[0].solid->mesh_to_marker, {0, 0, 0}) - cv::Vec3d(-(0.5 + 0.2 + 0.3), 0, 0)), 0, 1e-9);
  EXPECT_NEAR(cv::norm(apply(o[1].solid->mesh_to_marker, {0, 0, 0}) - cv::Vec3d(0, 0.5 + 0.25 + 0.5, 0)), 0, 1e-9);
}

TEST(Scene3D, WithoutAPoseNothingIsDrawnAndTheRowSaysWhy) {
  Scene3D s;
  ASSERT_TRUE(s.runtime.load(s.write("scene.lua", "marker(1, { media = cube() })\n"))) << s.runtime.status().error;
  const auto o = s.update({track(1, 320, 240)}, enters({1}));
  EXPECT_EQ(count_overlays(o, 1), 0);
  EXPECT_TRUE(s.has("scene.lua:1: marker 1: no pose for this marker")) << s.console();
  EXPECT_EQ(s.runtime.status().mappings[0].health, MappingHealth::error);
}

TEST(Scene3D, BadOptionsSkipTheCallWithTheirLine) {
  Scene3D s;
  make_png(s.dir.path() / "media" / "logo.png");
  ASSERT_TRUE(s.runtime.load(s.write("scene.lua", R"(
marker(1, { media = cube { size = -1 } })
marker(2, { media = cube { faces = { top = "#zz0000" } } })
marker(3, { media = cube { faces = { top = "media/missing.png" } } })
marker(4, { media = cube { offset = {1, 2} } })
marker(5, { media = axes { thickness = 5 } })
marker(6, { media = cube(), place = billboard() })
marker(7, { media = cube { faces = { topp = "#ff0000", front = "media/logo.png" } } })
marker(8, { media = model(42) })
)"))) << s.runtime.status().error;
  EXPECT_TRUE(s.has("scene.lua:2: cube: size must be a number of marker sides in (0, 100] (got -1)")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:3: cube: faces.top: colour must be \"#rrggbb\" or \"#rrggbbaa\", got '#zz0000'"))
      << s.console();
  EXPECT_TRUE(s.has("scene.lua:4: cube: faces.top: media/missing.png: no such file")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:5: cube: offset must be three finite numbers {x, y, z}")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:6: axes: thickness must be a number of marker sides in (0, length]")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:7: marker(6): a cube stands in the marker's 3D frame: place it on_marker or beside, "
                    "not billboard; marker() skipped"))
      << s.console();
  EXPECT_TRUE(s.has("scene.lua:8: cube: faces: unknown field 'topp' (did you mean 'top'?)")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:9: model: expected a path to an OBJ or glTF file (string), got number 42")) << s.console();
  const auto& rows = s.runtime.status().mappings;
  ASSERT_EQ(rows.size(), 8u);
  for (size_t i = 0; i < rows.size(); ++i)
    EXPECT_EQ(rows[i].health, i == 6 ? MappingHealth::ok : MappingHealth::skipped) << i;
  // The face with an image shows it: the mesh's front part has a texture of the image's size.
  const auto o = s.update({posed(track(7, 320, 240, 80), s.calib)}, enters({7}));
  ASSERT_EQ(o.size(), 1u) << s.console();
  const MeshPart& front = o[0].solid->mesh->parts[size_t(CubeFace::front)];
  ASSERT_TRUE(front.texture);
  EXPECT_EQ(front.texture->size(), cv::Size(64, 48));
  EXPECT_FALSE(o[0].solid->mesh->parts[size_t(CubeFace::top)].texture);
}

TEST(Scene3D, FlatMediaGoThroughTheLensOnlyWithACalibration) {
  Scene3D s;
  make_png(s.dir.path() / "media" / "logo.png");
  ASSERT_TRUE(s.runtime.load(s.write("scene.lua", R"(
marker(1, { media = image "media/logo.png", place = on_marker { fit = "fill" } })
marker(1, { media = image "media/logo.png", place = beside { side = "right" } })
marker(1, { media = image "media/logo.png", place = billboard() })
)"))) << s.runtime.status().error;
  // The default values (assumed): the homography of the corners, exact for a pinhole camera.
  auto o = s.update({posed(track(1, 300, 240, 80), s.calib)}, enters({1}));
  ASSERT_EQ(o.size(), 3u) << s.console();
  for (const Overlay& v : o) EXPECT_FALSE(v.solid);
  // A calibration with distortion: on_marker and beside become grids through the pose; the billboard stays flat.
  Calibration measured = s.calib;
  measured.assumed = false;
  measured.distortion = {-0.2, 0.05, 0, 0, 0};
  s.camera = &measured;
  o = s.update({posed(track(1, 300, 240, 80), measured)});
  ASSERT_EQ(o.size(), 3u) << s.console();
  ASSERT_TRUE(o[0].solid && o[1].solid);
  EXPECT_FALSE(o[2].solid);
  EXPECT_TRUE(o[0].solid->mesh->parts[0].overlay_texture);
  EXPECT_EQ(o[0].solid->distortion, measured.distortion);
  // The grid's corners land on the marker's corners for on_marker fill: (0,0) -> corner 0 at (-0.5, 0.5).
  EXPECT_NEAR(cv::norm(apply(o[0].solid->mesh_to_marker, {0, 0, 0}) - cv::Vec3d(-0.5, 0.5, 0)), 0, 1e-9);
  EXPECT_NEAR(cv::norm(apply(o[0].solid->mesh_to_marker, {1, 1, 0}) - cv::Vec3d(0.5, -0.5, 0)), 0, 1e-9);
  // beside right: the media starts 0.25 sides right of the marker's edge.
  EXPECT_NEAR(apply(o[1].solid->mesh_to_marker, {0, 0, 0})[0], 0.75, 1e-9);
}

TEST(Scene3D, ModelsStandOnTheMarkerFittedToTheirSizeAndBrokenOnesAreReported) {
  Scene3D s;
  // A box 4 wide, 2 high (y up) and 1 deep, its base at y = 3: fitted, its largest extent becomes `size`.
  std::filesystem::create_directories(s.dir.path() / "models");
  s.write("models/box.obj",
          "v -2 3 -0.5\nv 2 3 -0.5\nv 2 5 -0.5\nv -2 5 -0.5\nv -2 3 0.5\nv 2 3 0.5\nv 2 5 0.5\nv -2 5 0.5\n"
          "f 1 2 3 4\nf 5 6 7 8\nf 1 2 6 5\nf 4 3 7 8\n");
  s.write("models/broken.obj", "this is not a model\n");
  ASSERT_TRUE(s.runtime.load(s.write("scene.lua", R"(
marker(1, { media = model("models/box.obj", { size = 2 }) })
marker(2, { media = model "models/broken.obj" })
marker(3, { media = model "models/missing.obj" })
marker(4, { media = model "../outside.obj" })
)"))) << s.runtime.status().error;
  EXPECT_TRUE(s.has("scene.lua:4: model: models/missing.obj: no such file; marker(3) skipped")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:5: model: ../outside.obj: leaves the scene's folder; marker(4) skipped"))
      << s.console();
  const auto o = s.update({posed(track(1, 200, 240, 80), s.calib), posed(track(2, 440, 240, 80), s.calib)},
                          enters({1, 2}));
  // The broken model is reported with the scene's line and the file's reason; the other marker shows its box.
  EXPECT_TRUE(s.has("scene.lua:3: models/broken.obj")) << s.console();
  EXPECT_EQ(count_overlays(o, 2), 0);
  const Overlay* box = find_overlay(o, 1);
  ASSERT_TRUE(box && box->solid && box->solid->mesh) << s.console();
  EXPECT_EQ(box->solid->mesh->triangle_count(), 8u);
  // Model (x, y, z) -> marker (x, -z, y), scaled by size / largest extent (2 / 4), the base's centre at the
  // origin: (2, 3, 0) -> (1, 0, 0); (0, 5, 0) -> (0, 0, 1); the model's front (+z) towards the marker's -y.
  EXPECT_NEAR(cv::norm(apply(box->solid->mesh_to_marker, {2, 3, 0}) - cv::Vec3d(1, 0, 0)), 0, 1e-6);
  EXPECT_NEAR(cv::norm(apply(box->solid->mesh_to_marker, {0, 5, 0}) - cv::Vec3d(0, 0, 1)), 0, 1e-6);
  EXPECT_NEAR(cv::norm(apply(box->solid->mesh_to_marker, {0, 3, 0.5}) - cv::Vec3d(0, -0.25, 0)), 0, 1e-6);
  const auto& rows = s.runtime.status().mappings;
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].health, MappingHealth::ok);
  EXPECT_EQ(rows[1].health, MappingHealth::error);
  EXPECT_EQ(rows[0].media, "model models/box.obj size 2");
}

}  // namespace
}  // namespace arwb::script::test
