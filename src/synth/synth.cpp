#include "synth/synth.hpp"

#include "detect/quad.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace arwb {

// [SECTION] rendering

void draw_marker(cv::Mat& canvas, const Dictionary& dict, int id, const Quad& corners, double quiet_cells,
                 int supersample, int black, int white) {
  const int cells = dict.marker_size() + 2;
  const int cell_px = 16;
  const int quiet_px = static_cast<int>(std::lround(quiet_cells * cell_px));
  // The marker with its quiet zone, drawn large; values are scaled to black..white later.
  cv::Mat art(cells * cell_px + 2 * quiet_px, cells * cell_px + 2 * quiet_px, CV_8UC1, cv::Scalar(255));
  dict.render(id, cell_px).copyTo(art(cv::Rect(quiet_px, quiet_px, cells * cell_px, cells * cell_px)));

  // Where the quiet zone's corners land: extend the marker's homography by quiet_cells on each side.
  const float m0 = static_cast<float>(quiet_px), m1 = static_cast<float>(quiet_px + cells * cell_px);
  const cv::Point2f art_marker[4] = {{m0, m0}, {m1, m0}, {m1, m1}, {m0, m1}};
  cv::Point2f img_marker[4];
  for (int i = 0; i < 4; ++i) img_marker[i] = corners[size_t(i)] + cv::Point2f(0.5f, 0.5f);  // continuous coords
  const cv::Matx33d H = cv::getPerspectiveTransform(art_marker, img_marker);  // art continuous -> image continuous
  const float a1 = static_cast<float>(art.cols);
  const cv::Point2f art_quiet[4] = {{0, 0}, {a1, 0}, {a1, a1}, {0, a1}};
  std::vector<cv::Point2f> img_quiet(4);
  cv::perspectiveTransform(std::vector<cv::Point2f>(art_quiet, art_quiet + 4), img_quiet, cv::Mat(H));

  cv::Rect box = cv::boundingRect(img_quiet);
  box.x -= 2; box.y -= 2; box.width += 4; box.height += 4;
  box &= cv::Rect(0, 0, canvas.cols, canvas.rows);
  if (box.empty()) return;

  // Into the supersampled patch: continuous X_hi = s (X - box.x); warpPerspective works on pixel centres,
  // so shift by half a pixel on both sides.
  const double s = supersample;
  const cv::Matx33d to_hi(s, 0, -s * box.x, 0, s, -s * box.y, 0, 0, 1);
  const cv::Matx33d half_in(1, 0, 0.5, 0, 1, 0.5, 0, 0, 1), half_out(1, 0, -0.5, 0, 1, -0.5, 0, 0, 1);
  const cv::Matx33d Hpix = half_out * to_hi * H * half_in;
  const cv::Size hi(box.width * supersample, box.height * supersample);
  cv::Mat patch, mask;
  cv::warpPerspective(art, patch, Hpix, hi, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(255));
  cv::warpPerspective(cv::Mat(art.size(), CV_8UC1, cv::Scalar(255)), mask, Hpix, hi, cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::Mat small, small_mask;
  cv::resize(patch, small, box.size(), 0, 0, cv::INTER_AREA);
  cv::resize(mask, small_mask, box.size(), 0, 0, cv::INTER_AREA);

  cv::Mat roi = canvas(box);
  const double range = (white - black) / 255.0;
  for (int y = 0; y < box.height; ++y)
    for (int x = 0; x < box.width; ++x) {
      const double a = small_mask.at<uint8_t>(y, x) / 255.0;
      if (a <= 0) continue;
      const double v = black + small.at<uint8_t>(y, x) * range;
      if (roi.channels() == 1) {
        auto& px = roi.at<uint8_t>(y, x);
        px = cv::saturate_cast<uint8_t>(px * (1 - a) + v * a);
      } else {
        auto& px = roi.at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c) px[c] = cv::saturate_cast<uint8_t>(px[c] * (1 - a) + v * a);
      }
    }
}

