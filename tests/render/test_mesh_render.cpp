// 3D media: meshes drawn through the marker's pose and the lens model land where cv::projectPoints puts them
// (within a pixel), hidden faces stay hidden behind the depth buffer, and a flat media drawn through a
// distorting lens follows the distorted marker. Offscreen, on Mesa's llvmpipe, as `arwb render` draws.
#include "render/compositor.hpp"
#include "render/mesh_renderer.hpp"
#include "render/offscreen.hpp"
#include "track/mesh.hpp"

#include "still_media.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <cmath>
#include <cstdio>

namespace arwb {
namespace {

using StillMedia = test::StillMedia;

const cv::Size kFrame(640, 480);
const cv::Matx33d kK(600, 0, 319.5, 0, 600, 239.5, 0, 0, 1);

// The unit cube standing on the marker (mesh.hpp): each face's corners, in the order make_cube draws them,
// and its outward normal.
struct Face {
  std::array<cv::Vec3d, 4> corners;
  cv::Vec3d normal;
};
std::array<Face, kCubeFaces> cube_faces() {
  const double h = 0.5;
  return {{
      {{{{h, -h, 0}, {h, h, 0}, {h, h, 1}, {h, -h, 1}}}, {1, 0, 0}},
      {{{{-h, -h, 0}, {-h, h, 0}, {-h, h, 1}, {-h, -h, 1}}}, {-1, 0, 0}},
      {{{{-h, h, 0}, {h, h, 0}, {h, h, 1}, {-h, h, 1}}}, {0, 1, 0}},
      {{{{-h, -h, 0}, {h, -h, 0}, {h, -h, 1}, {-h, -h, 1}}}, {0, -1, 0}},
      {{{{-h, -h, 1}, {h, -h, 1}, {h, h, 1}, {-h, h, 1}}}, {0, 0, 1}},
      {{{{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}}}, {0, 0, -1}},
  }};
}

// The outline of a planar polygon (3D, in the frame `to_marker` maps to the marker's) as the camera sees it:
// every edge sampled densely and projected with the lens model, so distortion bends it.
std::vector<cv::Point2d> projected_outline(const std::vector<cv::Vec3d>& polygon, const cv::Matx44d& to_marker,
                                           cv::Vec3d rvec, cv::Vec3d tvec, const std::vector<double>& dist) {
  std::vector<cv::Point3d> pts;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const cv::Vec3d a = polygon[i], b = polygon[(i + 1) % polygon.size()];
    for (int k = 0; k < 200; ++k) {
      const cv::Vec3d p = a + (b - a) * (k / 200.0);
      const cv::Vec4d q = to_marker * cv::Vec4d(p[0], p[1], p[2], 1);
      pts.emplace_back(q[0], q[1], q[2]);
    }
  }
  std::vector<cv::Point2d> out;
  cv::projectPoints(pts, rvec, tvec, kK, dist, out);
  return out;
}

struct Agreement {
  double worst_outside = 0;   // px: how far the farthest drawn pixel lies outside the expected outline
  int missing_inside = 0;     // pixels more than 1 px inside the outline that were not drawn
  int drawn = 0;
};

// Compares a drawn mask with the expected outline, pixel centres at integer coordinates. Only the outline's
// bounding box (and a margin) is measured pixel by pixel; a drawn pixel beyond it counts as far outside.
Agreement compare(const cv::Mat& drawn, const std::vector<cv::Point2d>& outline) {
  std::vector<cv::Point2f> contour(outline.begin(), outline.end());
  const cv::Rect box = cv::boundingRect(contour) + cv::Size(6, 6) - cv::Point(3, 3);
  Agreement a;
  for (int y = 0; y < drawn.rows; ++y)
    for (int x = 0; x < drawn.cols; ++x) {
      const bool on = drawn.at<uchar>(y, x) != 0;
      if (!box.contains({x, y})) {
        if (on) {
          ++a.drawn;
          a.worst_outside = std::max(a.worst_outside, 3.0);
        }
        continue;
      }
      const double d = cv::pointPolygonTest(contour, cv::Point2f(float(x), float(y)), true);
      if (on) {
        ++a.drawn;
        a.worst_outside = std::max(a.worst_outside, -d);
      } else if (d > 1.0) {
        ++a.missing_inside;
      }
    }
  return a;
}

// Pixels of one pure hue (lit or not): the channel `c` (B=0, G=1, R=2) strong, the two others weak.
cv::Mat hue_mask(const cv::Mat& bgr, int c) {
  cv::Mat m(bgr.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      const int v = p[c], o1 = p[(c + 1) % 3], o2 = p[(c + 2) % 3];
      m.at<uchar>(y, x) = v > 60 && o1 < v / 4 && o2 < v / 4 ? 255 : 0;
    }
  return m;
}

// Pixels where two channels are strong (the hidden faces' yellow, cyan and magenta) more than 1.5 px inside the
// outline: a hidden face drawn over a visible one. (On the edges between two visible faces, smoothing mixes
// their hues: those pixels are not counted.)
int hidden_hue_pixels(const cv::Mat& bgr, const std::vector<cv::Point2d>& outline) {
  std::vector<cv::Point2f> contour(outline.begin(), outline.end());
  const cv::Rect box = cv::boundingRect(contour) & cv::Rect(0, 0, bgr.cols, bgr.rows);
  int n = 0;
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      int strong = 0;
      for (int c = 0; c < 3; ++c) strong += p[c] > 60;
      if (strong >= 2 && cv::pointPolygonTest(contour, cv::Point2f(float(x), float(y)), true) > 1.5) ++n;
    }
  return n;
}

