#include "synth/synthetic_world.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>

namespace arwb {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Noise is read from a table of unit-normal samples scaled by this, so that a frame costs an add, not a draw.
constexpr double kNoiseUnit = 64.0;
// Each row starts at a random offset into the table, up to this many samples past its own slice.
constexpr int kNoiseSlack = 4096;
// Grey levels of the printed marker: ink is not perfectly black, paper not perfectly white.
constexpr int kInk = 25, kPaper = 235;
// draw_marker warps an art of 16 px a cell. Supersampling it only matters while a cell is smaller than that in
// the image; a big marker needs none, and its cost then grows with its area alone.
constexpr double kArtCellPx = 16;
int supersample_for(const Quad& q, int cells) {
  double side = 0;
  for (size_t k = 0; k < 4; ++k) side = std::max(side, double(cv::norm(q[k] - q[(k + 1) % 4])));
  return std::clamp(int(std::ceil(kArtCellPx * cells / std::max(side, 1.0))), 1, 4);
}

uint64_t mix(uint64_t x) {  // splitmix64's finaliser: seeds that differ in one bit give unrelated streams
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

uint64_t time_key(uint64_t seed, double t) {
  uint64_t bits = 0;
  std::memcpy(&bits, &t, sizeof bits);
  return mix(seed ^ mix(bits));
}

// One marker's path: a Lissajous figure around its slot, a tilt that sways, a roll that turns.
struct Motion {
  double fx, fy, fz, px, py, pz;    // lateral and depth oscillation (rad/s, rad)
  double fa, fb, pa, pb;            // the two tilt axes
  double roll0, roll_rate;          // deg, deg/s
};

Motion motion_of(uint64_t seed, int i) {
  cv::RNG rng(mix(seed * 31 + uint64_t(i)));
  Motion m{};
  m.fx = rng.uniform(0.25, 0.6);
  m.fy = rng.uniform(0.25, 0.6);
  m.fz = rng.uniform(0.2, 0.5);
  m.px = rng.uniform(0.0, 6.283);
  m.py = rng.uniform(0.0, 6.283);
  m.pz = rng.uniform(0.0, 6.283);
  m.fa = rng.uniform(0.35, 0.9);
  m.fb = rng.uniform(0.35, 0.9);
  m.pa = rng.uniform(0.0, 6.283);
  m.pb = rng.uniform(0.0, 6.283);
  m.roll0 = rng.uniform(0.0, 360.0);
  const double roll_speed = rng.uniform(6.0, 18.0);  // one draw a statement: see desk()
  m.roll_rate = roll_speed * (rng.uniform(0, 2) ? 1 : -1);
  return m;
}

cv::Matx33d rotation(double yaw_deg, double pitch_deg, double roll_deg) {
  const double a = yaw_deg * kDeg, b = pitch_deg * kDeg, c = roll_deg * kDeg;
  const cv::Matx33d Ry(std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a));
  const cv::Matx33d Rx(1, 0, 0, 0, std::cos(b), -std::sin(b), 0, std::sin(b), std::cos(b));
  const cv::Matx33d Rz(std::cos(c), -std::sin(c), 0, std::sin(c), std::cos(c), 0, 0, 0, 1);
  return Ry * Rx * Rz;
}

SyntheticControls clamped(const SyntheticControls& c) {
  SyntheticControls o = c;
  o.time_s = std::isfinite(c.time_s) ? c.time_s : 0.0;
  auto clamp = [](double v, double lo, double hi) { return std::isfinite(v) ? std::clamp(v, lo, hi) : lo; };
  o.speed = clamp(c.speed, 0, 4);
  o.distance_m = clamp(c.distance_m, 0.2, 3);
  o.tilt_deg = clamp(c.tilt_deg, 0, 80);
  o.light = clamp(c.light, 0.2, 1.5);
  o.blur_px = clamp(c.blur_px, 0, 5);
  o.noise = clamp(c.noise, 0, 40);
  o.marker_size_m = clamp(c.marker_size_m, 0.02, 0.3);
  o.markers = std::clamp(c.markers, 1, 8);
  o.first_id = std::max(c.first_id, 0);
  o.ids.clear();
  for (int id : c.ids)
    if (id >= 0 && o.ids.size() < 8 && std::find(o.ids.begin(), o.ids.end(), id) == o.ids.end()) o.ids.push_back(id);
  if (o.board != "chessboard" && o.board != "charuco") o.board.clear();
  return o;
}

// The ids shown: first_id, first_id+1, ... wrapping at the dictionary's end, skipping ambiguous ones.
std::vector<int> scene_ids(const Dictionary& d, int first_id, int count) {
  std::vector<int> ids;
  if (d.size() == 0) return ids;
  int id = first_id % d.size();
  for (int tries = 0; tries < d.size() && int(ids.size()) < count; ++tries, id = (id + 1) % d.size())
    if (unambiguous(d, id)) ids.push_back(id);
  return ids;
}

// A desk seen from above: a warm surface with grain, soft stains and shadows, and a few thin lines (edges of a
// sheet, a pencil). Nothing square and dark, so the detector's candidates all come from the markers.
cv::Mat desk(cv::Size size, uint64_t seed) {
  cv::RNG rng(mix(seed ^ 0xDE5Cull));
  // Surface tone: a few random colours smoothly interpolated.
  cv::Mat low(3, 4, CV_32FC3);
  const double base = rng.uniform(165.0, 185.0);   // red; green and blue below it: wood, cork, beige
  // Every random draw is its own statement, so the same seed gives the same desk whatever order the compiler
  // evaluates a call's arguments in; they are taken in the order GCC took them, which keeps the desk it drew.
  const double green = rng.uniform(0.85, 0.92), blue = rng.uniform(0.68, 0.8);
  const cv::Vec3f tone(float(base * blue), float(base * green), float(base));
  for (int y = 0; y < low.rows; ++y)
    for (int x = 0; x < low.cols; ++x) {
      const float d = float(rng.uniform(-22.0, 22.0));
      low.at<cv::Vec3f>(y, x) = tone + cv::Vec3f(d, d * 0.9f, d * 0.8f);
    }
  cv::Mat bg;
  cv::resize(low, bg, size, 0, 0, cv::INTER_CUBIC);

  // Grain: noise stretched along x into streaks.
  cv::Mat grain(std::max(size.height / 5, 2), 12, CV_32FC1);
  rng.fill(grain, cv::RNG::NORMAL, 0, 3);
  cv::resize(grain, grain, size, 0, 0, cv::INTER_CUBIC);
  std::vector<cv::Mat> ch;
  cv::split(bg, ch);
  for (auto& c : ch) c += grain;
  cv::merge(ch, bg);

  // Soft blobs: stains, shadows and reflections, blurred far beyond any edge (at an eighth of the size, since
  // they are smooth anyway and a full-size blur this wide costs a tenth of a second).
  const cv::Size small(std::max(size.width / 8, 2), std::max(size.height / 8, 2));
  cv::Mat blobs(small, CV_32FC3, cv::Scalar::all(0));
  for (int i = 0, n = rng.uniform(4, 8); i < n; ++i) {
    const int cy = rng.uniform(0, small.height), cx = rng.uniform(0, small.width);
    const cv::Point c(cx, cy);
    const int r = std::max(rng.uniform(small.width / 16, small.width / 5), 1);
    const double v = rng.uniform(-40.0, 30.0);
    cv::circle(blobs, c, r, cv::Scalar(v, v * 0.95, v * 0.9), -1, cv::LINE_AA);
  }
  cv::GaussianBlur(blobs, blobs, cv::Size(0, 0), small.width / 25.0);
  cv::resize(blobs, blobs, size, 0, 0, cv::INTER_CUBIC);
  bg += blobs;

  // Thin lines: mid grey, long, anti-aliased, running roughly across or along the frame.
  for (int i = 0, n = rng.uniform(2, 5); i < n; ++i) {
    const int w = size.width, h = size.height;
    const bool across = rng.uniform(0, 2) != 0;
    const cv::Point a = across ? cv::Point(-w / 8, rng.uniform(0, h)) : cv::Point(rng.uniform(0, w), -h / 8);
    const cv::Point b = across ? cv::Point(w + w / 8, rng.uniform(0, h)) : cv::Point(rng.uniform(0, w), h + h / 8);
    const double g = rng.uniform(70.0, 120.0);
    cv::line(bg, a, b, cv::Scalar(g, g * 1.05, g * 1.1), rng.uniform(1, 3), cv::LINE_AA);
  }
  cv::GaussianBlur(bg, bg, cv::Size(0, 0), 0.8);
  cv::Mat out;
  bg.convertTo(out, CV_8UC3);
  return out;
}

}  // namespace

