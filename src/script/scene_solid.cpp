// 3D media in the marker's frame, and flat media through the lens model.
#include "script/scene_runtime_impl.hpp"

#include "track/mesh.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace arwb::script {
namespace {

// The marker's own frame of placement.hpp (corner 0 at (0,0), y down, one unit a side) to OpenCV's marker frame
// (origin at the centre, y up).
const cv::Matx44d kOwnToMarker(1, 0, 0, -0.5, 0, -1, 0, 0.5, 0, 0, 1, 0, 0, 0, 0, 1);

std::string key_of(const MediaSpec& s) {
  std::string k = s.describe();
  char b[64];
  std::snprintf(b, sizeof b, "\n%g %d", s.thickness / s.size, s.lit ? 1 : 0);
  k += b;
  if (s.kind == MediaKind::cube)
    for (size_t f = 0; f < s.face_colour.size(); ++f) {
      std::snprintf(b, sizeof b, "\n%g %g %g %g ", s.face_colour[f][0], s.face_colour[f][1], s.face_colour[f][2],
                    s.face_colour[f][3]);
      k += b + s.face_image[f];
    }
  return k;
}

// The pose as the renderer takes it: tvec in marker sides.
void set_pose(SolidDraw* d, const TrackedMarker& t, const SceneInput& in) {
  d->rvec = t.pose->pose.rvec;
  d->tvec = t.pose->pose.tvec * (1.0 / (in.marker_side > 0 ? in.marker_side : 1.0));
  d->camera_matrix = in.camera->camera_matrix;
  d->distortion = in.camera->distortion;
}

}  // namespace

