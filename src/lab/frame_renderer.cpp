// A lab run's frames: each rendered through the camera and sensor model exactly as its plan, options, cell and
// frame say (LabFrameRenderer, run.hpp), whatever ran before it and on whatever thread.
#include "lab/run.hpp"

#include "detect/dictionary.hpp"
#include "synth/marker_view.hpp"
#include "synth/synth.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

namespace arwb::lab {
namespace {

// A line of `length` pixels at `angle` radians, normalised: the streak a turning camera draws.
cv::Mat motion_kernel(double length, double angle) {
  const int n = std::max(1, int(std::ceil(length)) | 1);
  cv::Mat1f k(n, n, 0.f);
  const cv::Point2d c((n - 1) / 2.0, (n - 1) / 2.0), d(std::cos(angle), std::sin(angle));
  const int steps = 4 * n;
  for (int i = 0; i <= steps; ++i) {
    const cv::Point2d p = c + d * (length * (double(i) / steps - 0.5));
    const int x = std::clamp(int(std::lround(p.x)), 0, n - 1), y = std::clamp(int(std::lround(p.y)), 0, n - 1);
    k(y, x) += 1.f;
  }
  cv::Mat out;
  k.convertTo(out, CV_32F, 1.0 / cv::sum(k)[0]);
  return out;
}

// Optics and sensor, the same for every frame of a cell: defocus, the hand's motion during the exposure, then
// light to electrons, noise and grey levels.
cv::Mat camera_picture(cv::Mat1f levels, const LabOptions& options, const Cell& cell, std::mt19937& rng) {
  const double f = options.camera.camera_matrix(0, 0);
  std::uniform_real_distribution<double> u(0, 1);
  const Exposure ex = auto_exposure(options.sensor, cell.lux);
  const double defocus = defocus_sigma_px(options.sensor, cell.distance_m, f);
  const double shake = shake_length_px(options.sensor, ex.exposure_s, f);
  if (defocus > 0.05) cv::GaussianBlur(levels, levels, cv::Size(), defocus);
  if (shake > 0.3) {
    std::normal_distribution<double> speed(0, 1);
    const double length = std::abs(speed(rng)) * shake;
    const double angle = u(rng) * CV_PI;
    if (length > 0.5) cv::filter2D(levels, levels, -1, motion_kernel(length, angle));
  }
  // The plan's added blur (blurs_px), an optical one: before the sensor, so its noise stays sharp.
  if (cell.blur_px > 0) cv::GaussianBlur(levels, levels, cv::Size(), cell.blur_px);
  cv::Mat grey = expose(levels, options.sensor, cell.lux, rng);
  // The plan's added noise (noises), in grey levels on the sensor's picture. Drawn after the sensor's, from a
  // seed of the frame's draws: a plan without it draws exactly what it drew before.
  if (cell.noise > 0) {
    cv::Mat1f noisy, noise(grey.size());
    cv::RNG draw(uint64_t(rng()) << 32 | rng());
    draw.fill(noise, cv::RNG::NORMAL, 0, cell.noise);
    grey.convertTo(noisy, CV_32F);
    noisy += noise;
    noisy.convertTo(grey, CV_8U);   // rounded and clipped to 0..255
  }
  cv::Mat bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

// The background's grey where a patch lies: synth/marker_view.cpp paints the background as a ramp from 90 grey
// levels at the left edge to 150 at the right.
double background_level(double x, int width) { return 90 + 60.0 * x / std::max(1, width); }

// Covers `share` of the marker's area along its side `side` (0 top, 1 right, 2 bottom, 3 left of the upright
// marker) with a patch of the background's grey, as a finger or a cable over the print would: the patch runs
// along the whole side and a little past it (over the white margin too), `share` of the way across the marker in
// the marker's own plane (mapped by the homography of its corners, so the share holds under perspective). Its
// edges are anti-aliased (4x4 samples per pixel), as the renderer's are.
void occlude(cv::Mat1f& levels, const Quad& corners, double share, int side) {
  if (share <= 0) return;
  std::vector<cv::Point2f> unit{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, quad;
  for (int i = 0; i < 4; ++i) quad.push_back(corners[size_t((side + i) % 4)]);
  const cv::Mat H = cv::getPerspectiveTransform(unit, quad);
  const float past = 0.3f;   // beyond the side and its ends, in sides: over the margin and onto the background
  const std::vector<cv::Point2f> patch_unit{{-past, -past}, {1 + past, -past}, {1 + past, float(share)},
                                            {-past, float(share)}};
  std::vector<cv::Point2f> patch;
  cv::perspectiveTransform(patch_unit, patch, H);
  const cv::Rect whole(0, 0, levels.cols, levels.rows);
  const cv::Rect roi = cv::boundingRect(patch) & whole;
  if (roi.empty()) return;
  constexpr int kSamples = 4;
  cv::Mat1b mask(roi.height * kSamples, roi.width * kSamples, uchar(0));
  std::vector<cv::Point> at;
  for (const cv::Point2f& p : patch)
    at.emplace_back(int(std::lround((p.x - float(roi.x)) * kSamples)), int(std::lround((p.y - float(roi.y)) * kSamples)));
  cv::fillConvexPoly(mask, at, cv::Scalar(255));
  cv::Mat covered;
  cv::resize(mask, covered, roi.size(), 0, 0, cv::INTER_AREA);
  cv::Mat1f cover;
  covered.convertTo(cover, CV_32F, 1.0 / 255);
  const cv::Point2f centre = (patch[0] + patch[1] + patch[2] + patch[3]) * 0.25f;
  const auto grey = float(background_level(centre.x, levels.cols));
  cv::Mat1f part = levels(roi);
  for (int y = 0; y < roi.height; ++y)
    for (int x = 0; x < roi.width; ++x) part(y, x) += cover(y, x) * (grey - part(y, x));
}

}  // namespace

std::vector<int> lab_marker_ids(const LabPlan& plan, unsigned seed) {
  const auto dict = dictionary_by_name(plan.dictionary);
  if (!dict) return {};
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick(0, dict->size() - 1);
  std::set<int> chosen;
  while (int(chosen.size()) < std::min(plan.markers, dict->size())) chosen.insert(pick(rng));
  std::vector<int> ids(chosen.begin(), chosen.end());
  std::shuffle(ids.begin(), ids.end(), rng);
  return ids;
}

LabFrameRenderer::LabFrameRenderer(const LabPlan& plan, const LabOptions& options, std::vector<int> ids)
    : plan_(plan), options_(options), ids_(std::move(ids)), cells_(plan.cells(options.camera.camera_matrix(0, 0))),
      renderer_(options.camera, SynthMarker{plan.dictionary, 0, 1.0, 1.5}) {
  options_.finished.clear();   // a renderer needs the plan's physics, not a run's bookkeeping
  options_.on_cell = nullptr;
  options_.stop = nullptr;
}

LabFrame LabFrameRenderer::render(size_t ci, int k) const {
  LabFrame out;
  if (ci >= cells_.size() || k < 0 || k >= frames_per_cell() || ids_.empty()) return out;
  const Cell& cell = cells_[ci];
  const SynthCamera& cam = options_.camera;
  // Frames are drawn by the cell of the paper's axes this one belongs to: cells that differ only in an added axis
  // (tilt, blur, noise, occlusion) show the same markers, in the same places, with the same noise.
  const size_t pi = plan_.pose_index(ci);
  if (k >= plan_.frames_per_cell) {
    // A frame without a marker: one of the benchmark's cluttered photographs with no marker in it (rectangles,
    // checkerboard patches, text, and decoys with a black border whose bits decode to nothing), through the
    // cell's optics and sensor. Every marker a detector reports on it is a false positive.
    const int e = k - plan_.frames_per_cell;
    out.empty = out.visible = true;
    std::mt19937 rng(options_.seed * 2246822519u + unsigned(pi) * 3266489917u + unsigned(e) * 668265263u);
    SynthOptions so;
    so.size = cam.size;
    so.dictionaries = {*dictionary_by_name(plan_.dictionary)};
    so.empty_fraction = 1.0;
    const SynthImage photo = synth_photo(so, options_.seed + 1000003ull * (pi + 1), e);
    cv::Mat grey;
    cv::cvtColor(photo.image, grey, cv::COLOR_BGR2GRAY);
    cv::Mat1f levels;
    grey.convertTo(levels, CV_32F);
    out.image = camera_picture(levels, options_, cell, rng);
    return out;
  }
  // Each frame's draws come from its own seed: a frame is the same whatever ran before it, on any thread.
  const unsigned frame_seed = options_.seed * 2654435761u + unsigned(pi) * 7919u + unsigned(k) * 104729u;
  std::mt19937 rng(frame_seed);
  std::uniform_real_distribution<double> u(0, 1);
  out.id = ids_[size_t(int(pi) * plan_.frames_per_cell + k) % ids_.size()];
  renderer_.set_marker(SynthMarker{plan_.dictionary, out.id, 1.0, 1.5});
  // The pose: facing the camera, tilted about x and y, turned in plane; the centre somewhere in the middle of the
  // picture, at the cell's distance. Geometry is scale-free: a marker of side L at t is one of side 1 at t / L.
  const double L = cell.size_mm / 1000;
  if (!(L > 0)) return out;   // a sides_px plan's cells without the camera's focal length: nothing to render
  MarkerView truth;
  cv::Mat1f levels;
  for (int tries = 0; tries < 20 && !out.visible; ++tries) {
    const double roll = u(rng) * 2 * CV_PI;
    const double draw_x = u(rng), draw_y = u(rng);
    double tx = (draw_x * 2 - 1) * plan_.max_tilt_deg * CV_PI / 180;
    double ty = (draw_y * 2 - 1) * plan_.max_tilt_deg * CV_PI / 180;
    if (cell.tilt_deg >= 0) {
      // A fixed tilt: exactly that angle about an axis in the marker's plane in a random direction (the first
      // draw), the roll still random. The second draw goes unused, so the marker lands where the random tilt's
      // would have.
      const double axis = draw_x * 2 * CV_PI;
      tx = std::cos(axis) * cell.tilt_deg * CV_PI / 180;
      ty = std::sin(axis) * cell.tilt_deg * CV_PI / 180;
    }
    const double px = cam.size.width * (0.2 + 0.6 * u(rng));
    const double py = cam.size.height * (0.2 + 0.6 * u(rng));
    cv::Matx33d Rt, Rr;
    cv::Rodrigues(cv::Vec3d(tx, ty, 0), Rt);
    cv::Rodrigues(cv::Vec3d(0, 0, roll), Rr);
    cv::Vec3d rvec;
    cv::Rodrigues(cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1) * Rt * Rr, rvec);
    std::vector<cv::Point2d> ray_in{{px, py}}, ray;
    cv::undistortPoints(ray_in, ray, cv::Mat(cam.camera_matrix), cam.distortion);
    cv::Vec3d dir(ray[0].x, ray[0].y, 1);
    dir *= cell.distance_m / cv::norm(dir);
    levels = renderer_.render_levels(rvec, dir * (1.0 / L), &truth);
    out.visible = truth.all_inside;
    out.roll_deg = roll * 180 / CV_PI;
    out.tilt_x_deg = tx * 180 / CV_PI;
    out.tilt_y_deg = ty * 180 / CV_PI;
    // The rotation vector (tx, ty, 0) turns the marker by its length about an axis in its plane, and the roll
    // about its normal leaves the normal where it is: the normal is that length away from the optical axis.
    out.tilt_deg = std::hypot(tx, ty) * 180 / CV_PI;
  }
  if (!out.visible) return out;
  out.corners = truth.corners;
  if (cell.occlusion > 0) {
    // The covered side from a generator of its own: the frame's other draws stay those of the cell without it.
    // Covered before the light falls: the patch is in the same shadow or glint as the print around it.
    std::mt19937 side_rng(frame_seed ^ 0x5bd1e995u);
    out.occluded_side = int(side_rng() % 4);
    occlude(levels, out.corners, cell.occlusion, out.occluded_side);
  }
  // Shadows and glints from a generator of their own, so the pose and the noise stay those of the frame's seed
  // (seeded by the pose's cell: cells differing only in an added axis get the same light).
  std::mt19937 light_rng(options_.seed * 3624381323u + unsigned(pi) * 2246822519u + unsigned(k) * 40503u);
  out.light = apply_scene_light(levels, options_.light, cell.distance_m, cell.lux, cam.camera_matrix(0, 0),
                                out.corners, light_rng);
  out.image = camera_picture(levels, options_, cell, rng);
  return out;
}

}  // namespace arwb::lab