SyntheticWorld::SyntheticWorld(cv::Size size, double focal_px, uint64_t seed)
    : size_(std::max(size.width, 16), std::max(size.height, 16)),
      focal_px_(std::isfinite(focal_px) && focal_px > 1 ? focal_px : 600),
      seed_(seed) {
  background_ = desk(size_, seed_);
  // Unit-normal samples in kNoiseUnit steps, enough for every row of a frame at any offset.
  const int n = size_.width * size_.height * 3 + kNoiseSlack;
  cv::Mat normal(1, n, CV_32FC1);
  cv::RNG rng(mix(seed_ ^ 0x7015Eull));
  rng.fill(normal, cv::RNG::NORMAL, 0, kNoiseUnit);
  normal.convertTo(noise_, CV_16SC1);
}

void SyntheticWorld::set_controls(const SyntheticControls& c) {
  SyntheticControls o = clamped(c);
  if (auto d = dictionary_by_name(o.dict))
    o.dict = d->name();
  else
    o.dict = controls_.dict;
  controls_ = o;
}

SyntheticFrame SyntheticWorld::render(double t) const {
  // controls() hands out a mutable reference, so clamp again here rather than trust what it holds.
  const SyntheticControls c = clamped(controls_);
  if (!c.board.empty()) return render_board(c, std::isfinite(t) ? t : 0);
  SyntheticFrame frame;
  frame.image = background_.clone();
  auto dict = dictionary_by_name(c.dict);
  if (!dict) dict = dictionary_by_name("ARUCO_ORIGINAL");
  if (!std::isfinite(t)) t = 0;

  // [SECTION] geometry: the group centre comes and goes; each marker sways around its slot and turns.
  std::vector<int> ids;
  for (int id : c.ids)
    if (id < dict->size()) ids.push_back(id);
  if (c.ids.empty()) ids = scene_ids(*dict, c.first_id, c.markers);
  const int n = int(ids.size());
  const int cols = n <= 2 ? n : n <= 4 ? 2 : n <= 6 ? 3 : 4;
  const int rows = cols > 0 ? (n + cols - 1) / cols : 0;
  const double side = c.marker_size_m, spacing = 1.6 * side;
  const double group_z = c.distance_m * (1 + 0.35 * std::sin(0.33 * t));
  const cv::Point2d pp((size_.width - 1) / 2.0, (size_.height - 1) / 2.0);
  const int cells = dict->marker_size() + 2;
  const double half = side / 2, half_quiet = half * (cells + 2) / cells;

  struct Placed {
    int id;
    double z;
    bool visible;
    Quad marker, quiet;
  };
  std::vector<Placed> placed;
  for (int i = 0; i < n; ++i) {
    const int r = i / cols, in_row = std::min(cols, n - r * cols);
    const double sx = ((i % cols) - (in_row - 1) / 2.0) * spacing, sy = (r - (rows - 1) / 2.0) * spacing;
    const Motion m = motion_of(seed_, i);
    const cv::Vec3d centre(sx + 0.12 * spacing * std::sin(m.fx * t + m.px),
                           sy + 0.12 * spacing * std::sin(m.fy * t + m.py),
                           group_z + 0.15 * side * std::sin(m.fz * t + m.pz));
    // Two swaying tilt axes, scaled back when together they would exceed tilt_deg.
    double ta = std::sin(m.fa * t + m.pa), tb = std::sin(m.fb * t + m.pb);
    const double norm = std::hypot(ta, tb);
    if (norm > 1) ta /= norm, tb /= norm;
    const cv::Matx33d R = rotation(c.tilt_deg * ta, c.tilt_deg * tb, m.roll0 + m.roll_rate * t);

    Placed p{ids[size_t(i)], centre[2], true, {}, {}};
    const cv::Vec2d unit[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};  // top-left first, clockwise on screen
    for (int k = 0; k < 4; ++k) {
      for (int q = 0; q < 2; ++q) {
        const double h = q ? half_quiet : half;
        const cv::Vec3d P = centre + R * cv::Vec3d(unit[k][0] * h, unit[k][1] * h, 0);
        if (P[2] < 0.01) { p.visible = false; break; }
        const cv::Point2f img(float(pp.x + focal_px_ * P[0] / P[2]), float(pp.y + focal_px_ * P[1] / P[2]));
        (q ? p.quiet : p.marker)[size_t(k)] = img;
      }
    }
    if (p.visible) placed.push_back(p);
  }

  // [SECTION] drawing: far to near, so a nearer marker covers a farther one.
  std::sort(placed.begin(), placed.end(), [](const Placed& a, const Placed& b) { return a.z > b.z; });
  for (size_t i = 0; i < placed.size(); ++i) {
    const Placed& p = placed[i];
    draw_marker(frame.image, *dict, p.id, p.marker, 1.0, supersample_for(p.marker, cells), kInk, kPaper);
    bool inside = true;
    for (const auto& q : p.marker)
      inside = inside && q.x >= 0 && q.y >= 0 && q.x <= float(size_.width - 1) && q.y <= float(size_.height - 1);
    bool covered = false;
    for (size_t j = i + 1; j < placed.size() && !covered; ++j) {
      std::vector<cv::Point2f> overlap;
      covered = cv::intersectConvexConvex(std::vector<cv::Point2f>(p.marker.begin(), p.marker.end()),
                                          std::vector<cv::Point2f>(placed[j].quiet.begin(), placed[j].quiet.end()),
                                          overlap) > 0;
    }
    if (inside && !covered) frame.markers.push_back({p.id, dict->name(), p.marker});
  }
  std::sort(frame.markers.begin(), frame.markers.end(),
            [](const TruthMarker& a, const TruthMarker& b) { return a.id < b.id; });

  optics(frame.image, c, t);
  return frame;
}

