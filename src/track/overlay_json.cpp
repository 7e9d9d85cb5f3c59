#include "track/overlay_json.hpp"

namespace arwb {

namespace {
using Json = nlohmann::ordered_json;

Json point(const cv::Point2d& p) { return Json{p.x, p.y}; }

template <int R, int C>
Json matrix(const cv::Matx<double, R, C>& m) {
  Json a = Json::array();
  for (int i = 0; i < R * C; ++i) a.push_back(m.val[i]);
  return a;
}

Json vec3(const cv::Vec3d& v) { return Json{v[0], v[1], v[2]}; }
}  // namespace

Json overlay_json(const Overlay& o) {
  Json j = {{"marker", o.marker_id}, {"track", o.track_id}, {"mapping", o.mapping},
            {"kind", media_kind_name(o.media.kind)}, {"source", o.media.source}};
  if (o.media.kind == MediaKind::web) j["url"] = o.media.url, j["title"] = o.media.title;
  if (o.media.kind == MediaKind::text) j["text"] = o.media.text;
  j["place"] = o.place.describe();
  Json corners = Json::array();
  for (const cv::Point2d& c : o.quad.corners) corners.push_back(point(c));
  j["quad"] = {{"corners", std::move(corners)}, {"H", matrix(o.quad.H)}, {"uv_min", point(o.quad.uv_min)},
               {"uv_max", point(o.quad.uv_max)}, {"opacity", o.quad.opacity}};
  if (o.content) j["size"] = {o.content->size().width, o.content->size().height};
  if (o.solid)
    j["solid"] = {{"mesh_to_marker", matrix(o.solid->mesh_to_marker)}, {"rvec", vec3(o.solid->rvec)},
                  {"tvec", vec3(o.solid->tvec)}};
  return j;
}

Json overlays_json(const std::vector<Overlay>& overlays) {
  Json a = Json::array();
  for (const Overlay& o : overlays) a.push_back(overlay_json(o));
  return a;
}

}  // namespace arwb
