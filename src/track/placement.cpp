#include "track/placement.hpp"

#include "base/decimals.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace arwb {
namespace {

template <typename E, size_t N>
bool parse_name(std::string_view s, const std::array<E, N>& all, std::string_view (*name)(E), E* out) {
  for (E e : all)
    if (name(e) == s) {
      *out = e;
      return true;
    }
  return false;
}

// Maps a point through a homography; w is the homogeneous coordinate before division.
cv::Point2d apply(const cv::Matx33d& H, cv::Point2d p, double* w = nullptr) {
  const cv::Vec3d r = H * cv::Vec3d(p.x, p.y, 1.0);
  if (w) *w = r[2];
  return {r[0] / r[2], r[1] / r[2]};
}

// The affine map taking texture coordinates of the whole media to a rectangle of the plane: the drawn part
// [uv_min, uv_max] lands on the rectangle at (x0, y0) of size w x h, then the rectangle turns by `deg` about
// (cx, cy).
cv::Matx33d uv_to_plane(cv::Point2d uv_min, cv::Point2d uv_max, double x0, double y0, double w, double h,
                        double deg, cv::Point2d c) {
  const double sx = w / (uv_max.x - uv_min.x), sy = h / (uv_max.y - uv_min.y);
  const cv::Matx33d lin(sx, 0, x0 - uv_min.x * sx, 0, sy, y0 - uv_min.y * sy, 0, 0, 1);
  const double r = deg * CV_PI / 180.0, cs = std::cos(r), sn = std::sin(r);
  // Clockwise on screen, since y points down.
  const cv::Matx33d rot(cs, -sn, c.x - cs * c.x + sn * c.y, sn, cs, c.y - sn * c.x - cs * c.y, 0, 0, 1);
  return rot * lin;
}

}  // namespace

std::string_view place_kind_name(PlaceKind k) {
  switch (k) {
    case PlaceKind::on_marker: return "on_marker";
    case PlaceKind::beside: return "beside";
    case PlaceKind::billboard: return "billboard";
    case PlaceKind::screen: return "screen";
  }
  return "on_marker";
}
std::string_view fit_name(Fit f) {
  switch (f) {
    case Fit::fit: return "fit";
    case Fit::fill: return "fill";
    case Fit::stretch: return "stretch";
  }
  return "fit";
}
std::string_view side_name(Side s) {
  switch (s) {
    case Side::right: return "right";
    case Side::left: return "left";
    case Side::top: return "top";
    case Side::bottom: return "bottom";
  }
  return "right";
}
std::string_view screen_corner_name(ScreenCorner c) {
  switch (c) {
    case ScreenCorner::top_left: return "top_left";
    case ScreenCorner::top_right: return "top_right";
    case ScreenCorner::bottom_left: return "bottom_left";
    case ScreenCorner::bottom_right: return "bottom_right";
  }
  return "top_right";
}
bool parse_fit(std::string_view s, Fit* out) {
  return parse_name(s, std::array{Fit::fit, Fit::fill, Fit::stretch}, fit_name, out);
}
bool parse_side(std::string_view s, Side* out) {
  return parse_name(s, std::array{Side::right, Side::left, Side::top, Side::bottom}, side_name, out);
}
bool parse_screen_corner(std::string_view s, ScreenCorner* out) {
  return parse_name(s,
                    std::array{ScreenCorner::top_left, ScreenCorner::top_right, ScreenCorner::bottom_left,
                               ScreenCorner::bottom_right},
                    screen_corner_name, out);
}

PlaceSpec PlaceSpec::defaults(PlaceKind k) {
  PlaceSpec s;
  s.kind = k;
  if (k == PlaceKind::billboard) {
    s.side = Side::top;
    s.size = 0.6;
  }
  if (k == PlaceKind::screen) s.size = 0.25;
  return s;
}