void SyntheticWorld::optics(cv::Mat& image, const SyntheticControls& c, double t) const {
  // [SECTION] optics and sensor: blur, then light (slow global swell, a gradient that turns), then noise.
  if (c.blur_px > 0.05) cv::GaussianBlur(image, image, cv::Size(0, 0), c.blur_px);
  const double global = c.light * (0.85 + 0.15 * std::sin(0.5 * t + 1.0));
  const double ga = 0.2 * t;
  const double gx = 0.35 * std::cos(ga) / size_.width, gy = 0.35 * std::sin(ga) / size_.height;
  const int noise_scale = int(std::lround(c.noise / kNoiseUnit * 256));
  cv::RNG rows_rng(time_key(seed_, t));
  const int w3 = size_.width * 3;
  std::vector<int> gain(size_t(w3), 0);
  const int16_t* table = noise_.ptr<int16_t>();
  for (int y = 0; y < size_.height; ++y) {
    // The light is linear across a row: 8.8 fixed point per channel sample, so the loop below vectorises.
    const double g0 = 256 * global * (1 + gy * (y - size_.height / 2.0) - gx * size_.width / 2.0), dg = 256 * global * gx;
    for (int x = 0; x < size_.width; ++x) {
      const int g = int(g0 + dg * x + 0.5);
      gain[size_t(3 * x)] = gain[size_t(3 * x + 1)] = gain[size_t(3 * x + 2)] = g;
    }
    uint8_t* px = image.ptr<uint8_t>(y);
    const int16_t* nz = table + size_t(y) * size_t(w3) + size_t(rows_rng.uniform(0, kNoiseSlack));
    const int* gp = gain.data();
    for (int i = 0; i < w3; ++i) {
      const int v = (px[i] * gp[i] + nz[i] * noise_scale + 128) >> 8;
      px[i] = uint8_t(v < 0 ? 0 : v > 255 ? 255 : v);
    }
  }
}