// A marker facing the camera (its z towards it, upright), then turned by `tilt` (a Rodrigues vector in the
// marker's frame): a pose a detector can see.
cv::Vec3d facing(cv::Vec3d tilt) {
  cv::Matx33d T;
  cv::Rodrigues(tilt, T);
  cv::Vec3d rvec;
  cv::Rodrigues(cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1) * T, rvec);
  return rvec;
}

struct CubeCase {
  cv::Vec3d rvec, tvec;
  std::vector<double> dist;
  cv::Matx44d to_marker;   // the cube's mesh to the marker frame
};

// Draws the cube with its three faces toward the camera in red, green and blue and the three others in mixed
// hues, then checks each visible face against its projected outline and that no hidden face shows.
void check_cube(const CubeCase& c) {
  render::OffscreenContext context;
  ASSERT_TRUE(context.ok()) << context.error();
  cv::Matx33d R;
  cv::Rodrigues(c.rvec, R);
  const auto faces = cube_faces();
  CubeLook look;
  std::vector<int> visible;
  const cv::Scalar pure[3] = {{0, 0, 255, 255}, {0, 255, 0, 255}, {255, 0, 0, 255}};
  const cv::Scalar mixed[3] = {{0, 255, 255, 255}, {255, 255, 0, 255}, {255, 0, 255, 255}};
  int hidden = 0;
  for (int f = 0; f < kCubeFaces; ++f) {
    // Facing the camera: its outward normal points towards the camera from the face's centre.
    cv::Vec3d centre(0, 0, 0);
    for (const cv::Vec3d& p : faces[size_t(f)].corners) centre += p * 0.25;
    const cv::Vec4d cm = c.to_marker * cv::Vec4d(centre[0], centre[1], centre[2], 1);
    const cv::Vec4d nm = c.to_marker * cv::Vec4d(faces[size_t(f)].normal[0], faces[size_t(f)].normal[1],
                                                 faces[size_t(f)].normal[2], 0);
    const cv::Vec3d cam_centre = R * cv::Vec3d(cm[0], cm[1], cm[2]) + c.tvec;
    const cv::Vec3d cam_normal = R * cv::Vec3d(nm[0], nm[1], nm[2]);
    if (cam_normal.dot(-cam_centre) > 0 && visible.size() < 3) {
      look.colour[size_t(f)] = pure[visible.size()];
      visible.push_back(f);
    } else {
      look.colour[size_t(f)] = mixed[hidden++ % 3];
    }
  }
  ASSERT_EQ(visible.size(), 3u) << "the pose must show three faces";
  Overlay o;
  o.marker_id = 1;
  o.media.kind = MediaKind::cube;
  o.quad.opacity = 1;
  SolidDraw d;
  d.mesh = make_cube(look);
  d.mesh_to_marker = c.to_marker;
  d.rvec = c.rvec;
  d.tvec = c.tvec;
  d.camera_matrix = kK;
  d.distortion = c.dist;
  o.solid = d;
  render::Compositor comp;
  ASSERT_TRUE(comp.draw(cv::Mat(kFrame, CV_8UC3, cv::Scalar(0, 0, 0)), 1, {o})) << comp.error();
  const cv::Mat out = comp.read();
  for (size_t k = 0; k < visible.size(); ++k) {
    const Face& f = faces[size_t(visible[k])];
    const auto outline =
        projected_outline({f.corners.begin(), f.corners.end()}, c.to_marker, c.rvec, c.tvec, c.dist);
    const Agreement a = compare(hue_mask(out, 2 - int(k)), outline);
    SCOPED_TRACE(cube_face_name(static_cast<CubeFace>(visible[k])));
    std::printf("%s face: %d px drawn, farthest %.2f px outside the projected outline, %d px missing inside\n",
                cube_face_name(static_cast<CubeFace>(visible[k])), a.drawn, a.worst_outside, a.missing_inside);
    EXPECT_EQ(hidden_hue_pixels(out, outline), 0) << "a hidden face shows through: no depth test";
    EXPECT_GT(a.drawn, 500);
    EXPECT_LE(a.worst_outside, 1.0);
    EXPECT_EQ(a.missing_inside, 0);
  }
}