Quad project_square(cv::Point2d centre, double side_px, double roll_deg, double tilt_x_deg, double tilt_y_deg,
                    double focal_px) {
  const double d2r = std::numbers::pi / 180.0;
  const cv::Matx33d Rz(std::cos(roll_deg * d2r), -std::sin(roll_deg * d2r), 0, std::sin(roll_deg * d2r),
                       std::cos(roll_deg * d2r), 0, 0, 0, 1);
  const double ax = tilt_x_deg * d2r, ay = tilt_y_deg * d2r;
  const cv::Matx33d Rx(1, 0, 0, 0, std::cos(ax), -std::sin(ax), 0, std::sin(ax), std::cos(ax));
  const cv::Matx33d Ry(std::cos(ay), 0, std::sin(ay), 0, 1, 0, -std::sin(ay), 0, std::cos(ay));
  const cv::Matx33d R = Rx * Ry * Rz;
  const double h = side_px / 2;
  const cv::Vec3d local[4] = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
  Quad q;
  for (int i = 0; i < 4; ++i) {
    const cv::Vec3d p = R * local[i] + cv::Vec3d(0, 0, focal_px);
    q[size_t(i)] = cv::Point2f(float(centre.x + focal_px * p[0] / p[2]), float(centre.y + focal_px * p[1] / p[2]));
  }
  return q;
}

// [SECTION] photographs

// Some dictionaries hold markers that equal themselves or another marker when turned (ARUCO_ORIGINAL's id 1023
// reads the same upside down): no detector can tell their orientation, so the truth would be a coin toss.
bool unambiguous(const Dictionary& d, int id) {
  const uint64_t code = d.code(id);
  for (int k = 1; k < 4; ++k)
    if (d.code(id, k) == code) return false;
  for (int other = 0; other < d.size(); ++other)
    for (int k = 0; k < 4; ++k)
      if (other != id && d.code(other, k) == code) return false;
  return true;
}

