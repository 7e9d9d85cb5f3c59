// The phone player core's scene (web_scene.hpp).
#include "web_scene.hpp"

#include "web_self_test.hpp"

#include "render/mesh_uniforms.hpp"
#include "track/overlay_json.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>

namespace arwb::web {

namespace {
using Json = nlohmann::ordered_json;

Json mapping_rows(const SceneStatus& s, bool live) {
  Json rows = Json::array();
  for (const MappingRow& m : s.mappings) {
    if (live)
      rows.push_back({{"state", m.state}, {"health", mapping_health_name(m.health)}, {"reason", m.reason}});
    else
      rows.push_back({{"ids", m.ids}, {"media", m.media}, {"placement", m.placement}, {"line", m.line}});
  }
  return rows;
}
Json uniforms_json(const render::MeshUniforms& u) {
  return {{"model_view", u.model_view}, {"normal_matrix", u.normal_matrix}, {"intrinsics", u.intrinsics},
          {"skew", u.skew}, {"knum", u.knum}, {"kden", u.kden}, {"tangential", u.tangential},
          {"r2_max", u.r2_max}, {"size", u.size}, {"depth", u.depth}};
}
}  // namespace

WebScene::WebScene() : step_(media_) {}

std::string WebScene::load(const std::string& path) {
  const bool ok = step_.load(path);
  const SceneStatus& s = step_.status();
  console_serial_ = 0;
  return Json{{"ok", ok}, {"error", s.error}, {"dictionary", step_.dictionary()}, {"mappings", mapping_rows(s, false)}}
      .dump();
}

void WebScene::set_video(const std::string& path, int width, int height, double duration_s) {
  media_.set_video(path, {width, height}, std::isfinite(duration_s) && duration_s > 0 ? duration_s : 0);
}

const std::string& WebScene::step(WebDetector& d, double t_s) {
  const cv::Size size = d.frame_size();
  std::string camera_error;
  const Calibration* camera = size.area() > 0 ? d.camera_for(size.width, size.height, &camera_error) : nullptr;
  script::SceneStepInput in;
  in.markers = &d.markers();
  in.image = size;
  in.calibration = camera;
  in.marker_side = d.marker_side() > 0 ? d.marker_side() : 1;
  in.unit = d.marker_side() > 0 ? "mm" : "marker sides";
  in.t_s = t_s;
  in.frame_index = ++frame_index_;
  const script::SceneStepOutput out = step_.run(in);
  Json tracks = Json::array();
  for (const TrackedMarker& t : out.tracks) {
    Json corners = Json::array();
    for (const auto& c : t.corners) corners.push_back({c.x, c.y});
    tracks.push_back({{"id", t.id}, {"track", t.track_id}, {"detected", t.detected}, {"corners", std::move(corners)}});
  }
  Json overlays = Json::array();
  for (const Overlay& o : out.overlays) {
    Json j = overlay_json(o);
    if (const auto* c = dynamic_cast<const CardContent*>(o.content.get())) {
      const media::CardLayout& l = c->layout();
      const auto rgba = [](const cv::Scalar& bgra) { return Json{bgra[2], bgra[1], bgra[0], bgra[3]}; };
      j["card"] = {{"lines", l.lines}, {"font_px", l.font_px}, {"pad", l.pad}, {"line_h", l.line_h},
                   {"ascent", l.ascent}, {"width", l.width}, {"height", l.height},
                   {"colour", rgba(o.media.colour)}, {"background", rgba(o.media.background)}};
    }
    if (o.solid && o.solid->mesh) {
      j["solid"]["mesh"] = mesh_id(o.solid->mesh);
      j["solid"]["uniforms"] = uniforms_json(render::mesh_uniforms(*o.solid, size));
    }
    if (const auto* v = dynamic_cast<const RecordedVideo*>(o.content.get()))
      j["video"] = {{"t", v->position_s()}, {"playing", v->playing()}, {"loop", v->loop()},
                    {"duration", v->duration_s()}};
    overlays.push_back(std::move(j));
  }
  const SceneStatus& s = step_.status();
  Json scene = {{"ok", s.ok}, {"error", s.error}, {"mappings", mapping_rows(s, true)}};
  if (s.console_serial != console_serial_) {
    console_serial_ = s.console_serial;
    Json lines = Json::array();
    const size_t first = s.console.size() > 20 ? s.console.size() - 20 : 0;
    for (size_t i = first; i < s.console.size(); ++i)
      lines.push_back({{"level", s.console[i].level}, {"text", s.console[i].text}, {"repeats", s.console[i].repeats}});
    scene["console"] = std::move(lines);
  }
  for (auto it = meshes_.begin(); it != meshes_.end();)
    it = frame_index_ - it->second.last_frame > kKeepMeshFrames ? meshes_.erase(it) : std::next(it);
  Json result = {{"tracks", std::move(tracks)}, {"overlays", std::move(overlays)}, {"errors", step_.take_errors()},
                 {"scene", std::move(scene)}};
  if (!camera_error.empty()) result["camera_error"] = camera_error;
  result_ = result.dump();
  return result_;
}

int WebScene::mesh_id(const std::shared_ptr<const Mesh>& mesh) {
  NamedMesh& m = meshes_[mesh.get()];
  if (m.mesh != mesh) m = {next_mesh_id_++, mesh, 0};   // new, or a new mesh at a freed address
  m.last_frame = frame_index_;
  return m.id;
}

const std::string& WebScene::mesh(int id) {
  mesh_vertices_.clear();
  const auto it = std::find_if(meshes_.begin(), meshes_.end(), [&](const auto& m) { return m.second.id == id; });
  if (it == meshes_.end()) {
    mesh_result_ = Json{{"error", "no mesh " + std::to_string(id) + " is drawn"}}.dump();
    return mesh_result_;
  }
  Json parts = Json::array(), pictures = Json::array();
  std::map<const EncodedPicture*, int> picture_index;   // a texture several parts share is sent once
  for (const MeshPart& part : it->second.mesh->parts) {
    mesh_vertices_.push_back(render::interleaved_vertices(part));
    const auto* picture = dynamic_cast<const SizedContent*>(part.texture.get());
    int encoded = -1;
    if (const auto* e = dynamic_cast<const EncodedPicture*>(part.texture.get())) {
      const auto [at, added] = picture_index.emplace(e, static_cast<int>(pictures.size()));
      if (added) pictures.push_back({{"bytes", reinterpret_cast<uintptr_t>(e->bytes().data())},
                                     {"length", e->bytes().size()}});
      encoded = at->second;
    }
    const size_t n = part.positions.size();
    parts.push_back({{"vertices", reinterpret_cast<uintptr_t>(mesh_vertices_.back().data())},
                     {"floats", mesh_vertices_.back().size()},
                     {"indices", reinterpret_cast<uintptr_t>(part.indices.data())},
                     {"count", part.indices.size()},
                     {"colour", render::part_colour(part, 1.0)},
                     {"lit", part.lit},
                     {"normals", n > 0 && part.normals.size() == n},
                     {"uvs", n > 0 && part.uvs.size() == n},
                     {"overlay_texture", part.overlay_texture},
                     {"texture", picture ? picture->path() : std::string()},
                     {"picture", encoded},
                     {"name", part.name}});
  }
  mesh_result_ =
      Json{{"source", it->second.mesh->source}, {"parts", std::move(parts)}, {"pictures", std::move(pictures)}}.dump();
  return mesh_result_;
}

std::string WebScene::self_test(const std::string& path) { return self_test_json(path, media_); }

}  // namespace arwb::web