TEST(MeshRender, CubeLandsWhereProjectPointsPutsItsCorners) {
  // A marker 8 sides away, turned so that the top, the front and a side face the camera.
  check_cube({facing({0.7, 0.45, 0.2}), {0.4, 0.3, 8}, {}, cv::Matx44d::eye()});
}

TEST(MeshRender, CubeFollowsTheLensWhereTheImageIsDistorted) {
  // Barrel distortion and a cube near the image's corner, where the lens bends straight edges most.
  check_cube({facing({0.6, -0.5, 0.3}), {-2.2, -1.4, 7}, {-0.28, 0.09, 0.001, -0.0015, 0}, cv::Matx44d::eye()});
}

TEST(MeshRender, CubePlacedWithOffsetRotationAndScale) {
  const cv::Matx44d m = place_in_marker(cv::Matx44d::eye(), {0.7, -0.2, 0.1}, {0, 0, 30}, 0.6);
  check_cube({facing({-0.6, 0.5, -0.2}), {0.2, 0.1, 6}, {-0.1, 0.02, 0, 0, 0}, m});
}

TEST(MeshRender, FlatMediaThroughTheLensFollowsTheDistortedMarker) {
  render::OffscreenContext context;
  ASSERT_TRUE(context.ok()) << context.error();
  const std::vector<double> dist{-0.35, 0.1, 0, 0, 0};
  const cv::Vec3d rvec(0.5, -0.3, 0.1), tvec(-1.0, 0.7, 2.4);
  Overlay o;
  o.marker_id = 1;
  o.media.kind = MediaKind::text;
  o.quad.opacity = 1;
  o.content = std::make_shared<StillMedia>(cv::Mat(64, 64, CV_8UC3, cv::Scalar(0, 0, 255)));
  SolidDraw d;
  d.mesh = flat_media_mesh();
  // The grid's [0,1]^2 onto the marker: x right, y down from corner 0 at (-0.5, 0.5).
  d.mesh_to_marker = cv::Matx44d(1, 0, 0, -0.5, 0, -1, 0, 0.5, 0, 0, 1, 0, 0, 0, 0, 1);
  d.rvec = rvec;
  d.tvec = tvec;
  d.camera_matrix = kK;
  d.distortion = dist;
  o.solid = d;
  render::Compositor comp;
  ASSERT_TRUE(comp.draw(cv::Mat(kFrame, CV_8UC3, cv::Scalar(0, 0, 0)), 1, {o})) << comp.error();
  const cv::Mat out = comp.read();
  const auto outline = projected_outline({{-0.5, 0.5, 0}, {0.5, 0.5, 0}, {0.5, -0.5, 0}, {-0.5, -0.5, 0}},
                                         cv::Matx44d::eye(), rvec, tvec, dist);
  const Agreement a = compare(hue_mask(out, 2), outline);
  std::printf("flat media: %d px drawn, farthest %.2f px outside the projected outline, %d px missing inside\n",
              a.drawn, a.worst_outside, a.missing_inside);
  EXPECT_GT(a.drawn, 1000);
  EXPECT_LE(a.worst_outside, 1.0);
  EXPECT_EQ(a.missing_inside, 0);
  // The straight quad through the four projected corners misses the bent edges by more than a pixel here:
  // without the lens model the media would not follow the marker.
  std::vector<cv::Point2d> corners;
  for (size_t i = 0; i < outline.size(); i += 200) corners.push_back(outline[i]);
  double bend = 0;
  std::vector<cv::Point2f> quad(corners.begin(), corners.end());
  for (const cv::Point2d& p : outline)
    bend = std::max(bend, std::abs(cv::pointPolygonTest(quad, cv::Point2f(p), true)));
  EXPECT_GT(bend, 2.0);
}

TEST(MeshRender, DistortionLimitStopsWhereTheLensModelTurnsBack) {
  // k1 = -0.5 alone: r (1 - 0.5 r^2) grows until r^2 = 2/3.
  const double r2 = render::distortion_r2_limit(kK, {-0.5, 0, 0, 0, 0}, {4000, 3000});
  EXPECT_NEAR(r2, 2.0 / 3.0, 0.01);
  // No distortion: twice the farthest corner, (2 * hypot(320, 240) / 600)^2.
  EXPECT_NEAR(render::distortion_r2_limit(kK, {}, kFrame), std::pow(2 * 400.0 / 600, 2), 0.01);
}

}  // namespace
}  // namespace arwb