// [SECTION] board mode: a calibration board held in front of a known camera, from pose to pose.

struct SyntheticWorld::BoardStage {
  std::string name;   // "chessboard", "charuco"
  SynthCamera camera;
  std::unique_ptr<ChessboardRenderer> renderer;
  std::vector<std::pair<cv::Vec3d, cv::Vec3d>> poses;
  // The pose held last, rendered at full quality once: a pause shows the same board for a second.
  int cached_pose = -1;
  cv::Mat cached;   // BGR, before optics
  // The pose being moved to, rendered at full quality a band of rows a frame while the board moves, so that no
  // one frame pays for the whole of it.
  int next_pose = -1, next_rows = 0;
  cv::Mat1f next;
};

BoardSpec SyntheticWorld::board_spec(const std::string& board) {
  return default_board(board == "charuco" ? BoardKind::charuco : BoardKind::chessboard);
}

const SyntheticWorld::BoardStage* SyntheticWorld::stage(const std::string& board) const {
  if (board.empty()) return nullptr;
  if (board_ && board_->name == board) return board_.get();
  auto s = std::make_shared<BoardStage>();
  s->name = board;
  // SynthCamera's defaults are for 640x480: the same lens at this world's size.
  const double scale = size_.width / double(s->camera.size.width);
  s->camera.camera_matrix(0, 0) *= scale;
  s->camera.camera_matrix(1, 1) *= scale;
  s->camera.camera_matrix(0, 2) *= scale;
  s->camera.camera_matrix(1, 2) *= scale;
  s->camera.size = size_;
  const SynthChessboard sb = SynthChessboard::of(board_spec(board));
  s->renderer = std::make_unique<ChessboardRenderer>(s->camera, sb);
  s->poses = chessboard_poses(s->camera, sb, kBoardPoses, unsigned(seed_ % 1000 + 3));
  // A ChArUco board may be read in part: every fourth pose holds it partly out of the image.
  if (board == "charuco") {
    const auto partial = partial_board_poses(s->camera, sb, kBoardPoses / 4, unsigned(seed_ % 1000 + 5));
    for (size_t i = 0; i < partial.size(); ++i)
      s->poses.insert(s->poses.begin() + std::ptrdiff_t(std::min(s->poses.size(), 4 * i + 3)), partial[i]);
  }
  if (s->poses.empty()) return nullptr;
  board_ = std::move(s);
  return board_.get();
}

