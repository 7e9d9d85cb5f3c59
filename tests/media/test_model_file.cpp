// load_model and MediaStore::model: OBJ and glTF/GLB files written here by hand, what they become (counts,
// normals, texture coordinates, materials, node transforms), and the messages for what is refused.
#include "media/media_store.hpp"
#include "media/model_file.hpp"
#include "support/support.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using arwb::Mesh;
using arwb::MeshPart;
using arwb::media::load_model;
using arwb::media::MediaStore;
using arwb::media::ModelLimits;
using arwb::media::StoreMode;
using arwb::test::TempDir;
using arwb::test::write_file;
using json = nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

namespace {

constexpr float kEps = 1e-5f;

std::string png_bytes(int w, int h) {
  std::vector<uint8_t> out;
  EXPECT_TRUE(cv::imencode(".png", cv::Mat(h, w, CV_8UC3, cv::Scalar(10, 200, 30)), out));
  return std::string(out.begin(), out.end());
}

std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = static_cast<uint8_t>(bytes[i]) << 16 | static_cast<uint8_t>(bytes[i + 1]) << 8 |
                       static_cast<uint8_t>(bytes[i + 2]);
    for (int k = 18; k >= 0; k -= 6) out += kAlphabet[(v >> k) & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = static_cast<uint8_t>(bytes[i]) << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = static_cast<uint8_t>(bytes[i]) << 16 | static_cast<uint8_t>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

// A glTF document and its one binary buffer, built accessor by accessor.
struct Gltf {
  json doc = {{"asset", {{"version", "2.0"}}}};
  std::string bin;

  // Appends raw bytes as a buffer view (4-aligned); returns its index.
  int view(const std::string& bytes) {
    while (bin.size() % 4) bin += '\0';
    json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes.size()}};
    bin += bytes;
    doc["bufferViews"].push_back(v);
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  template <typename T>
  int accessor(const std::vector<T>& values, int component_type, const char* type, size_t width) {
    std::string bytes(values.size() * sizeof(T), '\0');
    std::memcpy(bytes.data(), values.data(), bytes.size());
    const int v = view(bytes);
    doc["accessors"].push_back(
        {{"bufferView", v}, {"componentType", component_type}, {"count", values.size() / width}, {"type", type}});
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  // One mesh of one triangle primitive; returns the mesh's index.
  int mesh(const std::vector<float>& positions, const std::vector<uint16_t>& indices,
           const std::vector<float>& normals = {}, const std::vector<float>& uvs = {}, int material = -1) {
    json prim = {{"attributes", {{"POSITION", accessor(positions, 5126, "VEC3", 3)}}}};
    if (!normals.empty()) prim["attributes"]["NORMAL"] = accessor(normals, 5126, "VEC3", 3);
    if (!uvs.empty()) prim["attributes"]["TEXCOORD_0"] = accessor(uvs, 5126, "VEC2", 2);
    if (!indices.empty()) prim["indices"] = accessor(indices, 5123, "SCALAR", 1);
    if (material >= 0) prim["material"] = material;
    doc["meshes"].push_back({{"primitives", json::array({prim})}});
    return static_cast<int>(doc["meshes"].size()) - 1;
  }
  // The buffer, named by `uri` (a file beside the .gltf, or "" for a GLB's own chunk); one node per mesh unless
  // the test placed them itself (meshes no node names are not drawn).
  void finish(const std::string& uri) {
    if (!doc.contains("nodes"))
      for (size_t i = 0; i < doc["meshes"].size(); ++i) doc["nodes"].push_back({{"mesh", i}});
    json buffer = {{"byteLength", bin.size()}};
    if (!uri.empty()) buffer["uri"] = uri;
    doc["buffers"] = json::array({buffer});
  }
  // `extras`: JSON text put as the asset's extras as it is (nesting that json's own dump would recurse through).
  std::string glb(const std::string& extras = "") {
    finish("");
    if (!extras.empty()) doc["asset"]["extras"] = "@extras@";
    std::string text = doc.dump();
    if (!extras.empty()) text.replace(text.find("\"@extras@\""), 10, extras);
    while (text.size() % 4) text += ' ';
    std::string chunk = bin;
    while (chunk.size() % 4) chunk += '\0';
    std::string out = "glTF";
    const auto u32 = [&](uint32_t v) {
      for (int k = 0; k < 4; ++k) out += static_cast<char>((v >> (8 * k)) & 0xFF);
    };
    u32(2);
    u32(static_cast<uint32_t>(12 + 8 + text.size() + 8 + chunk.size()));
    u32(static_cast<uint32_t>(text.size()));
    out += "JSON";
    out += text;
    u32(static_cast<uint32_t>(chunk.size()));
    out += std::string("BIN\0", 4);
    out += chunk;
    return out;
  }
};

// The unit square in the xy plane, facing +z, as two triangles.
const std::vector<float> kSquare = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const std::vector<float> kSquareNormals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
const std::vector<float> kSquareUvs = {0, 1, 1, 1, 1, 0, 0, 0};
const std::vector<uint16_t> kSquareIndices = {0, 1, 2, 0, 2, 3};

void expect_vec(const cv::Vec3f& got, const cv::Vec3f& want) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], want[i], kEps) << "component " << i << " of " << got;
}