std::string PlaceSpec::describe() const {
  // Appended piece by piece: g++ 12 reports a false -Wrestrict on `" " + std::string(...)` chains.
  std::string d(place_kind_name(kind));
  auto add = [&d](std::string_view word, const std::string& value = {}) {
    d.append(" ").append(word);
    if (!value.empty()) d.append(" ").append(value);
  };
  switch (kind) {
    case PlaceKind::on_marker:
      add(fit_name(fit));
      if (scale != 1.0) add("scale", general_text(scale));
      if (rotate_deg != 0.0) add("rotate", general_text(rotate_deg));
      break;
    case PlaceKind::beside:
      add(side_name(side));
      add("gap", general_text(gap));
      add("size", general_text(size));
      if (overlap) add("overlap");
      break;
    case PlaceKind::billboard:
      add(side_name(side));
      add("size", general_text(size));
      if (overlap) add("overlap");
      break;
    case PlaceKind::screen:
      add(screen_corner_name(corner));
      add("size", general_text(size));
      break;
  }
  if (opacity != 1.0) add("opacity", general_text(opacity));
  return d;
}

std::string PlaceSpec::validate() const {
  auto bad = [](const char* what, const char* rule, double v) {
    return std::string(what) + " must be " + rule + " (got " + general_text(v) + ")";
  };
  if (!std::isfinite(opacity) || opacity < 0 || opacity > 1) return bad("opacity", "a number from 0 to 1", opacity);
  if (!std::isfinite(scale) || scale <= 0 || scale > 100) return bad("scale", "a finite number in (0, 100]", scale);
  if (!std::isfinite(rotate_deg)) return bad("rotate", "a finite number of degrees", rotate_deg);
  if (!std::isfinite(gap) || gap < 0 || gap > 100) return bad("gap", "a finite number in [0, 100]", gap);
  if (!std::isfinite(size) || size <= 0 || size > 100) return bad("size", "a finite number > 0", size);
  if (kind == PlaceKind::screen && size > 1) return bad("size", "a fraction of the frame's width in (0, 1]", size);
  if (!std::isfinite(margin_px) || margin_px < 0 || margin_px > 10000)
    return bad("margin", "a finite number of pixels >= 0", margin_px);
  return {};
}

bool MediaQuad::contains(cv::Point2d p) const {
  int sign = 0;
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d a = corners[i], b = corners[(i + 1) % 4];
    const double cr = (b - a).cross(p - a);
    const int s = cr > 0 ? 1 : (cr < 0 ? -1 : 0);
    if (s == 0) continue;
    if (sign == 0) sign = s;
    else if (s != sign) return false;
  }
  return true;
}