const SynthCamera* SyntheticWorld::board_camera() const {
  const BoardStage* s = stage(clamped(controls_).board);
  return s ? &s->camera : nullptr;
}

SyntheticFrame SyntheticWorld::render_board(const SyntheticControls& c, double t) const {
  const BoardStage* s = stage(c.board);
  SyntheticFrame frame;
  if (!s) {
    frame.image = background_.clone();
    return frame;
  }
  BoardStage& st = *board_;
  const int n = int(st.poses.size());
  const double period = kBoardMoveS + kBoardHoldS;
  const double cycle = std::floor(std::max(t, 0.0) / period);
  const double phase = std::max(t, 0.0) - cycle * period;
  const int k = int(std::fmod(cycle, double(n)));
  const int h = st.camera.size.height;
  const auto& [rk, tk] = st.poses[size_t(k)];
  if (phase >= kBoardMoveS) {
    if (st.cached_pose != k) {
      if (st.next_pose != k) st.next_rows = 0;
      st.renderer->render_rows(rk, tk, st.next, st.next_rows, h);
      cv::cvtColor(st.renderer->finish(st.next, rk, tk).image, st.cached, cv::COLOR_GRAY2BGR);
      st.cached_pose = k;
      st.next_pose = -1;
    }
    frame.image = st.cached.clone();
  } else {
    // On the way from the previous pose: nobody measures a moving board, so one sample a pixel is enough.
    const auto& [r0, t0] = st.poses[size_t((k + n - 1) % n)];
    const double a = phase / kBoardMoveS, e = a * a * (3 - 2 * a);   // eased: still at either end
    cv::cvtColor(st.renderer->render(r0 * (1 - e) + rk * e, t0 * (1 - e) + tk * e, 0, 0, 1, 1).image, frame.image,
                 cv::COLOR_GRAY2BGR);
    if (st.next_pose != k) st.next_pose = k, st.next_rows = 0;
    const int band = (h + 7) / 8;
    st.renderer->render_rows(rk, tk, st.next, st.next_rows, std::min(h, st.next_rows + band));
    st.next_rows = std::min(h, st.next_rows + band);
  }
  optics(frame.image, c, t);
  return frame;
}

}  // namespace arwb