namespace {

// A code that no dictionary in use would accept, even with a few bits wrong.
uint64_t decoy_code(cv::RNG& rng, const std::vector<Dictionary>& dicts, int n) {
  for (;;) {
    const uint64_t high = rng.next(), low = rng.next();
    const uint64_t code = (high << 32 | low) & ((n * n == 64) ? ~0ull : ((1ull << (n * n)) - 1));
    bool close = false;
    for (const auto& d : dicts)
      if (d.marker_size() == n && d.nearest(code).hamming <= d.max_correction_bits() + 3) close = true;
    if (!close) return code;
  }
}

// Every random draw is its own statement: the order in which a call's arguments are evaluated is up to the
// compiler (GCC goes right to left, clang left to right), and the same seed must give the same set with either.
// Where one call used to take several draws, they are taken in the order GCC took them, so that sets made before
// stay the same.
void draw_clutter(cv::Mat& img, cv::RNG& rng, const std::vector<Dictionary>& dicts, double focal) {
  const int count = rng.uniform(3, 14);
  for (int i = 0; i < count; ++i) {
    const int cy = rng.uniform(0, img.rows), cx = rng.uniform(0, img.cols);
    const cv::Point c(cx, cy);
    const int grey = rng.uniform(0, 256);
    const int red = rng.uniform(0, 256), green = rng.uniform(0, 256);
    const cv::Scalar colour(grey, green, red);
    switch (rng.uniform(0, 6)) {
      case 0: {  // filled or outlined rectangles: quads that are no markers
        const int h = rng.uniform(8, img.rows / 4), w = rng.uniform(8, img.cols / 4);
        const cv::Size s(w, h);
        cv::rectangle(img, cv::Rect(c, s), colour, rng.uniform(0, 2) ? -1 : rng.uniform(1, 6));
        break;
      }
      case 1: {
        const int thickness = rng.uniform(1, 5);
        const int ey = rng.uniform(0, img.rows), ex = rng.uniform(0, img.cols);
        cv::line(img, c, cv::Point(ex, ey), colour, thickness);
        break;
      }
      case 2: {
        const int thickness = rng.uniform(1, 4);
        const double scale = rng.uniform(0.4, 2.0);
        cv::putText(img, "ArUco 42 lab", c, cv::FONT_HERSHEY_SIMPLEX, scale, colour, thickness);
        break;
      }
      case 3: {  // a checkerboard patch
        const int cell = rng.uniform(4, 20), nx = rng.uniform(3, 8), ny = rng.uniform(3, 8);
        for (int y = 0; y < ny; ++y)
          for (int x = 0; x < nx; ++x)
            if ((x + y) % 2)
              cv::rectangle(img, cv::Rect(c.x + x * cell, c.y + y * cell, cell, cell), cv::Scalar::all(20), -1);
        break;
      }
      case 4: {  // a decoy: black border and random inner bits that decode to nothing
        const Dictionary& d = dicts[size_t(rng.uniform(0, int(dicts.size())))];
        const uint64_t code = decoy_code(rng, dicts, d.marker_size());
        const Dictionary fake("decoy", d.marker_size(), {code}, 0);
        const double side = rng.uniform(24.0, std::min(img.cols, img.rows) * 0.3);
        const double tilt_y = rng.uniform(-40.0, 40.0), tilt_x = rng.uniform(-40.0, 40.0);
        const double roll = rng.uniform(0.0, 360.0);
        draw_marker(img, fake, 0, project_square(c, side, roll, tilt_x, tilt_y, focal));
        break;
      }
      default: {
        const int thickness = rng.uniform(0, 2) ? -1 : 3;
        cv::circle(img, c, rng.uniform(4, 60), colour, thickness);
      }
    }
  }
}

cv::Mat background(cv::Size size, cv::RNG& rng) {
  // A smooth random field: low-resolution noise scaled up, with a colour cast.
  const int cols = rng.uniform(2, 8), rows = rng.uniform(2, 8);  // in this order: see draw_clutter
  cv::Mat low(rows, cols, CV_8UC3);
  rng.fill(low, cv::RNG::UNIFORM, cv::Scalar::all(60), cv::Scalar::all(230));
  cv::Mat bg;
  cv::resize(low, bg, size, 0, 0, cv::INTER_CUBIC);
  return bg;
}

}  // namespace

std::string_view hardship_name(Hardship h) {
  switch (h) {
    case Hardship::low_contrast: return "low_contrast";
    case Hardship::tiny: return "tiny";
    case Hardship::low_light: return "low_light";
    case Hardship::crossed: return "crossed";
    case Hardship::none: break;
  }
  return "none";
}

