// corner_refinement: a quad's four corners refined to subpixel accuracy on the grey image, from profiles across its
// sides. The detector runs it on each quad before perspective_removal.
#include "detect/pipeline.hpp"

#include "detect/kernels/kernels.hpp"
#include "detect/stages/sampling.hpp"
#include "detect/stages/side_lines.hpp"

#include <cmath>

namespace arwb::stages {

// profile.size() samples from `from` in steps of `step`, bilinear, as grey levels times 65536 (integers: the
// refinement's sums over a profile stay exact and cheap). Where the whole line lies inside the image (the usual case)
// the samples step along it in 1/256 pixel with bilinear_q8, several at a time where the level has a kernel for it
// (the same integers); otherwise through sample_bilinear's clamping.
void sample_line(const cv::Mat& grey, cv::Point2d from, cv::Point2d step, std::span<int> profile) {
  const int n = int(profile.size());
  const cv::Point2d to = from + step * double(n - 1);
  const double xmax = grey.cols - 1.001, ymax = grey.rows - 1.001;
  if (std::min(from.x, to.x) < 0 || std::min(from.y, to.y) < 0 || std::max(from.x, to.x) > xmax ||
      std::max(from.y, to.y) > ymax) {
    for (int j = 0; j < n; ++j)
      profile[size_t(j)] = int(std::lround(65536 * sample_bilinear(grey, from.x + j * step.x, from.y + j * step.y)));
    return;
  }
  const uchar* data = grey.data;
  const size_t stride = grey.step;
  // 16 fractional bits while stepping, so that the steps add up no error to speak of over a profile. Rounded as
  // std::llround, halves away from zero, inline (llround is a library call, four a profile): truncated, then a step
  // away from zero when what was cut is a half or more (exact below 2^52; the line is inside the image here).
  auto round = [](double v) {
    int64_t t = int64_t(v);
    const double cut = v - double(t);
    t += (cut >= 0.5) - (cut <= -0.5);
    return t;
  };
  int64_t x = round(from.x * 65536), y = round(from.y * 65536);
  const int64_t dx = round(step.x * 65536), dy = round(step.y * 65536);
  int j = 0;
  // Several at a time where the line stays 3 pixels inside the row's end (the kernels read 4 bytes a sample) and its
  // positions in 1/65536 pixel and the pixels' offsets fit 32 bits.
  if (std::max(from.x, to.x) < grey.cols - 4 && grey.cols < 16384 && grey.rows < 16384 &&
      double(grey.step) * grey.rows < 2e9)
    j = kernels::kernels().sample_line(data, stride, int(x), int(y), int(dx), int(dy), n, profile.data());
  x += dx * j;
  y += dy * j;
  for (; j < n; ++j, x += dx, y += dy)
    profile[size_t(j)] = bilinear_q8(data, stride, int(x >> 8), int(y >> 8));
}

namespace {

// corner_refinement's profiles, kProfilesAtOnce at a time (kernels' profile_edges): each one's spread, and the sums
// for the centroid of its rising steps above a fifth of the highest step. Each profile's sums are added in the same
// order as alone (the same bits; no multiply-add is fused), but its chain of dependent additions runs beside the
// others' instead of after them, and a step at or below the floor adds +0, with no branch.
constexpr int kProfilesAtOnce = 8;
// Profile q is samples [first[q], first[q] + samples) of `profiles`.
void profile_edges(const int* profiles, const int* first, int samples, int* spread, double* wsum, double* jsum) {
  thread_local std::vector<int> scratch;
  const size_t need = size_t(kProfilesAtOnce) * size_t(samples);
  if (scratch.size() < need) scratch.resize(need);
  kernels::kernels().profile_edges(profiles, first, samples, spread, wsum, jsum, scratch.data());
}

// One pass of refine_corners; false when an edge could not be trusted (the corners are then left as they were).
bool refine_corners_once(const cv::Mat& grey, Quad& corners, int cells, const DetectorParams& p, double slack) {
  // Each side of the marker is the edge between its black border (inside) and the white quiet zone (outside).
  // Along the side, profiles across the edge locate it to a fraction of a pixel (the centroid of the rising
  // gradient, which sits on the edge for any symmetric blur); a line is fitted through those points and the
  // corners are where neighbouring lines meet. A corner that would move more than half a cell keeps its place.
  // Only the gradient above a fifth of the profile's peak counts: below it is mostly noise, spread evenly over
  // the profile, and it pulled the centroid towards the profile's middle (docs/detector-history.md has what that
  // and a profile every 2 px, not 3, did to the corners' error on the bench sets).
  double min_side = 1e18;
  for (int i = 0; i < 4; ++i)
    min_side = std::min(min_side, double(cv::norm(corners[size_t(i)] - corners[size_t((i + 1) % 4)])));
  const double cell = min_side / cells;
  const double reach = std::max(std::clamp(0.6 * cell, 2.5, double(p.subpix_window_px) + 1.0), slack);
  const double step = 0.5;
  const int samples = static_cast<int>(std::lround(2 * reach / step)) + 1;
  const cv::Point2f centre = quad_centre(corners);

  std::array<cv::Vec3d, 4> lines;  // a x + b y = c, (a, b) unit
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d a = corners[size_t(i)], b = corners[size_t((i + 1) % 4)];
    const cv::Point2d dir = (b - a) / cv::norm(b - a);
    cv::Point2d normal(dir.y, -dir.x);
    if (normal.dot(cv::Point2d(centre) - a) > 0) normal = -normal;  // outward
    const int count = std::clamp(static_cast<int>(cv::norm(b - a) / 2), 8, 32);
    // Kept from side to side and quad to quad (per thread): no allocation a side.
    thread_local std::vector<cv::Point2d> pts, bases;
    thread_local std::vector<int> profiles;   // count profiles of `samples` grey levels times 65536
    pts.clear();
    bases.resize(size_t(count));
    profiles.resize(size_t(count) * size_t(samples));
    for (int k = 0; k < count; ++k) {
      const double t = 0.12 + 0.76 * (k + 0.5) / count;  // away from the corners
      bases[size_t(k)] = a + (b - a) * t;
      sample_line(grey, bases[size_t(k)] - normal * reach, normal * step,
                  std::span<int>(profiles.data() + size_t(k) * size_t(samples), size_t(samples)));
    }
    // Each profile's edge, kProfilesAtOnce at a time (profile_edges).
    for (int k0 = 0; k0 < count; k0 += kProfilesAtOnce) {
      int first[kProfilesAtOnce];   // past the last profile: the last again, computed and dropped
      for (int q = 0; q < kProfilesAtOnce; ++q) first[q] = std::min(k0 + q, count - 1) * samples;
      int spread[kProfilesAtOnce];
      double wsum[kProfilesAtOnce], jsum[kProfilesAtOnce];
      profile_edges(profiles.data(), first, samples, spread, wsum, jsum);
      for (int q = 0; q < kProfilesAtOnce && k0 + q < count; ++q) {
        if (spread[q] < 10 * 65536) continue;  // no edge here (occluded, glare)
        if (wsum[q] <= 0) continue;
        pts.push_back(bases[size_t(k0 + q)] + normal * (-reach + (jsum[q] / wsum[q] + 0.5) * step));
      }
    }
    if (pts.size() < 3) return false;  // not enough edge to trust: keep the corners as they are
    lines[size_t(i)] = fit_side(pts);
  }
  Quad refined;
  if (!meet_sides(lines, &refined)) return false;
  for (size_t i = 0; i < 4; ++i)
    if (cv::norm(refined[i] - corners[i]) > std::max({cell, 2.0, slack})) return false;
  corners = refined;
  return true;
}

}  // namespace