cv::Matx33d marker_homography(const Quad& c) {
  const cv::Point2f src[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const cv::Point2f dst[4] = {c[0], c[1], c[2], c[3]};
  cv::Mat H = cv::getPerspectiveTransform(src, dst, cv::DECOMP_LU);
  cv::Matx33d out;
  H.convertTo(cv::Mat(3, 3, CV_64F, out.val), CV_64F);
  return out;
}

double marker_side_px(const Quad& c) {
  double s = 0;
  for (int i = 0; i < 4; ++i) s += cv::norm(c[(i + 1) % 4] - c[i]);
  return s / 4;
}

std::optional<MediaQuad> place(const PlaceSpec& spec, const Quad& corners, double media_aspect, cv::Size frame,
                               std::string* why) {
  auto fail = [&](std::string m) -> std::optional<MediaQuad> {
    if (why) *why = std::move(m);
    return std::nullopt;
  };
  if (std::string v = spec.validate(); !v.empty()) return fail(v);
  if (!std::isfinite(media_aspect) || media_aspect <= 0) return fail("the media has no size yet");
  const double a = media_aspect;
  MediaQuad q;
  q.opacity = spec.opacity;
  cv::Matx33d H_plane = cv::Matx33d::eye();   // plane -> image
  cv::Matx33d uv_map;                         // uv -> plane
  const bool in_marker_plane = spec.kind == PlaceKind::on_marker || spec.kind == PlaceKind::beside;
  const double side = marker_side_px(corners);
  if (spec.kind != PlaceKind::screen) {
    // A marker must span a few pixels and be convex (a twisted quad has no plane).
    double area2 = 0;
    int turn = 0;
    for (int i = 0; i < 4; ++i) {
      const cv::Point2d p = corners[i], n = corners[(i + 1) % 4], nn = corners[(i + 2) % 4];
      area2 += p.x * n.y - n.x * p.y;
      const double cr = (n - p).cross(nn - n);
      const int t = cr > 0 ? 1 : -1;
      if (turn != 0 && t != turn) return fail("the marker's corners do not form a convex quadrilateral");
      turn = t;
    }
    if (std::abs(area2) < 8.0 || !(side > 2.0)) return fail("the marker is too small to place media on");
  }
  switch (spec.kind) {
    case PlaceKind::on_marker: {
      double w = 1, h = 1;
      if (spec.fit == Fit::fit) {
        if (a >= 1) h = 1 / a;
        else w = a;
      } else if (spec.fit == Fit::fill) {
        // The marker is covered; the media's overflow is cropped, centred.
        if (a >= 1) {
          q.uv_min.x = 0.5 - 0.5 / a;
          q.uv_max.x = 0.5 + 0.5 / a;
        } else {
          q.uv_min.y = 0.5 - 0.5 * a;
          q.uv_max.y = 0.5 + 0.5 * a;
        }
      }
      w *= spec.scale;
      h *= spec.scale;
      uv_map = uv_to_plane(q.uv_min, q.uv_max, 0.5 - w / 2, 0.5 - h / 2, w, h, spec.rotate_deg, {0.5, 0.5});
      H_plane = marker_homography(corners);
      break;
    }
    case PlaceKind::beside: {
      const double g = spec.gap, s = spec.size;
      double x0 = 0, y0 = 0, w = 0, h = 0;
      switch (spec.side) {
        case Side::right: w = s; h = s / a; x0 = 1 + g; y0 = 0.5 - h / 2; break;
        case Side::left: w = s; h = s / a; x0 = -g - s; y0 = 0.5 - h / 2; break;
        case Side::top: h = s; w = s * a; x0 = 0.5 - w / 2; y0 = -g - s; break;
        case Side::bottom: h = s; w = s * a; x0 = 0.5 - w / 2; y0 = 1 + g; break;
      }
      uv_map = uv_to_plane(q.uv_min, q.uv_max, x0, y0, w, h, 0, {0, 0});
      H_plane = marker_homography(corners);
      break;
    }
    case PlaceKind::billboard: {
      // Upright on screen: an axis-aligned rectangle beside the marker's bounding box, sized by its side.
      double l = corners[0].x, r = l, t = corners[0].y, b = t;
      for (const auto& p : corners) {
        l = std::min(l, double(p.x));
        r = std::max(r, double(p.x));
        t = std::min(t, double(p.y));
        b = std::max(b, double(p.y));
      }
      const cv::Point2d c = (cv::Point2d(corners[0]) + cv::Point2d(corners[2])) * 0.5 * 0.5 +
                            (cv::Point2d(corners[1]) + cv::Point2d(corners[3])) * 0.5 * 0.5;
      const double h = spec.size * side, w = h * a, g = spec.gap * side;
      double x0 = 0, y0 = 0;
      switch (spec.side) {
        case Side::top: x0 = c.x - w / 2; y0 = t - g - h; break;
        case Side::bottom: x0 = c.x - w / 2; y0 = b + g; break;
        case Side::right: x0 = r + g; y0 = c.y - h / 2; break;
        case Side::left: x0 = l - g - w; y0 = c.y - h / 2; break;
      }
      uv_map = uv_to_plane(q.uv_min, q.uv_max, x0, y0, w, h, 0, {0, 0});
      break;
    }
    case PlaceKind::screen: {
      if (frame.width <= 0 || frame.height <= 0) return fail("the frame has no size");
      const double w = spec.size * frame.width, h = w / a, m = spec.margin_px;
      const bool left = spec.corner == ScreenCorner::top_left || spec.corner == ScreenCorner::bottom_left;
      const bool top = spec.corner == ScreenCorner::top_left || spec.corner == ScreenCorner::top_right;
      const double x0 = left ? m : frame.width - m - w, y0 = top ? m : frame.height - m - h;
      uv_map = uv_to_plane(q.uv_min, q.uv_max, x0, y0, w, h, 0, {0, 0});
      break;
    }
  }
  q.H = H_plane * uv_map;
  q.uv_to_marker = uv_map;
  q.in_marker_plane = in_marker_plane;
  const cv::Point2d uv[4] = {q.uv_min, {q.uv_max.x, q.uv_min.y}, q.uv_max, {q.uv_min.x, q.uv_max.y}};
  if (in_marker_plane) {
    // The plane's points in front of the camera all have w of the marker centre's sign; a media crossing the
    // horizon line would wrap around through infinity.
    double wc = 0;
    apply(H_plane, {0.5, 0.5}, &wc);
    for (const auto& p : uv) {
      double w = 0;
      apply(q.H, p, &w);
      if (!(w * wc > 0) || std::abs(w) < 1e-6 * std::abs(wc))
        return fail("the media would reach the horizon of the marker's plane (the marker is seen too obliquely)");
    }
  }
  for (int i = 0; i < 4; ++i) {
    q.corners[i] = apply(q.H, uv[i]);
    if (!std::isfinite(q.corners[i].x) || !std::isfinite(q.corners[i].y)) return fail("the placement is degenerate");
  }
  return q;
}

std::optional<MediaQuad> place_apart(const PlaceSpec& spec, const Quad& corners, double media_aspect, cv::Size frame,
                                     std::vector<cv::Rect2d>& taken, std::optional<Side> kept, Side* side,
                                     std::string* why) {
  if (side) *side = spec.side;
  if (spec.overlap || (spec.kind != PlaceKind::beside && spec.kind != PlaceKind::billboard))
    return place(spec, corners, media_aspect, frame, why);
  const auto box = [](const MediaQuad& q) {
    double x0 = q.corners[0].x, y0 = q.corners[0].y, x1 = x0, y1 = y0;
    for (const cv::Point2d& p : q.corners) {
      x0 = std::min(x0, p.x), y0 = std::min(y0, p.y);
      x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
    }
    return cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
  };
  const auto covered = [&](const cv::Rect2d& b) {
    double area = 0;
    for (const cv::Rect2d& t : taken) area += (b & t).area();
    return area;
  };
  std::vector<Side> order;
  for (const Side s : {kept.value_or(spec.side), spec.side, Side::right, Side::left, Side::top, Side::bottom})
    if (std::find(order.begin(), order.end(), s) == order.end()) order.push_back(s);
  std::optional<MediaQuad> best;
  cv::Rect2d best_box;
  double least = 0;
  for (const Side s : order) {
    PlaceSpec tried = spec;
    tried.side = s;
    std::string reason;
    std::optional<MediaQuad> q = place(tried, corners, media_aspect, frame, &reason);
    if (!q) {
      if (!best && s == spec.side && why) *why = reason;   // the side asked for says why, if none can be placed
      continue;
    }
    const cv::Rect2d b = box(*q);
    const double c = covered(b);
    if (!best || c < least) {
      best = std::move(q), best_box = b, least = c;
      if (side) *side = s;
    }
    if (c <= 0) break;
  }
  if (best) taken.push_back(best_box);
  else if (why && why->empty()) *why = "cannot be placed on any side of the marker";
  return best;
}

}  // namespace arwb