namespace {

// Where a photograph's markers go: how many, their sides and tilts, by the set's hardship.
struct MarkerRange {
  int max_markers = 0;
  double min_side = 0, max_side = 0, tilt = 0, min_px_per_cell = 2.0;
};

MarkerRange marker_range(const SynthOptions& opt, Hardship hard, double short_side) {
  MarkerRange r;
  r.max_markers = opt.max_markers;
  r.min_side = opt.min_side_px;
  r.max_side = std::max(opt.min_side_px * 1.5, opt.max_side_rate * short_side);
  r.tilt = opt.max_tilt_deg;
  if (hard == Hardship::low_contrast) {
    r.max_markers = std::min(r.max_markers, 3);
    r.max_side = opt.max_side_rate * short_side;
    r.min_side = std::min(std::max(100.0, 0.2 * short_side), 0.8 * r.max_side);
  } else if (hard == Hardship::tiny) {
    r.max_markers = 8;
    r.min_side = 10;
    r.max_side = 24;
    r.tilt = std::min(r.tilt, 35.0);
    r.min_px_per_cell = 1.25;
  } else if (hard == Hardship::crossed) {
    r.max_markers = 3;
  }
  return r;
}

// A crossed image's marker k: the sides it is drawn between (the held-out set's misses: large markers, and markers
// of 37 and 55 px).
std::pair<double, double> crossed_side(size_t k) {
  constexpr double kSides[3][2] = {{190, 265}, {34, 40}, {50, 60}};
  return {kSides[k % 3][0], kSides[k % 3][1]};
}

// The markers drawn into out.image, each in perspective, its quiet zone inside the frame and clear of the others.
void place_markers(const SynthOptions& opt, Hardship hard, const MarkerRange& range, int index, double focal,
                   cv::RNG& rng, SynthImage& out) {
  const cv::Size size = opt.size;
  const bool empty = rng.uniform(0.0, 1.0) < opt.empty_fraction;
  int want = empty ? 0 : rng.uniform(1, range.max_markers + 1);
  if (hard == Hardship::crossed && !empty) want = 3;
  std::vector<cv::Rect> taken;
  for (int attempt = 0; int(out.markers.size()) < want && attempt < 200; ++attempt) {
    const Dictionary& d = opt.dictionaries[size_t(int(out.markers.size() + size_t(index)) % int(opt.dictionaries.size()))];
    auto [lo, hi] = hard == Hardship::crossed ? crossed_side(out.markers.size())
                                              : std::pair<double, double>(range.min_side, range.max_side);
    const double side = std::exp(rng.uniform(std::log(lo), std::log(hi)));
    // One draw a statement, in the order GCC took them (see draw_clutter).
    const double cy = rng.uniform(side, size.height - side), cx = rng.uniform(side, size.width - side);
    const cv::Point2d centre(cx, cy);
    if (centre.x <= 0 || centre.y <= 0) continue;
    const double tilt_y = rng.uniform(-range.tilt, range.tilt), tilt_x = rng.uniform(-range.tilt, range.tilt),
                 roll = rng.uniform(0.0, 360.0);
    const Quad q = project_square(centre, side, roll, tilt_x, tilt_y, focal);
    // Keep the quiet zone inside the frame and away from other markers.
    const double cell = side / (d.marker_size() + 2);
    cv::Rect box = cv::boundingRect(std::vector<cv::Point2f>(q.begin(), q.end()));
    const int pad = static_cast<int>(std::ceil(cell * 1.5)) + 4;
    box = cv::Rect(box.x - pad, box.y - pad, box.width + 2 * pad, box.height + 2 * pad);
    if ((box & cv::Rect(0, 0, size.width, size.height)) != box) continue;
    if (std::any_of(taken.begin(), taken.end(), [&](const cv::Rect& r) { return (r & box).area() > 0; })) continue;
    // Foreshortened too far to be readable: every side must keep 2 px a cell.
    double min_edge = 1e9;
    for (int i = 0; i < 4; ++i) min_edge = std::min(min_edge, double(cv::norm(q[size_t(i)] - q[size_t((i + 1) % 4)])));
    if (min_edge < range.min_px_per_cell * (d.marker_size() + 2)) continue;
    taken.push_back(box);
    int id = rng.uniform(0, d.size());
    while (!unambiguous(d, id)) id = (id + 1) % d.size();
    int black = 0, white = 255;
    if (hard == Hardship::low_contrast) {
      black = rng.uniform(60, 120);
      white = black + rng.uniform(35, 70);  // grey on grey
    } else if (opt.effects) {
      black = rng.uniform(0, 60);
      white = rng.uniform(170, 256);
    }
    draw_marker(out.image, d, id, q, 1.0, 4, black, white);
    out.markers.push_back({id, d.name(), q});
  }
}

// A crossed image's lines, dark and thin (1 to 2.5 px at 720 rows, thicker in larger frames): through the large
// marker's border into it, and across each other marker's quiet zone, ending on its border, where a detector sees
// one shape of the marker and the line.
void draw_crossing_lines(cv::Mat& image, const std::vector<TruthMarker>& markers, double short_side, cv::RNG& rng) {
  for (size_t k = 0; k < markers.size(); ++k) {
    const Quad& q = markers[k].corners;
    const int s = rng.uniform(0, 4);
    const double t = rng.uniform(0.2, 0.8);
    const cv::Point2d a = q[size_t(s)], b = q[size_t((s + 1) % 4)];
    const cv::Point2d on = a + t * (b - a), along = (b - a) / cv::norm(b - a), out(along.y, -along.x);
    // Out of the marker (its corners run clockwise on screen: the left of a side is outside), at 30 to 150 degrees
    // to the side.
    const double angle = rng.uniform(30.0, 150.0) * CV_PI / 180.0;
    const cv::Point2d dir = std::cos(angle) * along + std::sin(angle) * out;
    const double side = quad_perimeter(q) / 4;
    const double outside = rng.uniform(1.0, 3.0) * side, inside = k == 0 ? rng.uniform(0.3, 0.9) * side : 0.0;
    const int thickness = std::max(1, int(std::lround(rng.uniform(1.0, 2.5) * short_side / 720.0)));
    const int grey = rng.uniform(15, 70);
    cv::line(image, on - inside * dir, on + outside * dir, cv::Scalar::all(grey), thickness, cv::LINE_AA);
  }
}

// Light: a gradient across the frame, and sometimes a soft shadow; what was added is appended to *notes.
cv::Mat light_of(cv::Size size, Hardship hard, const std::vector<TruthMarker>& markers, double short_side,
                 cv::RNG& rng, std::string* notes) {
  cv::Mat light(size, CV_32FC1);
  double gx = rng.uniform(-0.5, 0.5), gy = rng.uniform(-0.5, 0.5), base = rng.uniform(0.75, 1.1);
  if (hard == Hardship::low_contrast) {
    gx *= 1.8, gy *= 1.8;  // steep: one side of a large marker in half the light of the other
  } else if (hard == Hardship::low_light) {
    base *= 0.25, gx *= 0.2, gy *= 0.2;  // dim and even
  }
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      light.at<float>(y, x) =
          float(std::max(0.05, base + gx * (x / double(size.width) - 0.5) + gy * (y / double(size.height) - 0.5)));
  if ((hard == Hardship::low_contrast || hard == Hardship::crossed) && !markers.empty()) {
    // A shadow whose soft edge crosses the first marker: a straight edge at a random angle through a point near
    // its centre, everything on one side darkened; in a crossed image, a band from that edge about a side wide.
    const Quad& q = markers[0].corners;
    const cv::Point2f c = quad_centre(q);
    const double reach = 0.075 * quad_perimeter(q);  // 0.3 of a side
    const double ox = rng.uniform(-reach, reach), oy = rng.uniform(-reach, reach);
    const double angle = rng.uniform(0.0, 2 * CV_PI);
    const double depth = rng.uniform(0.45, 0.7);
    const double softness = rng.uniform(1.0, 6.0) * std::max(1.0, short_side / 720.0);
    const cv::Point2d p(c.x + ox, c.y + oy), along(std::cos(angle), std::sin(angle)), across(-along.y, along.x);
    const double far = 4.0 * (size.width + size.height);
    const double width = hard == Hardship::crossed ? rng.uniform(0.7, 1.3) * quad_perimeter(q) / 4 : far;
    const std::vector<cv::Point> half = {p + far * along, p + far * along + width * across,
                                         p - far * along + width * across, p - far * along};
    cv::Mat shadow(size, CV_32FC1, cv::Scalar(1));
    cv::fillConvexPoly(shadow, half, cv::Scalar(depth), cv::LINE_AA);
    cv::GaussianBlur(shadow, shadow, cv::Size(0, 0), softness);
    light = light.mul(shadow);
    *notes += hard == Hardship::crossed ? "shadow_band " : "shadow_edge ";
  } else if (rng.uniform(0, 3) == 0) {
    cv::Mat shadow(size, CV_32FC1, cv::Scalar(1));
    std::vector<cv::Point> poly;
    for (int i = 0; i < 4; ++i) {
      const int y = rng.uniform(-size.height / 2, size.height * 3 / 2);
      const int x = rng.uniform(-size.width / 2, size.width * 3 / 2);
      poly.emplace_back(x, y);
    }
    cv::fillConvexPoly(shadow, poly, cv::Scalar(rng.uniform(0.55, 0.85)));
    cv::GaussianBlur(shadow, shadow, cv::Size(0, 0), rng.uniform(2.0, 15.0));
    light = light.mul(shadow);
    *notes += "shadow ";
  }
  return light;
}

// The camera's part: blur, sensor noise, and sometimes JPEG compression; what was done is appended to *notes.
void camera_effects(Hardship hard, cv::RNG& rng, cv::Mat& image, std::string* notes) {
  double blur = rng.uniform(0.0, 1.2);
  if (hard == Hardship::tiny) blur *= 0.6;
  if (hard == Hardship::low_light) blur += 0.6;  // a long exposure
  if (blur > 0.3) {
    cv::GaussianBlur(image, image, cv::Size(0, 0), blur);
    *notes += "blur ";
  }
  double noise = rng.uniform(0.0, 8.0);
  if (hard == Hardship::tiny) noise *= 0.6;
  if (hard == Hardship::low_light) noise += 6;  // sensor noise, amplified by the gain of a dim scene
  cv::Mat n(image.size(), CV_16SC3);
  rng.fill(n, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(noise));
  cv::Mat img16;
  image.convertTo(img16, CV_16SC3);
  img16 += n;
  img16.convertTo(image, CV_8UC3);
  if (rng.uniform(0, 2) == 0) {
    std::vector<uint8_t> buf;
    const int quality = rng.uniform(40, 95);
    cv::imencode(".jpg", image, buf, {cv::IMWRITE_JPEG_QUALITY, quality});
    image = cv::imdecode(buf, cv::IMREAD_COLOR);
    *notes += "jpeg" + std::to_string(quality) + " ";
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "blur%.1f noise%.1f", blur, noise);
  *notes += buf;
}

}  // namespace