bool SceneRuntime::Impl::solid_overlay(Program& p, const Mapping& m, Instance& inst, const MediaSpec& spec,
                                       const PlaceSpec& place, const TrackedMarker& t, const SceneInput& in,
                                       Overlay* o) {
  const std::string at = p.display + ":" + std::to_string(m.line) + ": ";
  auto fail = [&](const std::string& why, int level) {
    inst.error = why;
    report(level, at + "marker " + std::to_string(t.id) + ": " + why);
    return false;
  };
  if (place.kind != PlaceKind::on_marker && place.kind != PlaceKind::beside)
    return fail(spec.describe() + " stands in the marker's 3D frame: place it on_marker or beside, not " +
                    std::string(place_kind_name(place.kind)),
                2);
  if (!in.camera || !t.pose) return fail("no pose for this marker, so its 3D media cannot be drawn", 1);

  // The mesh, made or loaded once per description.
  const std::string key = key_of(spec);
  if (inst.mesh_key != key) {
    inst.mesh_key = key;
    inst.mesh.reset();
    inst.load_error.clear();
    std::string err;
    switch (spec.kind) {
      case MediaKind::cube: {
        CubeLook look;
        look.colour = spec.face_colour;
        look.lit = spec.lit;
        for (size_t f = 0; f < spec.face_image.size(); ++f) {
          if (spec.face_image[f].empty()) continue;
          look.texture[f] = store.image(spec.face_image[f], &err);
          if (!look.texture[f]) report(2, at + (err.empty() ? spec.face_source[f] + ": cannot be loaded" : err));
        }
        inst.mesh = make_cube(look);
        break;
      }
      case MediaKind::axes: {
        auto axes = make_axes(spec.thickness / spec.size);
        for (MeshPart& part : axes->parts) part.lit = spec.lit;
        inst.mesh = axes;
        break;
      }
      case MediaKind::model: {
        std::string warning;
        inst.mesh = store.model(std::filesystem::path(p.path).parent_path(), spec.source, &err, &warning);
        if (!warning.empty()) report(1, at + warning);
        if (!inst.mesh) {
          inst.load_error = err.empty() ? spec.source + ": cannot be loaded" : err;
          report(2, at + inst.load_error);
        }
        if (inst.mesh && !spec.lit) {   // the store's mesh is shared: an unlit copy for this media
          auto flat = std::make_shared<Mesh>(*inst.mesh);
          for (MeshPart& part : flat->parts) part.lit = false;
          inst.mesh = flat;
        }
        break;
      }
      default: break;
    }
  }
  if (!inst.mesh) {
    inst.error = inst.load_error.empty() ? "cannot load " + spec.source : inst.load_error;
    return false;
  }

  SolidDraw d;
  d.mesh = inst.mesh;
  set_pose(&d, t, in);
  cv::Vec3d offset = spec.offset;
  if (place.kind == PlaceKind::beside) {
    // Beside the marker's edge, `gap` sides away, the media's own size deciding how far its centre is.
    const double reach = 0.5 + place.gap + spec.size / 2;
    switch (place.side) {
      case Side::right: offset[0] += reach; break;
      case Side::left: offset[0] -= reach; break;
      case Side::top: offset[1] += reach; break;
      case Side::bottom: offset[1] -= reach; break;
    }
  }
  const cv::Matx44d inner = spec.kind == MediaKind::model ? model_to_marker(*inst.mesh) : cv::Matx44d::eye();
  d.mesh_to_marker = place_in_marker(inner, offset, spec.rotate_deg, spec.size);

  // On screen, the box around the mesh's projected bounds: what a click or a label finds.
  std::vector<cv::Point3d> box;
  for (int i = 0; i < 8; ++i) {
    const cv::Vec3f& lo = inst.mesh->min;
    const cv::Vec3f& hi = inst.mesh->max;
    const cv::Vec4d q(i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2], 1);
    const cv::Vec4d r = d.mesh_to_marker * q;
    box.emplace_back(r[0], r[1], r[2]);
  }
  PoseSolution ps;
  ps.rvec = d.rvec;
  ps.tvec = d.tvec;
  const std::vector<cv::Point2d> px = project_marker_points(box, ps, *in.camera);
  double l = 1e18, r = -1e18, top = 1e18, b = -1e18;
  for (const cv::Point2d& q : px) {
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) continue;
    l = std::min(l, q.x);
    r = std::max(r, q.x);
    top = std::min(top, q.y);
    b = std::max(b, q.y);
  }
  if (!(l <= r && top <= b)) return fail("its 3D media falls outside the camera's view", 1);
  o->quad.corners = {cv::Point2d(l, top), cv::Point2d(r, top), cv::Point2d(r, b), cv::Point2d(l, b)};
  o->quad.H = cv::Matx33d::eye();
  o->quad.opacity = place.opacity;
  o->solid = std::move(d);
  return true;
}

void SceneRuntime::Impl::through_lens(const TrackedMarker& t, const SceneInput& in, Overlay* o) {
  if (!in.camera || in.camera->assumed || !t.pose || !o->quad.in_marker_plane) return;
  static const std::shared_ptr<const Mesh> flat = flat_media_mesh();
  const MediaQuad& q = o->quad;
  const cv::Matx33d& a = q.uv_to_marker;
  // Grid point g in [0,1]^2 -> the drawn part's texture coordinates -> the marker's own frame -> OpenCV's.
  const double du = q.uv_max.x - q.uv_min.x, dv = q.uv_max.y - q.uv_min.y;
  const cv::Matx44d window(du, 0, 0, q.uv_min.x, 0, dv, 0, q.uv_min.y, 0, 0, 1, 0, 0, 0, 0, 1);
  const cv::Matx44d affine(a(0, 0), a(0, 1), 0, a(0, 2), a(1, 0), a(1, 1), 0, a(1, 2), 0, 0, 1, 0, 0, 0, 0, 1);
  SolidDraw d;
  d.mesh = flat;
  set_pose(&d, t, in);
  d.mesh_to_marker = kOwnToMarker * affine * window;
  o->solid = std::move(d);
}

}  // namespace arwb::script