void refine_corners(const cv::Mat& grey, Quad& corners, int cells, const DetectorParams& p, int factor) {
  if (p.corner_refinement == 0) return;
  // Each pass profiles across the sides found by the last one, so the profiles end up square to the true edges;
  // it stops when no corner moves more than subpix_epsilon_px (usually after two or three passes). A quad found on
  // the decimated image starts up to about `factor` pixels off: the first pass reaches that far, and one more
  // pass follows with the usual reach.
  // When that first reach is longer than the usual one (0.6 of a cell: a small marker), its profiles can take in
  // an inner cell's edge, and it takes two more passes to settle (tiny markers stay a fraction of a pixel off after
  // one); a large marker's noisy edges only wander with more.
  double min_side = 1e18;
  for (size_t i = 0; i < 4; ++i) min_side = std::min(min_side, double(cv::norm(corners[i] - corners[(i + 1) % 4])));
  const double slack = factor > 1 ? factor + 1.5 : 0;
  const bool far = slack > std::clamp(0.6 * min_side / cells, 2.5, double(p.subpix_window_px) + 1.0);
  const int passes = p.subpix_max_iterations + (factor > 1 ? 1 : 0) + (far ? 1 : 0);
  for (int it = 0; it < passes; ++it) {
    const Quad before = corners;
    if (!refine_corners_once(grey, corners, cells, p, it == 0 ? slack : 0)) return;
    double moved = 0;
    for (size_t k = 0; k < 4; ++k) moved = std::max(moved, double(cv::norm(corners[k] - before[k])));
    if (moved < p.subpix_epsilon_px) return;
  }
}

}  // namespace arwb::stages