SynthImage synth_photo(const SynthOptions& opt, uint64_t seed, int index) {
  cv::RNG rng(seed * 0x9E3779B97F4A7C15ull + uint64_t(index) * 0xBF58476D1CE4E5B9ull + 1);
  SynthImage out;
  const cv::Size size = opt.size;
  out.image = opt.effects ? background(size, rng) : cv::Mat(size, CV_8UC3, cv::Scalar::all(128));
  const double focal = size.width * 1.1;
  if (opt.effects) draw_clutter(out.image, rng, opt.dictionaries, focal);

  // A hard set's condition changes the draws below only for its own images: the photographs of Hardship::none
  // take exactly the draws they always took, so sets made before stay the same. Each step draws from `rng` in
  // turn, so their order is part of the set.
  const Hardship hard = opt.effects ? opt.hardship : Hardship::none;
  const double short_side = std::min(size.width, size.height);
  place_markers(opt, hard, marker_range(opt, hard, short_side), index, focal, rng, out);
  if (!opt.effects) return out;
  if (hard == Hardship::crossed) draw_crossing_lines(out.image, out.markers, short_side, rng);

  std::string notes;
  if (hard != Hardship::none) notes = std::string(hardship_name(hard)) + " ";
  const cv::Mat light = light_of(size, hard, out.markers, short_side, rng, &notes);
  cv::Mat f;
  out.image.convertTo(f, CV_32FC3);
  std::vector<cv::Mat> ch;
  cv::split(f, ch);
  for (auto& c : ch) c = c.mul(light);
  cv::merge(ch, f);
  f.convertTo(out.image, CV_8UC3);
  camera_effects(hard, rng, out.image, &notes);
  out.notes = notes;
  return out;
}

}  // namespace arwb
