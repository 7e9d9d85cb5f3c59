// arwb bench --tracking: jitter of a still marker and lag of a moving one, filtered against raw
// (bench_tracking.hpp says what is measured).
#include "cli/bench_tracking.hpp"

#include "base/decimals.hpp"
#include "cli/cli_common.hpp"
#include "detect/detector.hpp"
#include "detect/dictionary.hpp"
#include "pose/marker_pose.hpp"
#include "synth/marker_view.hpp"
#include "track/tracker.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>

#include <cmath>
#include <cstdio>
#include <optional>

namespace arwb {
namespace {

constexpr double kFps = 30;
constexpr int kWarmup = 10;   // frames before measuring: the filter starts from the first detection

SmoothingSettings smoothing_of(const DetectorParams& p) {
  return {p.tracking_smoothing != 0, p.tracking_min_cutoff_hz, p.tracking_beta, p.tracking_d_cutoff_hz};
}

struct Sums {
  double sq_px = 0, sq_deg = 0, lag = 0, err = 0;
  long corners = 0, moves = 0, rotations = 0;   // corners measured, corner moves and rotation changes summed
};

}  // namespace

TrackingBench run_tracking_bench(const TrackingBenchOptions& o) {
  TrackingBench out;
  const SynthCamera cam;
  SynthMarker sm;
  sm.id = 0;
  const MarkerRenderer renderer(cam, sm);
  Calibration calib;
  calib.camera_matrix = cam.camera_matrix;
  calib.distortion = cam.distortion;
  calib.image_size = cam.size;
  auto dict = dictionary_by_name(sm.dictionary);
  if (!dict) {
    out.error = "no dictionary " + sm.dictionary;
    return out;
  }
  const Detector detector({*dict}, o.params);
  TrackerSettings ts;
  ts.smoothing = smoothing_of(o.params);
  ts.smoothing.on = true;   // filtered is what the table's values give; raw is the detections
  const double z = 0.35;    // metres: the 50 mm marker about 80 px wide

  // One sequence: the pose of frame k, and what is measured on it.
  auto run = [&](auto pose_at, bool moving, Sums& raw, Sums& filt, int& measured) {
    Tracker tracker(ts);
    tracker.set_camera(calib, 1.0);
    std::optional<MarkerPose> raw_pose;
    std::optional<Quad> prev_raw, prev_filt, prev_truth;
    std::optional<cv::Vec3d> prev_raw_r, prev_filt_r;
    for (int k = 0; k < o.frames; ++k) {
      const auto [rvec, tvec] = pose_at(k);
      const MarkerView v = renderer.render(rvec, tvec, 0.6, o.noise, o.seed * 7919u + unsigned(k));
      std::vector<Marker> found;
      for (const Marker& m : detector.detect(v.image))
        if (m.id == sm.id) found.push_back(m);
      tracker.update(found, k / kFps);
      const TrackedMarker* t = tracker.tracks().empty() ? nullptr : &tracker.tracks()[0];
      if (!t || !t->detected) {
        prev_raw.reset(), prev_filt.reset(), prev_truth.reset(), prev_raw_r.reset(), prev_filt_r.reset();
        continue;
      }
      std::optional<MarkerPose> rp = estimate_marker_pose(t->raw_corners, 1.0, calib);
      if (rp && raw_pose) rp = resolve_with_previous(*rp, raw_pose->pose.rvec);
      raw_pose = rp;
      if (k >= kWarmup) {
        ++measured;
        // The truth's corner each detected corner is: the cyclic shift that fits (a marker's corner 0 is its
        // dictionary's, which a symmetric-looking code may put elsewhere than the renderer's).
        size_t shift = 0;
        double best = 1e300;
        for (size_t r = 0; r < 4; ++r) {
          double d = 0;
          for (size_t c = 0; c < 4; ++c)
            d += cv::norm(cv::Point2d(t->raw_corners[c]) - cv::Point2d(v.corners[(c + r) % 4]));
          if (d < best) best = d, shift = r;
        }
        auto measure = [&](const Quad& q, const std::optional<Quad>& prev, Sums& s) {
          for (size_t c = 0; c < 4; ++c) {
            const cv::Point2d e = cv::Point2d(q[c]) - cv::Point2d(v.corners[(c + shift) % 4]);
            s.err += cv::norm(e);
            if (moving && prev_truth) {
              const size_t tc = (c + shift) % 4;
              cv::Point2d d = cv::Point2d(v.corners[tc]) - cv::Point2d((*prev_truth)[tc]);
              d *= 1.0 / std::max(cv::norm(d), 1e-9);
              s.lag += -e.dot(d);   // behind the truth along the motion: positive
            }
            if (prev) s.sq_px += std::pow(cv::norm(cv::Point2d(q[c]) - cv::Point2d((*prev)[c])), 2), ++s.moves;
            ++s.corners;
          }
        };
        measure(t->raw_corners, prev_raw, raw);
        measure(t->corners, prev_filt, filt);
        if (rp && prev_raw_r) raw.sq_deg += std::pow(rotation_difference_deg(rp->pose.rvec, *prev_raw_r), 2);
        if (t->pose && prev_filt_r)
          filt.sq_deg += std::pow(rotation_difference_deg(t->pose->pose.rvec, *prev_filt_r), 2);
        if (rp && prev_raw_r && t->pose && prev_filt_r) ++raw.rotations, ++filt.rotations;
      }
      prev_raw = t->raw_corners;
      prev_filt = t->corners;
      prev_truth = v.corners;
      prev_raw_r = rp ? std::optional<cv::Vec3d>(rp->pose.rvec) : std::nullopt;
      prev_filt_r = t->pose ? std::optional<cv::Vec3d>(t->pose->pose.rvec) : std::nullopt;
    }
  };

  // Still: facing the camera (the marker frame's z towards it: half a turn about x) tilted about 25 degrees,
  // a little off the axis.
  cv::Matx33d tilt, flip;
  cv::Rodrigues(cv::Vec3d(0.35, 0.25, 0.1), tilt);
  cv::Rodrigues(cv::Vec3d(CV_PI, 0, 0), flip);
  cv::Vec3d still_r;
  cv::Rodrigues(flip * tilt, still_r);
  const cv::Vec3d still_t(0.01, -0.005, z);
  Sums rs, fs;
  run([&](int) { return std::pair(still_r, still_t); }, false, rs, fs, out.still_frames);
  // Moving: across the image at a steady speed (metres per second for the asked pixels per second at z).
  const double v_m = o.speed_px_s * z / cam.camera_matrix(0, 0);
  const double x0 = -v_m * (o.frames - 1) / kFps / 2;
  Sums rm, fm;
  run([&](int k) { return std::pair(still_r, cv::Vec3d(x0 + v_m * k / kFps, -0.005, z)); }, true, rm, fm,
      out.moving_frames);
  if (out.still_frames < 2 || out.moving_frames < 2) {
    out.error = "the marker was detected on too few frames (" + std::to_string(out.still_frames) + " still, " +
                std::to_string(out.moving_frames) + " moving)";
    return out;
  }
  auto fill = [](const Sums& s, const Sums& m, TrackingFigures& f) {
    auto at_least_1 = [](long n) { return static_cast<double>(std::max(1L, n)); };
    f.jitter_px = std::sqrt(s.sq_px / at_least_1(s.moves));
    f.jitter_deg = std::sqrt(s.sq_deg / at_least_1(s.rotations));
    f.lag_px = m.lag / at_least_1(m.moves);
    f.error_px = m.err / at_least_1(m.corners);
  };
  fill(rs, rm, out.raw);
  fill(fs, fm, out.filtered);
  // The truth's own speed: the projection of v_m at z, distortion aside, near the centre.
  out.speed_px_s = v_m * cam.camera_matrix(0, 0) / z;
  return out;
}

int bench_tracking(const TrackingBenchOptions& o, bool as_json) {
  const TrackingBench b = run_tracking_bench(o);
  if (!b.error.empty()) {
    print_problem("arwb bench --tracking: %s\n", b.error.c_str());
    return 1;
  }
  const DetectorParams& p = o.params;
  if (as_json) {
    using Json = nlohmann::ordered_json;
    auto figs = [](const TrackingFigures& f) {
      return Json{{"jitter_px", round_decimals(f.jitter_px, 4)}, {"jitter_deg", round_decimals(f.jitter_deg, 4)},
                  {"lag_px", round_decimals(f.lag_px, 4)}, {"error_px", round_decimals(f.error_px, 4)}};
    };
    const Json j = {{"frames", o.frames},
                    {"fps", kFps},
                    {"noise", o.noise},
                    {"speed_px_s", round_decimals(b.speed_px_s, 1)},
                    {"min_cutoff_hz", p.tracking_min_cutoff_hz},
                    {"beta", p.tracking_beta},
                    {"d_cutoff_hz", p.tracking_d_cutoff_hz},
                    {"raw", figs(b.raw)},
                    {"filtered", figs(b.filtered)}};
    std::printf("%s\n", json_text(j).c_str());
    return 0;
  }
  std::printf("Tracking: a 50 mm marker about 80 px wide at %g fps, %d frames per sequence (the first %d not "
              "measured), sensor noise %g grey levels\n",
              kFps, o.frames, kWarmup, o.noise);
  std::printf("One Euro filter: tracking_min_cutoff_hz %g, tracking_beta %g, tracking_d_cutoff_hz %g\n",
              p.tracking_min_cutoff_hz, p.tracking_beta, p.tracking_d_cutoff_hz);
  std::printf("%-10s %16s %17s %22s %20s\n", "", "still jitter px", "still jitter deg", "moving lag px",
              "moving error px");
  for (const auto& [name, f] : {std::pair("raw", b.raw), std::pair("filtered", b.filtered)})
    std::printf("%-10s %16.3f %17.3f %22.3f %20.3f\n", name, f.jitter_px, f.jitter_deg, f.lag_px, f.error_px);
  std::printf("(jitter: RMS frame-to-frame motion; lag: mean corner offset behind the truth along the motion, at "
              "%.0f px/s)\n", b.speed_px_s);
  return 0;
}

}  // namespace arwb
