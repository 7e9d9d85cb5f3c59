#include "lab/run.hpp"

#include "lab/detectors.hpp"
#include "lab/stats.hpp"
#include "base/decimals.hpp"
#include "detect/detector.hpp"
#include "detect/video_search.hpp"
#include "detect/dictionary.hpp"
#include "peers/peers.hpp"
#include "synth/marker_view.hpp"
#include "synth/synth.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <mutex>
#include <set>
#include <thread>

namespace arwb::lab {
namespace {

using Clock = std::chrono::steady_clock;

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

double quad_error(const Quad& a, const Quad& b) {
  double e = 0;
  for (size_t i = 0; i < 4; ++i) e += cv::norm(a[i] - b[i]);
  return e / 4;
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

Result<DetectFn> make_detector(const std::string& name, const std::string& dict, const DetectorParams& params,
                               bool video) {
  if (name == "arwb") {
    auto d = dictionary_by_name(dict);
    if (!d) return fail("unknown dictionary " + dict);
    auto det = std::make_shared<Detector>(std::vector<Dictionary>{*d}, params);
    if (video) {
      auto search = std::make_shared<VideoSearch>();
      return DetectFn([det, search](const cv::Mat& img) { return search->detect(*det, img); });
    }
    return DetectFn([det](const cv::Mat& img) { return det->detect(img); });
  }
  if (name == "opencv" || name == "opencv-aruco3") {
    try {
      auto peer = std::make_shared<OpenCvArucoPeer>(dict, name == "opencv-aruco3");
      return DetectFn([peer](const cv::Mat& img) { return peer->detect(img).markers; });
    } catch (const std::exception& e) {
      return fail(name + ": " + e.what());
    }
  }
  if (name == "apriltag") {
    if (!AprilTagPeer::supports(dict)) return fail("apriltag reads the AprilTag families, not " + dict);
    auto peer = std::make_shared<AprilTagPeer>(dict);
    return DetectFn([peer](const cv::Mat& img) { return peer->detect(img).markers; });
  }
  std::string known;
  for (const auto& k : kLabDetectors) known += (known.empty() ? "" : ", ") + k;
  return fail("unknown detector '" + name + "' (" + known + ")");
}

double DetectorTally::median_ms() const {
  if (ms.empty()) return 0;
  std::vector<double> v = ms;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

namespace {

// One frame's outcome for every detector, kept by frame so that tallies do not depend on which thread ran it.
struct FrameOutcome {
  bool visible = false;
  float tilt_deg = -1;           // the marker's (a frame with one, placed)
  bool empty = false;            // a frame without a marker: `found` counts false positives
  std::vector<char> marks;       // per detector (namespace mark)
  std::vector<char> other_id;    // per detector: another id reported (the wrong-id rate counts it even beside
                                 // the right one)
  std::vector<int> found;
  std::vector<double> ms;
};

// A thread's own renderer and detectors (AprilTag's detector and the renderer's buffers are not shared).
struct Worker {
  LabFrameRenderer renderer;
  std::vector<DetectFn> detectors;
};

FrameOutcome run_frame(Worker& w, size_t ci, double side_px, int k) {
  const LabFrame frame = w.renderer.render(ci, k);
  FrameOutcome fo;
  fo.visible = frame.visible;
  fo.empty = frame.empty;
  if (frame.visible && !frame.empty) fo.tilt_deg = float(frame.tilt_deg);
  if (!frame.visible) {   // the marker could not be placed wholly in view: not a frame of the experiment
    fo.marks.assign(w.detectors.size(), mark::not_visible);
    return fo;
  }
  for (const DetectFn& detect : w.detectors) {
    const auto s0 = Clock::now();
    const std::vector<Marker> found = detect(frame.image);
    fo.ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - s0).count());
    bool other = false;
    fo.found.push_back(int(found.size()));
    fo.marks.push_back(frame_mark(frame, found, side_px, &other));
    fo.other_id.push_back(other);
  }
  return fo;
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

char frame_mark(const LabFrame& frame, const std::vector<Marker>& found, double side_px, bool* other_id) {
  bool right = false, wrong = false;
  if (other_id) *other_id = false;
  if (frame.empty) return found.empty() ? mark::clean : mark::false_positive;
  if (!frame.visible) return mark::not_visible;
  for (const Marker& m : found) {
    if (m.id == frame.id && quad_error(m.corners, frame.corners) < std::max(3.0, 0.2 * side_px)) right = true;
    else if (m.id != frame.id) wrong = true;
  }
  if (other_id) *other_id = wrong;
  return right ? mark::detected : wrong ? mark::wrong_id : mark::missed;
}

Result<LabResults> run_lab(const LabPlan& plan, const LabOptions& options,
                           const std::function<void(int, int)>& progress) {
  const auto t0 = Clock::now();
  const auto dict = dictionary_by_name(plan.dictionary);
  if (!dict) return fail("the plan's dictionary '" + plan.dictionary + "' is unknown");
  if (plan.frames_per_cell < 1) return fail("a plan needs at least one frame per cell");
  const int threads = std::clamp(options.threads, 1, 64);
  std::vector<std::unique_ptr<Worker>> workers;
  for (int i = 0; i < threads; ++i) {
    auto w = std::make_unique<Worker>(Worker{LabFrameRenderer(plan, options, lab_marker_ids(plan, options.seed)), {}});
    for (const std::string& name : options.detectors) {
      auto d = make_detector(name, plan.dictionary, options.params);
      if (!d) return fail(d.error());
      w->detectors.push_back(std::move(*d));
    }
    workers.push_back(std::move(w));
  }
  LabResults out;
  out.plan = plan;
  out.options = options;
  out.ids = workers[0]->renderer.ids();
  const double f = options.camera.camera_matrix(0, 0);
  const std::vector<Cell> cells = plan.cells(f);
  const int total = int(cells.size()) * (plan.frames_per_cell + plan.empty_frames_per_cell());
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  auto report = [&] {
    const int d = ++done;
    if (!progress) return;
    std::lock_guard lock(progress_mutex);
    progress(d, total);
  };
  for (size_t ci = 0; ci < cells.size(); ++ci) {
    const Cell& cell = cells[ci];
    // A cell finished by an earlier run (resume): taken as it was.
    if (ci < options.finished.size() && options.finished[ci]) {
      out.cells.push_back(*options.finished[ci]);
      for (int k = 0; k < plan.frames_per_cell + plan.empty_frames_per_cell(); ++k) report();
      continue;
    }
    CellResult cr;
    cr.cell = cell;
    cr.side_px = marker_side_px(cell.size_mm, cell.distance_m, f);
    const Exposure ex = auto_exposure(options.sensor, cell.lux);
    cr.exposure_ms = ex.exposure_s * 1000;
    cr.gain = ex.gain;
    cr.snr_black_white = snr(options.sensor, cell.lux, 0.12);
    cr.blur_px = std::hypot(defocus_sigma_px(options.sensor, cell.distance_m, f),
                            shake_length_px(options.sensor, ex.exposure_s, f) / 2);
    if (cell.blur_px > 0) cr.blur_px = std::hypot(cr.blur_px, cell.blur_px);
    cr.detectors.resize(options.detectors.size());
    const int empty = plan.empty_frames_per_cell(), n = plan.frames_per_cell + empty;
    std::vector<FrameOutcome> frames(static_cast<size_t>(n));
    std::atomic<int> next{0};
    auto stopped = [&] { return options.stop && options.stop->load(); };
    // A library's exception on one frame (OpenCV, a detector) must not end the process from a worker thread: the
    // first one stops the cell's other threads and becomes the run's error, naming the cell and frame.
    std::mutex failure_mutex;
    std::string failure;
    std::atomic<bool> failed{false};
    auto work = [&](Worker& w) {
      for (int k = next++; k < n && !stopped() && !failed; k = next++) {
        try {
          frames[size_t(k)] = run_frame(w, ci, cr.side_px, k);
        } catch (const std::exception& e) {
          std::lock_guard lock(failure_mutex);
          if (failure.empty())
            failure = "cell " + std::to_string(ci + 1) + ", frame " + std::to_string(k + 1) + ": " + e.what();
          failed = true;
        }
        report();
      }
    };
    std::vector<std::thread> pool;
    for (int i = 1; i < threads; ++i) pool.emplace_back(work, std::ref(*workers[size_t(i)]));
    work(*workers[0]);
    for (std::thread& t : pool) t.join();
    if (failed) return fail(failure);
    if (stopped()) {
      return fail("stopped after " + std::to_string(ci) + " of " + std::to_string(cells.size()) +
                  " cells (those are kept)");
    }
    for (const FrameOutcome& fo : frames) {
      for (size_t d = 0; d < cr.detectors.size(); ++d) cr.detectors[d].marks += fo.marks[d];
      if (!fo.empty) cr.tilts_deg.push_back(fo.tilt_deg);
      if (fo.empty) {
        for (size_t d = 0; d < cr.detectors.size(); ++d) {
          ++cr.detectors[d].empty_frames;
          cr.detectors[d].false_positives += fo.found[d];
        }
        continue;
      }
      if (!fo.visible) continue;
      for (size_t d = 0; d < cr.detectors.size(); ++d) {
        DetectorTally& t = cr.detectors[d];
        ++t.frames;
        t.detected += fo.marks[d] == mark::detected;
        t.wrong_id += fo.other_id[d];
        t.ms.push_back(fo.ms[d]);
      }
    }
    if (options.on_cell) options.on_cell(ci, cr);
    out.cells.push_back(std::move(cr));
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

std::string lab_run_key(const LabPlan& plan, const LabOptions& options) {
  nlohmann::ordered_json j;
  j["plan"] = {plan.name,        plan.dictionary,   plan.markers,         plan.sizes_mm, plan.distances_m,
               plan.lux,         plan.max_tilt_deg, plan.frames_per_cell, plan.empty_share,  plan.sides_px,
               plan.tilts_deg,   plan.blurs_px,     plan.noises,          plan.occlusions};
  j["seed"] = options.seed;
  j["detectors"] = options.detectors;
  nlohmann::ordered_json params = nlohmann::ordered_json::object();
  for (const ParamInfo& info : param_table()) params[info.name] = get_param(options.params, info);
  j["params"] = params;
  const SynthCamera& c = options.camera;
  j["camera"] = {c.size.width, c.size.height, std::vector<double>(c.camera_matrix.val, c.camera_matrix.val + 9),
                 c.distortion};
  const SensorModel& m = options.sensor;
  j["sensor"] = {m.sensitivity, m.full_well,    m.read_noise, m.target_level, m.max_exposure_s,
                 m.max_gain,    m.focal_length_mm, m.f_number, m.focus_m,  m.shake_deg_s};
  const SceneLight& l = options.light;
  j["light"] = {l.direct_outdoor,   l.direct_indoor,   l.direct_evening, l.shadow_chance_half_metre,
                l.sun_diameter_rad, l.glare_chance,    l.glare_lobe_deg, l.glare_peak};
  return j.dump();
}

std::string cell_to_line(const std::string& key, size_t index, const CellResult& c) {
  nlohmann::json j;
  j["key"] = key;
  j["index"] = index;
  j["cell"] = {c.cell.size_mm, c.cell.distance_m, c.cell.lux,      c.cell.side_px,
               c.cell.tilt_deg, c.cell.blur_px,    c.cell.noise, c.cell.occlusion};
  j["side_px"] = c.side_px;
  j["tilts"] = c.tilts_deg;
  j["exposure_ms"] = c.exposure_ms;
  j["gain"] = c.gain;
  j["snr"] = c.snr_black_white;
  j["blur_px"] = c.blur_px;
  nlohmann::json ds = nlohmann::json::array();
  for (const DetectorTally& t : c.detectors)
    ds.push_back({t.frames, t.detected, t.wrong_id, t.ms, t.empty_frames, t.false_positives, t.marks});
  j["detectors"] = ds;
  return j.dump() + "\n";
}

std::optional<std::pair<size_t, CellResult>> cell_from_line(const std::string& key, const std::string& line,
                                                            size_t detectors) {
  const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
  try {
    if (!j.is_object() || j.value("key", std::string()) != key) return std::nullopt;
    CellResult c;
    const auto& cell = j.at("cell");
    double* fields[] = {&c.cell.size_mm, &c.cell.distance_m, &c.cell.lux,      &c.cell.side_px,
                        &c.cell.tilt_deg, &c.cell.blur_px,    &c.cell.noise, &c.cell.occlusion};
    for (size_t i = 0; i < std::size(fields); ++i) *fields[i] = cell.at(i).get<double>();
    c.side_px = j.at("side_px").get<double>();
    c.tilts_deg = j.at("tilts").get<std::vector<float>>();
    c.exposure_ms = j.at("exposure_ms").get<double>();
    c.gain = j.at("gain").get<double>();
    c.snr_black_white = j.at("snr").get<double>();
    c.blur_px = j.at("blur_px").get<double>();
    const auto& ds = j.at("detectors");
    if (!ds.is_array() || ds.size() != detectors) return std::nullopt;
    for (const auto& d : ds) {
      DetectorTally t;
      t.frames = d.at(0).get<int>();
      t.detected = d.at(1).get<int>();
      t.wrong_id = d.at(2).get<int>();
      t.ms = d.at(3).get<std::vector<double>>();
      t.empty_frames = d.at(4).get<int>();
      t.false_positives = d.at(5).get<int>();
      if (d.size() > 6) t.marks = d.at(6).get<std::string>();
      c.detectors.push_back(std::move(t));
    }
    return std::pair{j.at("index").get<size_t>(), std::move(c)};
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;   // a line cut short by the interruption, or one edited by hand
  }
}

std::string lab_table_text(const LabResults& r) {
  std::string s;
  char b[256];
  // The added axes' values of each row (nothing for the paper's plan), each axis's values padded to one width so
  // the columns stay in line: "tilt 0  blur 1.5", "tilt 60 blur 1.5".
  const size_t per_row = std::max<size_t>(1, r.plan.lux.size());
  const struct {
    bool has;
    const char* name;
    double Cell::*value;
  } axes[] = {{r.plan.has_tilts(), "tilt", &Cell::tilt_deg},
              {r.plan.has_blurs(), "blur", &Cell::blur_px},
              {r.plan.has_noises(), "noise", &Cell::noise},
              {r.plan.has_occlusions(), "occluded", &Cell::occlusion}};
  std::vector<std::vector<std::string>> values;   // per row, per axis the plan has
  std::vector<size_t> widths(std::size(axes), 0);
  for (size_t i = 0; i < r.cells.size(); i += per_row) {
    values.emplace_back();
    for (size_t a = 0; a < std::size(axes); ++a) {
      if (!axes[a].has) continue;
      std::snprintf(b, sizeof b, "%g", r.cells[i].cell.*axes[a].value);
      values.back().push_back(b);
      widths[a] = std::max(widths[a], values.back().back().size());
    }
  }
  std::vector<std::string> added;
  for (const std::vector<std::string>& row : values) {
    std::string text;
    for (size_t a = 0, v = 0; a < std::size(axes); ++a) {
      if (!axes[a].has) continue;
      text += std::string(" ") + axes[a].name + " " + row[v] + std::string(widths[a] - row[v].size(), ' ');
      ++v;
    }
    added.push_back(text);
  }
  const int label_width = 20 + int(added.empty() ? 0 : added[0].size());
  for (size_t d = 0; d < r.options.detectors.size(); ++d) {
    std::snprintf(b, sizeof b, "%s: P_Rec %% [95%% interval]\n%-*s", r.options.detectors[d].c_str(), label_width,
                  "size, distance");
    s += b;
    for (double l : r.plan.lux) {
      std::snprintf(b, sizeof b, "  %14.0f lx", l);
      s += b;
    }
    s += "\n";
    for (size_t i = 0; i < r.cells.size(); i += r.plan.lux.size()) {
      const CellResult& c0 = r.cells[i];
      std::snprintf(b, sizeof b, "%3.0f mm %4.1f m %4.0f px", c0.cell.size_mm, c0.cell.distance_m, c0.side_px);
      s += b;
      s += added[i / per_row];
      for (size_t j = i; j < i + r.plan.lux.size() && j < r.cells.size(); ++j) {
        const DetectorTally& t = r.cells[j].detectors[d];
        const auto [lo, hi] = wilson_interval(t.detected, t.frames);
        if (t.frames == 0)   // a cell no frame was taken in (videos of some conditions only)
          std::snprintf(b, sizeof b, "  %5s %11s", "-", "");
        else
          std::snprintf(b, sizeof b, "  %5.1f [%4.0f-%3.0f]", t.p_rec(), 100 * lo, 100 * hi);
        s += b;
      }
      s += "\n";
    }
    int empty = 0, fps = 0;
    for (const CellResult& c : r.cells) {
      empty += c.detectors[d].empty_frames;
      fps += c.detectors[d].false_positives;
    }
    if (empty > 0) {
      std::snprintf(b, sizeof b, "false positives: %d on %d frames without a marker (%.3f per frame)\n", fps, empty,
                    double(fps) / empty);
      s += b;
    }
    s += "\n";
  }
  return s;
}

std::string lab_table_csv(const LabResults& r) {
  std::string s =
      "detector,size_mm,distance_m,lux,side_px,frames,detected,p_rec,ci_low,ci_high,wrong_id_rate,empty_frames,"
      "false_positives,tilt_deg,added_blur_px,added_noise,occlusion,median_ms\n";
  char b[400];
  for (size_t d = 0; d < r.options.detectors.size(); ++d)
    for (const CellResult& c : r.cells) {
      const DetectorTally& t = c.detectors[d];
      const auto [lo, hi] = wilson_interval(t.detected, t.frames);
      // tilt_deg is empty for a random tilt (up to the plan's max_tilt_deg).
      char tilt[32] = "";
      if (c.cell.tilt_deg >= 0) std::snprintf(tilt, sizeof tilt, "%g", c.cell.tilt_deg);
      std::snprintf(b, sizeof b, "%s,%g,%g,%g,%.1f,%d,%d,%.2f,%.2f,%.2f,%.4f,%d,%d,%s,%g,%g,%g,%.3f\n",
                    r.options.detectors[d].c_str(), c.cell.size_mm, c.cell.distance_m, c.cell.lux, c.side_px, t.frames,
                    t.detected, t.p_rec(), 100 * lo, 100 * hi, t.frames ? double(t.wrong_id) / t.frames : 0.0,
                    t.empty_frames, t.false_positives, tilt, c.cell.blur_px, c.cell.noise, c.cell.occlusion,
                    t.median_ms());
      s += b;
    }
  return s;
}

std::string lab_results_json(const LabResults& r) {
  using Json = nlohmann::ordered_json;
  const SensorModel& m = r.options.sensor;
  Json j;
  j["plan"] = {{"name", r.plan.name},
               {"dictionary", r.plan.dictionary},
               {"markers", r.plan.markers},
               {"sizes_mm", r.plan.sizes_mm},
               {"distances_m", r.plan.distances_m},
               {"lux", r.plan.lux},
               {"max_tilt_deg", r.plan.max_tilt_deg},
               {"sides_px", r.plan.sides_px},
               {"tilts_deg", r.plan.tilts_deg},
               {"blurs_px", r.plan.blurs_px},
               {"noises", r.plan.noises},
               {"occlusions", r.plan.occlusions},
               {"frames_per_cell", r.plan.frames_per_cell},
               {"empty_frames_per_cell", r.plan.empty_frames_per_cell()}};
  j["seed"] = r.options.seed;
  j["ids"] = r.ids;
  j["camera"] = {{"name", r.options.camera_name},
                 {"width", r.options.camera.size.width},
                 {"height", r.options.camera.size.height},
                 {"fx", r.options.camera.camera_matrix(0, 0)},
                 {"distortion", r.options.camera.distortion}};
  j["sensor"] = {{"sensitivity_e_per_lux_s", m.sensitivity}, {"full_well_e", m.full_well},
                 {"read_noise_e", m.read_noise},          {"target_level", m.target_level},
                 {"max_exposure_s", m.max_exposure_s},    {"max_gain", m.max_gain},
                 {"focal_length_mm", m.focal_length_mm},  {"f_number", m.f_number},
                 {"focus_m", m.focus_m},                  {"shake_deg_s", m.shake_deg_s}};
  const SceneLight& l = r.options.light;
  j["light"] = {{"direct_outdoor", l.direct_outdoor},   {"direct_indoor", l.direct_indoor},
                {"direct_evening", l.direct_evening},   {"shadow_chance_half_metre", l.shadow_chance_half_metre},
                {"sun_diameter_rad", l.sun_diameter_rad}, {"glare_chance", l.glare_chance},
                {"glare_lobe_deg", l.glare_lobe_deg},   {"glare_peak", l.glare_peak}};
  j["detectors"] = r.options.detectors;
  // Each detector's "marks": a character per frame of the cell (frames with a marker, then those without): D
  // detected, M missed, W another id only, . not counted (the marker not wholly in view), c nothing reported on a
  // frame without a marker, F a false positive there.
  Json cells = Json::array();
  for (const CellResult& c : r.cells) {
    Json per = Json::object();
    for (size_t d = 0; d < r.options.detectors.size(); ++d) {
      const DetectorTally& t = c.detectors[d];
      const auto [lo, hi] = wilson_interval(t.detected, t.frames);
      per[r.options.detectors[d]] = {{"frames", t.frames},
                                     {"detected", t.detected},
                                     {"p_rec", round_decimals(t.p_rec(), 2)},
                                     {"ci95", {round_decimals(100 * lo, 2), round_decimals(100 * hi, 2)}},
                                     {"wrong_id", t.wrong_id},
                                     {"empty_frames", t.empty_frames},
                                     {"false_positives", t.false_positives},
                                     {"median_ms", round_decimals(t.median_ms(), 3)},
                                     {"marks", t.marks}};
    }
    Json tilts = Json::array();
    for (float t : c.tilts_deg) tilts.push_back(round_decimals(t, 1));
    cells.push_back({{"size_mm", round_decimals(c.cell.size_mm, 3)},
                     {"distance_m", c.cell.distance_m},
                     {"lux", c.cell.lux},
                     {"side_px", round_decimals(c.side_px, 1)},
                     // The added axes: tilt_deg null for a random tilt; blur_px below is the cell's whole blur.
                     {"tilt_deg", c.cell.tilt_deg >= 0 ? Json(c.cell.tilt_deg) : Json(nullptr)},
                     {"added_blur_px", c.cell.blur_px},
                     {"added_noise", c.cell.noise},
                     {"occlusion", c.cell.occlusion},
                     {"exposure_ms", round_decimals(c.exposure_ms, 2)},
                     {"gain", round_decimals(c.gain, 2)},
                     {"snr_ink", round_decimals(c.snr_black_white, 1)},
                     {"blur_px", round_decimals(c.blur_px, 2)},
                     // Each frame with a marker's tilt (the angle of its normal from the optical axis), -1 where
                     // the marker could not be placed.
                     {"tilts_deg", tilts},
                     {"results", per}});
  }
  j["cells"] = cells;
  j["seconds"] = round_decimals(r.seconds, 1);
  return j.dump(2) + "\n";
}

}  // namespace arwb::lab