class ModelFile : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(scene / "models"); }
  void write(const std::string& relative, const std::string& bytes) { write_file((scene / relative).string(), bytes); }
  arwb::Result<std::shared_ptr<Mesh>> load(const std::string& relative, const ModelLimits& limits = {}) {
    warning = "(not set)";
    return load_model(scene, relative, limits, &warning);
  }
  TempDir tmp;
  fs::path scene = tmp.path() / "scene";
  std::string warning;
};

const char* kHouseObj =
    "# a box and a roof\n"
    "mtllib house.mtl\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\n"
    "vn 0 0 2\n"
    "vt 0.25 0.75\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "usemtl wall\n"
    "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
    "usemtl roof\n"
    "f 4//1 3//1 5//1\n";
const char* kHouseMtl =
    "newmtl wall\nKd 1 0 0\nd 0.5\nmap_Kd wall.png\n"
    "newmtl roof\nKd 0 0 1\n";

// ---------------------------------------------------------------------------------------------------------------
// OBJ

TEST_F(ModelFile, ObjQuadIsFannedAndEachMaterialIsAPart) {
  write("models/house.obj", kHouseObj);
  write("models/house.mtl", kHouseMtl);
  write("models/wall.png", png_bytes(16, 8));
  const auto mesh = load("models/house.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(warning, "");
  const Mesh& m = **mesh;
  EXPECT_EQ(m.source, "models/house.obj");
  ASSERT_EQ(m.parts.size(), 2u);
  EXPECT_EQ(m.triangle_count(), 3u);  // the quad as two, the roof as one
  EXPECT_EQ(m.vertex_count(), 7u);    // 4 for the wall, 3 for the roof (corners are per part)
  const MeshPart& wall = m.parts[0];
  EXPECT_EQ(wall.name, "wall");
  EXPECT_EQ(wall.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(m.validate(), "");
  expect_vec(m.min, {0, 0, 0});
  expect_vec(m.max, {1, 1.5f, 0});
}

TEST_F(ModelFile, ObjNormalsAreUnitAndTextureCoordinatesFlipV) {
  write("models/house.obj", kHouseObj);
  write("models/house.mtl", kHouseMtl);
  write("models/wall.png", png_bytes(16, 8));
  const auto mesh = load("models/house.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  const MeshPart& wall = (*mesh)->parts[0];
  ASSERT_EQ(wall.normals.size(), 4u);
  for (const cv::Vec3f& n : wall.normals) expect_vec(n, {0, 0, 1});  // "vn 0 0 2" normalised
  ASSERT_EQ(wall.uvs.size(), 4u);
  EXPECT_NEAR(wall.uvs[0][0], 0.25f, kEps);
  EXPECT_NEAR(wall.uvs[0][1], 0.25f, kEps);  // vt 0.25 0.75: v runs up in OBJ, down from the top here
  EXPECT_NEAR(wall.uvs[1][1], 1.0f, kEps);
  // The roof's faces have normals but no texture coordinates.
  const MeshPart& roof = (*mesh)->parts[1];
  EXPECT_EQ(roof.normals.size(), 3u);
  EXPECT_TRUE(roof.uvs.empty());
}

TEST_F(ModelFile, ObjMaterialColourAndTexture) {
  write("models/house.obj", kHouseObj);
  write("models/house.mtl", kHouseMtl);
  write("models/wall.png", png_bytes(16, 8));
  const auto mesh = load("models/house.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  const MeshPart& wall = (*mesh)->parts[0];
  EXPECT_EQ(wall.colour, cv::Scalar(0, 0, 255, 127.5));  // Kd 1 0 0, d 0.5, as BGRA
  ASSERT_TRUE(wall.texture);
  EXPECT_EQ(wall.texture->size(), cv::Size(16, 8));
  const MeshPart& roof = (*mesh)->parts[1];
  EXPECT_EQ(roof.colour, cv::Scalar(255, 0, 0, 255));
  EXPECT_FALSE(roof.texture);
}

TEST_F(ModelFile, ObjCornersWithDifferentTextureCoordinatesAreDifferentVertices) {
  write("models/seam.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 0.5 0.5\n"
        "f 1/1 2/2 3/3\nf 2/4 4/2 3/3\n");
  const auto mesh = load("models/seam.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ((*mesh)->triangle_count(), 2u);
  EXPECT_EQ((*mesh)->vertex_count(), 5u);  // vertex 2 appears with two texture coordinates; 3/3 is shared
  EXPECT_TRUE((*mesh)->parts[0].normals.empty());
  EXPECT_EQ((*mesh)->parts[0].name, "default");
  EXPECT_EQ((*mesh)->parts[0].colour, cv::Scalar(255, 255, 255, 255));
}

TEST_F(ModelFile, ObjMissingTextureOrLibraryWarnsAndKeepsTheModel) {
  write("models/house.obj", kHouseObj);
  write("models/house.mtl", kHouseMtl);  // wall.png is not there
  auto mesh = load("models/house.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(warning, "models/house.obj: material 'wall' map_Kd: wall.png: no such file");
  EXPECT_FALSE((*mesh)->parts[0].texture);
  EXPECT_EQ((*mesh)->parts[0].colour, cv::Scalar(0, 0, 255, 127.5));

  write("models/bare.obj", "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  mesh = load("models/bare.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(warning, "models/bare.obj: mtllib gone.mtl: no such file");
}

TEST_F(ModelFile, ObjTextureThatIsNotAnImageWarns) {
  write("models/house.obj", kHouseObj);
  write("models/house.mtl", kHouseMtl);
  write("models/wall.png", "just text");
  const auto mesh = load("models/house.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_THAT(warning, StartsWith("models/house.obj: material 'wall' map_Kd: wall.png: "));
  EXPECT_FALSE((*mesh)->parts[0].texture);
}

TEST_F(ModelFile, ObjFaceIndexOutOfRangeNamesTheLine) {
  write("models/bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n# comment\nf 1 2 3\nf 1 2 9\n");
  const auto mesh = load("models/bad.obj");
  ASSERT_FALSE(mesh.ok());
  EXPECT_EQ(mesh.error(), "models/bad.obj:6: face index 9 out of range (3 vertices)");

  write("models/bad_vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/4\n");
  EXPECT_EQ(load("models/bad_vt.obj").error(),
            "models/bad_vt.obj:5: texture coordinate index 4 out of range (1 texture coordinates)");
}

TEST_F(ModelFile, ObjWithoutFacesHasNoTriangles) {
  write("models/points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  EXPECT_EQ(load("models/points.obj").error(), "models/points.obj: no triangles");
}

// ---------------------------------------------------------------------------------------------------------------
// What is not a model, and limits

TEST_F(ModelFile, RefusesFilesThatAreNotModelsByTheirBytes) {
  write("models/picture.obj", png_bytes(4, 4));
  EXPECT_EQ(load("models/picture.obj").error(), "models/picture.obj: not a 3D model (OBJ, glTF or GLB)");
  write("models/notes.obj", "Dear reader,\nthis is a letter.\n");
  EXPECT_EQ(load("models/notes.obj").error(), "models/notes.obj: not a 3D model (OBJ, glTF or GLB)");
  write("models/empty.obj", "");
  EXPECT_EQ(load("models/empty.obj").error(), "models/empty.obj: empty file (0 bytes)");
  write("models/other.json", R"({"name": "not a glTF"})");
  EXPECT_EQ(load("models/other.json").error(), "models/other.json: not a 3D model (OBJ, glTF or GLB)");
  EXPECT_EQ(load("models/none.obj").error(), "models/none.obj: no such file");
  EXPECT_EQ(load("models").error(), "models: not a regular file (folder)");
}

TEST_F(ModelFile, RefusesWhatIsTooLarge) {
  write("models/house.obj", kHouseObj);
  write("models/house.mtl", kHouseMtl);
  ModelLimits small;
  small.file_bytes = 100;
  EXPECT_EQ(load("models/house.obj", small).error(),
            "models/house.obj: " + std::to_string(std::string(kHouseObj).size()) +
                " bytes, more than the limit of 100 bytes");
  ModelLimits few_triangles;
  few_triangles.triangles = 2;
  EXPECT_EQ(load("models/house.obj", few_triangles).error(), "models/house.obj: 3 triangles, more than the limit of 2");
  // Counted from the text before the file is parsed: the faces come before a material library the parse would
  // refuse, and the limit is what is said.
  write("models/many.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\nf\t1 2 3\r\nmtllib ../outside.mtl\n");
  EXPECT_EQ(load("models/many.obj", few_triangles).error(), "models/many.obj: 3 triangles, more than the limit of 2");
  ModelLimits few_vertices;
  few_vertices.vertices = 6;
  EXPECT_EQ(load("models/house.obj", few_vertices).error(), "models/house.obj: more than the limit of 6 vertices");

  Gltf g;
  g.mesh(kSquare, kSquareIndices);
  write("models/square.glb", g.glb());
  ModelLimits three_vertices;
  three_vertices.vertices = 3;
  EXPECT_EQ(load("models/square.glb", three_vertices).error(),
            "models/square.glb: 4 vertices, more than the limit of 3");
  ModelLimits one_triangle;
  one_triangle.triangles = 1;
  EXPECT_EQ(load("models/square.glb", one_triangle).error(),
            "models/square.glb: 2 triangles, more than the limit of 1");
  small.file_bytes = 64;
  EXPECT_THAT(load("models/square.glb", small).error(), HasSubstr(" bytes, more than the limit of 64 bytes"));
}

// ---------------------------------------------------------------------------------------------------------------
// Paths: the model and everything it names stay inside the scene's folder

TEST_F(ModelFile, RefusesModelsOutsideTheFolder) {
  write_file((tmp.path() / "outside.obj").string(), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(load("../outside.obj").error(), "../outside.obj: leaves the scene's folder");
  const std::string absolute = (tmp.path() / "outside.obj").string();
  EXPECT_EQ(load(absolute).error(), absolute + ": absolute paths are not allowed");
  fs::create_symlink(tmp.path() / "outside.obj", scene / "models/link.obj");
  EXPECT_EQ(load("models/link.obj").error(), "models/link.obj: leaves the scene's folder");
}

TEST_F(ModelFile, RefusesMaterialLibrariesAndTexturesOutsideTheFolder) {
  write_file((tmp.path() / "outside.mtl").string(), "newmtl wall\nKd 1 0 0\n");
  write_file((tmp.path() / "outside.png").string(), png_bytes(4, 4));
  const std::string face = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl wall\nf 1/1 2/1 3/1\n";

  write("models/up.obj", "mtllib ../../outside.mtl\n" + face);
  EXPECT_EQ(load("models/up.obj").error(), "models/up.obj: mtllib ../../outside.mtl: leaves the scene's folder");
  const std::string absolute = (tmp.path() / "outside.mtl").string();
  write("models/abs.obj", "mtllib " + absolute + "\n" + face);
  EXPECT_EQ(load("models/abs.obj").error(), "models/abs.obj: mtllib " + absolute + ": absolute paths are not allowed");
  fs::create_symlink(tmp.path() / "outside.mtl", scene / "models/link.mtl");
  write("models/link.obj", "mtllib link.mtl\n" + face);
  EXPECT_EQ(load("models/link.obj").error(), "models/link.obj: mtllib link.mtl: leaves the scene's folder");

  // Textures named by a library inside the folder.
  write("models/tex.obj", "mtllib tex.mtl\n" + face);
  write("models/tex.mtl", "newmtl wall\nmap_Kd ../../outside.png\n");
  EXPECT_EQ(load("models/tex.obj").error(),
            "models/tex.obj: material 'wall' map_Kd: ../../outside.png: leaves the scene's folder");
  fs::create_symlink(tmp.path() / "outside.png", scene / "models/link.png");
  write("models/tex.mtl", "newmtl wall\nmap_Kd link.png\n");
  EXPECT_EQ(load("models/tex.obj").error(),
            "models/tex.obj: material 'wall' map_Kd: link.png: leaves the scene's folder");

  // A reference is relative to the model's folder: "house.mtl" beside the model, not beside the scene.
  write("house.mtl", "newmtl wall\nKd 0 1 0\n");
  write("models/near.obj", "mtllib house.mtl\n" + face);
  const auto mesh = load("models/near.obj");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(warning, "models/near.obj: mtllib house.mtl: no such file");
}

TEST_F(ModelFile, RefusesBuffersOutsideTheFolderOrMissing) {
  Gltf g;
  g.mesh(kSquare, kSquareIndices);
  write_file((tmp.path() / "outside.bin").string(), g.bin);
  const auto with_buffer = [&](const std::string& uri) {
    g.finish(uri);
    write("models/sq.gltf", g.doc.dump());
    return load("models/sq.gltf").error();
  };
  EXPECT_EQ(with_buffer("../../outside.bin"), "models/sq.gltf: buffer 0: ../../outside.bin: leaves the scene's folder");
  const std::string absolute = (tmp.path() / "outside.bin").string();
  EXPECT_EQ(with_buffer(absolute), "models/sq.gltf: buffer 0: " + absolute + ": absolute paths are not allowed");
  fs::create_symlink(tmp.path() / "outside.bin", scene / "models/link.bin");
  EXPECT_EQ(with_buffer("link.bin"), "models/sq.gltf: buffer 0: link.bin: leaves the scene's folder");
  EXPECT_EQ(with_buffer("gone.bin"), "models/sq.gltf: buffer 0: gone.bin: no such file");
  write("models/short.bin", g.bin.substr(0, 10));
  EXPECT_EQ(with_buffer("short.bin"), "models/sq.gltf: buffer 0: short.bin: 10 bytes, its byteLength says 60");
}

// ---------------------------------------------------------------------------------------------------------------
// glTF and GLB

TEST_F(ModelFile, GltfWithItsBufferBesideIt) {
  Gltf g;
  g.doc["materials"] =
      json::array({{{"name", "paint"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1.0, 0.5, 0.0, 1.0}}}}}});
  g.mesh(kSquare, kSquareIndices, kSquareNormals, kSquareUvs, 0);
  g.doc["nodes"] = json::array({{{"mesh", 0}}});
  g.doc["scenes"] = json::array({{{"nodes", {0}}}});
  g.doc["scene"] = 0;
  g.finish("square data.bin");  // a space, as the file is named
  write("models/square data.bin", g.bin);
  write("models/square.gltf", g.doc.dump(2));
  const auto mesh = load("models/square.gltf");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(warning, "");
  const Mesh& m = **mesh;
  EXPECT_EQ(m.source, "models/square.gltf");
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(m.vertex_count(), 4u);
  ASSERT_EQ(m.parts.size(), 1u);
  EXPECT_EQ(m.parts[0].name, "paint");
  EXPECT_EQ(m.parts[0].colour, cv::Scalar(0, 127.5, 255, 255));
  ASSERT_EQ(m.parts[0].normals.size(), 4u);
  expect_vec(m.parts[0].normals[2], {0, 0, 1});
  ASSERT_EQ(m.parts[0].uvs.size(), 4u);
  EXPECT_EQ(m.parts[0].uvs[2], cv::Vec2f(1, 0));  // glTF's (0,0) is already the top-left: kept as written
  expect_vec(m.min, {0, 0, 0});
  expect_vec(m.max, {1, 1, 0});
}

TEST_F(ModelFile, GltfNodeTransformsAreAppliedDownTheHierarchy) {
  Gltf g;
  g.mesh(kSquare, kSquareIndices, kSquareNormals);
  // Root: moved 10 along x; child: scaled by 2 and turned a quarter about z (x becomes y).
  const double s = std::sqrt(0.5);
  g.doc["nodes"] = json::array({{{"children", {1}}, {"translation", {10, 0, 0}}},
                                {{"mesh", 0}, {"scale", {2, 2, 2}}, {"rotation", {0, 0, s, s}}}});
  write("models/moved.glb", g.glb());
  auto mesh = load("models/moved.glb");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  expect_vec((*mesh)->min, {8, 0, 0});
  expect_vec((*mesh)->max, {10, 2, 0});
  expect_vec((*mesh)->parts[0].normals[0], {0, 0, 1});

  // The same as one column-major matrix; a mirroring matrix keeps the faces facing out (winding reversed).
  Gltf h;
  h.mesh(kSquare, kSquareIndices, kSquareNormals);
  h.doc["nodes"] = json::array({{{"mesh", 0}, {"matrix", {-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 6, 7, 1}}}});
  write("models/mirror.glb", h.glb());
  mesh = load("models/mirror.glb");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  expect_vec((*mesh)->min, {4, 6, 7});
  expect_vec((*mesh)->max, {5, 7, 7});
  EXPECT_EQ((*mesh)->parts[0].indices, (std::vector<uint32_t>{0, 2, 1, 0, 3, 2}));
}

TEST_F(ModelFile, GlbWithAnEmbeddedTexture) {
  Gltf g;
  const int image_view = g.view(png_bytes(16, 8));
  g.doc["images"] = json::array({{{"bufferView", image_view}, {"mimeType", "image/png"}}});
  g.doc["textures"] = json::array({{{"source", 0}}});
  g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  g.mesh(kSquare, kSquareIndices, {}, kSquareUvs, 0);
  write("models/textured.glb", g.glb());
  const auto mesh = load("models/textured.glb");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(warning, "");
  const MeshPart& part = (*mesh)->parts[0];
  EXPECT_EQ(part.name, "material 0");
  ASSERT_TRUE(part.texture);
  EXPECT_EQ(part.texture->size(), cv::Size(16, 8));
  EXPECT_EQ(part.colour, cv::Scalar(255, 255, 255, 255));
  EXPECT_TRUE(part.normals.empty());
}

TEST_F(ModelFile, GltfDataUriBufferAndExternalImage) {
  Gltf g;
  g.mesh(kSquare, kSquareIndices, {}, kSquareUvs, 0);
  g.doc["images"] = json::array({{{"uri", "tex.png"}}});
  g.doc["textures"] = json::array({{{"source", 0}}});
  g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  g.finish("data:application/octet-stream;base64," + base64(g.bin));
  write("models/inline.gltf", g.doc.dump());
  write("models/tex.png", png_bytes(6, 4));
  auto mesh = load("models/inline.gltf");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  ASSERT_TRUE((*mesh)->parts[0].texture);
  EXPECT_EQ((*mesh)->parts[0].texture->size(), cv::Size(6, 4));

  // The image missing: a warning, the model kept; leading out: refused.
  fs::remove(scene / "models/tex.png");
  mesh = load("models/inline.gltf");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(warning, "models/inline.gltf: image 0: tex.png: no such file");
  EXPECT_FALSE((*mesh)->parts[0].texture);
  write_file((tmp.path() / "outside.png").string(), png_bytes(4, 4));
  fs::create_symlink(tmp.path() / "outside.png", scene / "models/tex.png");
  EXPECT_EQ(load("models/inline.gltf").error(), "models/inline.gltf: image 0: tex.png: leaves the scene's folder");
}

TEST_F(ModelFile, GltfFilesBeyondTheLimit) {
  Gltf g;
  g.mesh(kSquare, kSquareIndices, {}, kSquareUvs, 0);
  g.doc["images"] = json::array({{{"uri", "noise.png"}}});
  g.doc["textures"] = json::array({{{"source", 0}}});
  g.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  cv::Mat noise(64, 64, CV_8UC3);
  cv::randu(noise, 0, 256);
  ASSERT_TRUE(cv::imwrite((scene / "models/noise.png").string(), noise));
  const auto noise_bytes = fs::file_size(scene / "models/noise.png");
  ASSERT_GT(noise_bytes, 2000u);
  ModelLimits limits;
  limits.file_bytes = 2000;

  // An image too large: a warning, the model kept with its colour.
  g.finish("square.bin");
  write("models/square.bin", g.bin);
  write("models/square.gltf", g.doc.dump());
  const auto mesh = load("models/square.gltf", limits);
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ(warning, "models/square.gltf: image 0: noise.png: " + std::to_string(noise_bytes) +
                         " bytes, more than the limit of 2000 bytes");
  EXPECT_FALSE((*mesh)->parts[0].texture);

  // A buffer too large: refused.
  g.view(std::string(3000, 'x'));
  g.finish("square.bin");
  write("models/square.bin", g.bin);
  write("models/square.gltf", g.doc.dump());
  EXPECT_EQ(load("models/square.gltf", limits).error(),
            "models/square.gltf: buffer 0: square.bin: " + std::to_string(g.bin.size()) +
                " bytes, more than the limit of 2000 bytes");
}

TEST_F(ModelFile, GltfRefusesBrokenFiles) {
  write("models/garbage.gltf", "{ \"asset\": {\"version\": \"2.0\"}, nonsense ]");
  EXPECT_EQ(load("models/garbage.gltf").error(), "models/garbage.gltf: invalid JSON at byte 33");
  write("models/garbage.glb", "glTF" + std::string("\x02\0\0\0\x1c\0\0\0\x08\0\0\0JSON{{{{[[[[", 24));
  EXPECT_EQ(load("models/garbage.glb").error(), "models/garbage.glb: invalid JSON at byte 2");
  // Valid syntax, but a number beyond a double: nlohmann's parser throws another exception than for syntax.
  write("models/huge.gltf", R"({"asset": {"version": "2.0"}, "nodes": [{"scale": [1e999, 1, 1]}]})");
  EXPECT_EQ(load("models/huge.gltf").error(), "models/huge.gltf: invalid JSON (number overflow parsing '1e999')");
  write("models/no_asset.gltf", R"({"meshes": []})");
  EXPECT_EQ(load("models/no_asset.gltf").error(), "models/no_asset.gltf: not a 3D model (OBJ, glTF or GLB)");

  Gltf g;
  g.mesh(kSquare, {0, 1, 2, 0, 2, 7});
  write("models/index.glb", g.glb());
  EXPECT_EQ(load("models/index.glb").error(),
            "models/index.glb: mesh 0 primitive 0: index 7 out of range (4 vertices)");

  Gltf whole;
  whole.mesh(kSquare, kSquareIndices);
  const std::string glb = whole.glb();
  write("models/truncated.glb", glb.substr(0, glb.size() - 20));
  EXPECT_EQ(load("models/truncated.glb").error(), "models/truncated.glb: truncated GLB (the header says " +
                                                      std::to_string(glb.size()) + " bytes, the file has " +
                                                      std::to_string(glb.size() - 20) + ")");
  write("models/stub.glb", glb.substr(0, 10));
  EXPECT_EQ(load("models/stub.glb").error(), "models/stub.glb: truncated GLB (10 bytes)");

  // An image in a buffer view that reaches past its buffer (tinygltf itself would read past the end).
  Gltf img;
  const int view = img.view(png_bytes(4, 4));
  img.doc["bufferViews"][view]["byteLength"] = 100000;
  img.doc["images"] = json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
  img.mesh(kSquare, kSquareIndices);
  write("models/image_view.glb", img.glb());
  EXPECT_EQ(load("models/image_view.glb").error(),
            "models/image_view.glb: image 0: buffer view 0 reaches past the end of its buffer");

  // An accessor claiming more elements than its buffer view holds.
  Gltf far;
  far.mesh(kSquare, kSquareIndices);
  far.doc["accessors"][0]["count"] = 1000;
  write("models/far.glb", far.glb());
  EXPECT_EQ(load("models/far.glb").error(),
            "models/far.glb: mesh 0 primitive 0 POSITION: accessor 0 reaches past the end of its buffer");
}

// tinygltf copies `extras` into its own values recursively: 20,000 nested arrays (40 KB) overflowed the stack of
// every program that loads a model. The depth is checked first; nesting a model may have still loads.
TEST_F(ModelFile, GltfNestedDeeperThanTheLimitIsRefusedBeforeItIsParsed) {
  const std::string deep = std::string(20000, '[') + std::string(20000, ']');
  write("models/deep.gltf", "{\"asset\": {\"version\": \"2.0\",\n\"extras\": " + deep + "}}");
  EXPECT_EQ(load("models/deep.gltf").error(), "models/deep.gltf:2: nested deeper than 64 levels");
  Gltf glb;
  glb.mesh(kSquare, kSquareIndices);
  write("models/deep.glb", glb.glb(deep));
  EXPECT_EQ(load("models/deep.glb").error(), "models/deep.glb:1: nested deeper than 64 levels");

  Gltf ok;
  ok.mesh(kSquare, kSquareIndices);
  json extras = json::array();
  for (int i = 0; i < 60; ++i) extras = json::array({extras});
  ok.doc["asset"]["extras"] = extras;
  write("models/nested.glb", ok.glb());
  EXPECT_TRUE(load("models/nested.glb").ok()) << load("models/nested.glb").error();
}

TEST_F(ModelFile, GltfWithoutTrianglesSkipsOtherModes) {
  Gltf g;
  g.mesh(kSquare, {});
  g.doc["meshes"][0]["primitives"][0]["mode"] = 0;  // points
  write("models/points.glb", g.glb());
  EXPECT_EQ(load("models/points.glb").error(), "models/points.glb: no triangles");

  // Points beside triangles: the triangles are kept, the points skipped with a warning.
  Gltf h;
  h.mesh(kSquare, kSquareIndices);
  json points = h.doc["meshes"][0]["primitives"][0];
  points["mode"] = 0;
  points.erase("indices");
  h.doc["meshes"][0]["primitives"].push_back(points);
  write("models/mixed.glb", h.glb());
  const auto mesh = load("models/mixed.glb");
  ASSERT_TRUE(mesh.ok()) << mesh.error();
  EXPECT_EQ((*mesh)->triangle_count(), 2u);
  EXPECT_EQ(warning, "models/mixed.glb: primitives of mode 0 skipped (only triangles are drawn)");
}

// ---------------------------------------------------------------------------------------------------------------
// The store's cache, and the examples we ship

TEST_F(ModelFile, StoreSharesAModelWhileHeldAndNamesFailures) {
  write("models/house.obj", kHouseObj);
  write("models/house.mtl", kHouseMtl);
  MediaStore store(StoreMode::offline);
  std::string error = "x", warned = "x";
  const auto a = store.model(scene, "models/house.obj", &error, &warned);
  ASSERT_TRUE(a) << error;
  EXPECT_EQ(error, "");
  EXPECT_EQ(warned, "models/house.obj: material 'wall' map_Kd: wall.png: no such file");
  warned.clear();
  const auto b = store.model(scene, "./models/house.obj", &error, &warned);
  EXPECT_EQ(a.get(), b.get());                                                            // one file, one mesh
  EXPECT_EQ(warned, "models/house.obj: material 'wall' map_Kd: wall.png: no such file");  // said again

  const auto none = store.model(scene, "models/none.obj", &error, &warned);
  EXPECT_FALSE(none);
  EXPECT_EQ(error, "models/none.obj: no such file");
}

TEST(ModelExamples, HouseAndMarkerPostLoad) {
  const fs::path models = fs::path(ARWB_SOURCE_DIR) / "scripts/models";
  std::string warned;
  const auto house = load_model(models, "house.obj", {}, &warned);
  ASSERT_TRUE(house.ok()) << house.error();
  EXPECT_EQ(warned, "");
  ASSERT_EQ((*house)->parts.size(), 2u);
  EXPECT_EQ((*house)->parts[0].name, "walls");
  EXPECT_EQ((*house)->parts[1].name, "roof");
  EXPECT_EQ((*house)->triangle_count(), 16u);
  expect_vec((*house)->min, {-0.5f, 0, -0.5f});
  expect_vec((*house)->max, {0.5f, 1.6f, 0.5f});

  // Three nodes under a root that halves them: the base plate, the pole on it, the cap turned 45 degrees on top.
  const auto post = load_model(models, "marker_post.gltf", {}, &warned);
  ASSERT_TRUE(post.ok()) << post.error();
  EXPECT_EQ(warned, "");
  ASSERT_EQ((*post)->parts.size(), 3u);
  EXPECT_EQ((*post)->parts[2].name, "cap");
  EXPECT_EQ((*post)->triangle_count(), 12u + 12u + 6u);
  expect_vec((*post)->min, {-0.2f, 0, -0.2f});
  expect_vec((*post)->max, {0.2f, 0.95f, 0.2f});
}

}  // namespace
