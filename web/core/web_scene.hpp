// The phone player core's scene: the desktop's scene step (script::SceneStep: the tracker, the Lua sandbox with
// its limits, or the paper's XML database, and placement) on the markers WebDetector found, over media the page
// draws (recording_media.hpp). Plain C++ that knows nothing of JavaScript; exports.cpp exports it.
#pragma once
#include "recording_media.hpp"
#include "script/scene_step.hpp"
#include "web_detector.hpp"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace arwb::web {

class WebScene {
 public:
  WebScene();
  // Loads the scene file at `path` in the core's file system (the page puts the bundle's files under /bundle/).
  // {"ok": true|false, "error": "file:line: message", "dictionary": "NAME"|"", "mappings": [{"ids","media",
  // "placement","line"}]}.
  std::string load(const std::string& path);
  // A video's size and length as the page's <video> read them, by its path in the core's file system.
  void set_video(const std::string& path, int width, int height, double duration_s);
  // One frame at `t_s` seconds: the tracker and the scene on `d`'s last markers, with its camera and marker side.
  // {"tracks": [{"id","track","detected","corners"}], "overlays": overlays_json's, each video's also with "video":
  // {"t","playing","loop","duration"}, each text card's also with "card": {"lines","font_px","pad","line_h",
  // "ascent","width","height","colour":[r,g,b,a],"background":[r,g,b,a]} (its layout), each solid's "solid" also
  // with "mesh" (its id for mesh()) and "uniforms" (render/mesh_uniforms.hpp's, by their shader names), "errors":
  // [new error lines], "scene": {"ok","error","mappings":[{"state","health","reason"}], "console": [the newest
  // lines, when there are new ones]}}.
  const std::string& step(WebDetector& d, double t_s);
  // The mesh a step named `id`, its arrays in the module's memory until the next call: {"source": what the scene
  // named ("models/duck.glb", "cube"), "parts": [{"vertices": address, "floats": count
  // (render::interleaved_vertices'), "indices": address, "count": uint32 count, "colour": [r,g,b,a] in 0..1, "lit",
  // "normals", "uvs", "overlay_texture", "texture": the picture's path in the core's file system or "", "picture":
  // its index in pictures or -1, "name": the material's}], "pictures": [{"bytes": address, "length"}] (a model's
  // textures as encoded picture files, for the page to decode)}; {"error": "..."} for an id no step named or one
  // forgotten.
  const std::string& mesh(int id);
  // The bundle's self-test on the scene at `path` (web_self_test.hpp), beside the running scene, which it leaves
  // as it is.
  std::string self_test(const std::string& path);

 private:
  RecordingMedia media_;
  script::SceneStep step_;
  uint64_t console_serial_ = 0;
  uint64_t frame_index_ = 0;
  std::string result_;
  // The meshes steps named, each kept while drawn and for kKeepMeshFrames frames after, as the desktop keeps them.
  struct NamedMesh {
    int id = 0;
    std::shared_ptr<const Mesh> mesh;
    uint64_t last_frame = 0;
  };
  static constexpr uint64_t kKeepMeshFrames = 240;
  std::map<const Mesh*, NamedMesh> meshes_;
  int next_mesh_id_ = 1;
  std::vector<std::vector<float>> mesh_vertices_;   // the last mesh()'s
  std::string mesh_result_;
  int mesh_id(const std::shared_ptr<const Mesh>& mesh);
};

}  // namespace arwb::web
