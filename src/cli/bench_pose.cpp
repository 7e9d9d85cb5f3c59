#include "cli/bench_pose.hpp"

#include "base/decimals.hpp"
#include "detect/detector.hpp"
#include "peers/peers.hpp"
#include "pose/marker_pose.hpp"
#include "synth/marker_view.hpp"
#include "track/tracker.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace arwb {
namespace {

// The setting: a 50 mm marker at 0.25 to 1.5 m through a 640x480 webcam's barrel lens, a little blur and
// noise. Tilts up to 60 degrees, as the pose tests use.
constexpr double kSide = 0.05, kNear = 0.25, kFar = 1.5, kMaxTilt = 60, kBlur = 0.6, kNoise = 2;
constexpr double kFlipDeg = 10;      // a pose this far off in rotation is the wrong one, not a noisy one
constexpr double kAmbiguous = 0.3;   // resolve_with_previous's default: the corners leave the choice open
// The sequences: a marker held nearly facing the camera (tilted up to 20 degrees) at 0.8 to 1.5 m, where the two
// solutions of a frame are hardest to tell apart and tracking has something to do; several, for a steadier count.
constexpr int kSequences = 3, kSequenceKeys = 5;
constexpr double kSeqNear = 0.8, kSeqTilt = 20;
// Ids spread over ARUCO_ORIGINAL's 1024; a renderer each, as one renderer draws one id.
constexpr std::array<int, 6> kIds{3, 128, 301, 512, 777, 1021};

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const size_t k = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  return v[k];
}

struct Truth {
  int id = 0;
  Quad corners{};
  cv::Vec3d rvec, tvec;
};

// One detector's pose of the frame's marker: nullopt when it did not find the marker's id.
struct Estimate {
  PoseSolution pose;
  std::optional<MarkerPose> both;   // arwb's: both solutions and the ambiguity
};
using EstimateFn = std::function<std::optional<Estimate>(const cv::Mat&, const Truth&)>;

// The detection of the marker's id nearest its true place (one marker per frame; a second of the same id would
// be a false one).
const Marker* right_marker(const std::vector<Marker>& found, const Truth& truth) {
  const Marker* best = nullptr;
  double best_d = 1e18;
  for (const Marker& m : found) {
    if (m.id != truth.id) continue;
    const cv::Point2f d = quad_centre(m.corners) - quad_centre(truth.corners);
    if (d.dot(d) < best_d) best = &m, best_d = d.dot(d);
  }
  return best;
}

// OpenCV's way, as its tutorials and users do it: solvePnP with IPPE_SQUARE on the detected corners.
std::optional<PoseSolution> opencv_pose(const Quad& corners, const Calibration& camera) {
  const auto o = marker_object_points(kSide);
  const std::vector<cv::Point3d> obj(o.begin(), o.end());
  const std::vector<cv::Point2d> img(corners.begin(), corners.end());
  cv::Mat rvec, tvec;
  if (!cv::solvePnP(obj, img, cv::Mat(camera.camera_matrix), camera.distortion, rvec, tvec, false,
                    cv::SOLVEPNP_IPPE_SQUARE))
    return std::nullopt;
  PoseSolution p;
  p.rvec = cv::Vec3d(rvec.ptr<double>());
  p.tvec = cv::Vec3d(tvec.ptr<double>());
  return p;
}

double translation_pct(const PoseSolution& p, const Truth& t) {
  return 100 * cv::norm(p.tvec - t.tvec) / cv::norm(t.tvec);
}

struct PoseTally {
  std::string detector;
  int frames = 0, detected = 0, flips = 0;
  std::vector<double> rot_deg, trans_pct, common_rot_deg;
  // arwb only: poses whose corners left the choice open, and of the flips, those flagged so and those whose
  // alternative solution was the right one.
  int ambiguous = 0, flips_ambiguous = 0, flips_alternative_right = 0;
};

struct SequenceTally {
  int frames = 0, detected = 0, ambiguous = 0, flips_alone = 0, flips_tracked = 0, chosen_by_previous = 0;
  int flips_filtered = 0;                                       // through the Tracker
  std::vector<double> rot_alone, rot_resolved, rot_filtered;   // rotation errors, degrees
};

// Rotation from a to b by the fraction u along the shortest way; translation along the straight line.
std::pair<cv::Vec3d, cv::Vec3d> interpolate(const std::pair<cv::Vec3d, cv::Vec3d>& a,
                                            const std::pair<cv::Vec3d, cv::Vec3d>& b, double u) {
  cv::Matx33d Ra, Rb, Rd;
  cv::Rodrigues(a.first, Ra);
  cv::Rodrigues(b.first, Rb);
  cv::Vec3d d;
  cv::Rodrigues(cv::Matx33d(Ra.t() * Rb), d);
  cv::Rodrigues(d * u, Rd);
  cv::Vec3d r;
  cv::Rodrigues(cv::Matx33d(Ra * Rd), r);
  return {r, a.second * (1 - u) + b.second * u};
}

// The single frames' outcome: a tally per detector, and the frames every detector found.
struct FrameResults {
  std::vector<PoseTally> tallies;
  int frames = 0, common = 0;
};

// The bench's camera, markers and detectors, and its two runs.
class PoseBench {
 public:
  explicit PoseBench(unsigned seed) : seed_(seed) {
    calib_.camera_matrix = camera_.camera_matrix;
    calib_.distortion = camera_.distortion;
    calib_.image_size = camera_.size;
    calib_.source = "the synthetic camera";
    for (int id : kIds) renderers_.emplace_back(camera_, SynthMarker{"ARUCO_ORIGINAL", id, kSide, 1.5});
  }

  // Single frames: each detector on the same renders.
  FrameResults single_frames(int frames) const {
    auto arwb_estimate = [&](const cv::Mat& img, const Truth& t) -> std::optional<Estimate> {
      const auto m = arwb_find(img, t);
      return m ? arwb_estimate_from(*m) : std::nullopt;
    };
    auto peer_estimate = [&](const OpenCvArucoPeer& peer) {
      return [&](const cv::Mat& img, const Truth& t) -> std::optional<Estimate> {
        const auto found = peer.detect(img);   // kept: right_marker points into its markers
        const Marker* m = right_marker(found.markers, t);
        if (!m) return std::nullopt;
        const auto p = opencv_pose(m->corners, calib_);
        if (!p) return std::nullopt;
        return Estimate{*p, std::nullopt};
      };
    };
    const std::vector<std::pair<std::string, EstimateFn>> detectors{
        {"arwb", arwb_estimate}, {"opencv", peer_estimate(ocv_)}, {"opencv_aruco3", peer_estimate(ocv3_)}};

    FrameResults out;
    for (const auto& [name, _] : detectors) {
      out.tallies.emplace_back();
      out.tallies.back().detector = name;
    }
    const auto poses = marker_poses(camera_, kSide, frames, kNear, kFar, kMaxTilt, seed_);
    out.frames = int(poses.size());
    for (int i = 0; i < int(poses.size()); ++i) {
      const auto [img, truth] = render(i, poses[size_t(i)], seed_ * 7919u + unsigned(i));
      std::vector<std::optional<Estimate>> est;
      for (size_t d = 0; d < detectors.size(); ++d) {
        est.push_back(detectors[d].second(img, truth));
        tally(est.back(), truth, out.tallies[d]);
      }
      if (std::all_of(est.begin(), est.end(), [](const auto& e) { return e.has_value(); })) {
        ++out.common;
        for (size_t d = 0; d < detectors.size(); ++d)
          out.tallies[d].common_rot_deg.push_back(rotation_difference_deg(est[d]->pose.rvec, truth.rvec));
      }
    }
    return out;
  }

  // The sequence: one marker along a smooth path through a few poses, 20 frames a second; arwb choosing each
  // frame alone, choosing by the previous frame's pose (resolve_with_previous) where the corners leave it open,
  // and the workbench's Tracker (One Euro-filtered corners, then the same choice by the track's previous pose).
  SequenceTally sequences(int frames) const {
    SequenceTally seq;
    for (int j = 0; j < kSequences; ++j) {
      const auto keys =
          marker_poses(camera_, kSide, kSequenceKeys, kSeqNear, kFar, kSeqTilt, seed_ + 104729u * unsigned(j + 1));
      std::optional<cv::Vec3d> previous;
      Tracker tracker;
      tracker.set_camera(calib_, kSide);
      for (int i = 0; i < frames && keys.size() >= 2; ++i) {
        const double s = double(i) * double(keys.size() - 1) / (frames - 1);
        const size_t k = std::min(keys.size() - 2, size_t(s));
        const auto [img, truth] =
            render(j, interpolate(keys[k], keys[k + 1], s - double(k)), seed_ * 31u + unsigned(j * 1000 + i));
        ++seq.frames;
        const auto m = arwb_find(img, truth);
        tracker.update(m ? std::vector<Marker>{*m} : std::vector<Marker>{}, i / 20.0);
        const auto e = m ? arwb_estimate_from(*m) : std::nullopt;
        if (!e) continue;   // the previous pose is kept: a frame lost is not a reason to forget
        ++seq.detected;
        seq.ambiguous += e->both->ambiguity >= kAmbiguous;
        const MarkerPose tracked = previous ? resolve_with_previous(*e->both, *previous, kAmbiguous) : *e->both;
        seq.chosen_by_previous += tracked.chosen_by_previous;
        const double alone = rotation_difference_deg(e->pose.rvec, truth.rvec);
        const double resolved = rotation_difference_deg(tracked.pose.rvec, truth.rvec);
        seq.flips_alone += alone > kFlipDeg;
        seq.flips_tracked += resolved > kFlipDeg;
        seq.rot_alone.push_back(alone);
        seq.rot_resolved.push_back(resolved);
        previous = tracked.pose.rvec;
        for (const TrackedMarker& t : tracker.tracks())
          if (t.detected && t.pose) {
            const double filtered = rotation_difference_deg(t.pose->pose.rvec, truth.rvec);
            seq.flips_filtered += filtered > kFlipDeg;
            seq.rot_filtered.push_back(filtered);
          }
      }
    }
    return seq;
  }

 private:
  std::optional<Marker> arwb_find(const cv::Mat& img, const Truth& t) const {
    const auto found = arwb_det_.detect(img);
    const Marker* m = right_marker(found, t);
    if (!m) return std::nullopt;
    return *m;
  }

  std::optional<Estimate> arwb_estimate_from(const Marker& m) const {
    auto p = estimate_marker_pose(m.corners, kSide, calib_);
    if (!p) return std::nullopt;
    return Estimate{p->pose, p};
  }

  std::pair<cv::Mat, Truth> render(int i, const std::pair<cv::Vec3d, cv::Vec3d>& pose, unsigned noise_seed) const {
    const MarkerRenderer& r = renderers_[size_t(i) % renderers_.size()];
    const MarkerView v = r.render(pose.first, pose.second, kBlur, kNoise, noise_seed);
    return std::pair{v.image, Truth{r.marker().id, v.corners, pose.first, pose.second}};
  }

  // One detector's estimate of a frame counted against the truth.
  static void tally(const std::optional<Estimate>& est, const Truth& truth, PoseTally& t) {
    ++t.frames;
    if (!est) return;
    const Estimate& e = *est;
    ++t.detected;
    const double rot = rotation_difference_deg(e.pose.rvec, truth.rvec);
    t.rot_deg.push_back(rot);
    t.trans_pct.push_back(translation_pct(e.pose, truth));
    const bool flip = rot > kFlipDeg;
    t.flips += flip;
    if (e.both) {
      const bool ambiguous = e.both->ambiguity >= kAmbiguous;
      t.ambiguous += ambiguous;
      t.flips_ambiguous += flip && ambiguous;
      t.flips_alternative_right += flip && rotation_difference_deg(e.both->alternative.rvec, truth.rvec) <= kFlipDeg;
    }
  }

  unsigned seed_;
  const SynthCamera camera_;   // 640x480, barrel distortion
  Calibration calib_;
  std::vector<MarkerRenderer> renderers_;
  const Detector arwb_det_{{*dictionary_by_name("ARUCO_ORIGINAL")}};
  const OpenCvArucoPeer ocv_{"ARUCO_ORIGINAL"}, ocv3_{"ARUCO_ORIGINAL", true};
};

double share(int n, int of) { return of ? double(n) / of : 0.0; }

void print_json(const PoseBenchOptions& options, const FrameResults& f, const SequenceTally& seq, double seconds) {
  using Json = nlohmann::ordered_json;
  Json out = {{"frames", f.frames},
              {"seed", options.seed},
              {"marker_mm", kSide * 1000},
              {"dictionary", "ARUCO_ORIGINAL"},
              {"distance_m", {kNear, kFar}},
              {"max_tilt_deg", kMaxTilt},
              {"blur_px", kBlur},
              {"noise", kNoise},
              {"flip_deg", kFlipDeg},
              {"ambiguous_at", kAmbiguous},
              {"common_frames", f.common},
              {"detectors", Json::array()}};
  for (const PoseTally& t : f.tallies) {
    Json d = {{"detector", t.detector},
              {"frames", t.frames},
              {"detected", t.detected},
              {"median_rotation_deg", round_decimals(quantile(t.rot_deg, 0.5), 4)},
              {"p90_rotation_deg", round_decimals(quantile(t.rot_deg, 0.9), 4)},
              {"median_translation_pct", round_decimals(quantile(t.trans_pct, 0.5), 4)},
              {"flips", t.flips},
              {"flip_share", round_decimals(share(t.flips, t.detected), 4)},
              {"median_rotation_deg_common", round_decimals(quantile(t.common_rot_deg, 0.5), 4)}};
    if (t.detector == "arwb") {
      d["ambiguous"] = t.ambiguous;
      d["flips_ambiguous"] = t.flips_ambiguous;
      d["flips_alternative_right"] = t.flips_alternative_right;
    }
    out["detectors"].push_back(std::move(d));
  }
  out["sequence"] = {{"sequences", kSequences},
                     {"frames", seq.frames},
                     {"distance_m", {kSeqNear, kFar}},
                     {"max_tilt_deg", kSeqTilt},
                     {"detected", seq.detected},
                     {"ambiguous", seq.ambiguous},
                     {"flips_alone", seq.flips_alone},
                     {"flips_tracked", seq.flips_tracked},
                     {"chosen_by_previous", seq.chosen_by_previous},
                     {"flips_per_100_alone", round_decimals(100 * share(seq.flips_alone, seq.frames), 3)},
                     {"flips_per_100_tracked", round_decimals(100 * share(seq.flips_tracked, seq.frames), 3)},
                     {"flips_filtered", seq.flips_filtered},
                     {"flips_per_100_filtered", round_decimals(100 * share(seq.flips_filtered, seq.frames), 3)},
                     {"rot_median_deg_alone", round_decimals(quantile(seq.rot_alone, 0.5), 3)},
                     {"rot_median_deg_resolved", round_decimals(quantile(seq.rot_resolved, 0.5), 3)},
                     {"rot_median_deg_filtered", round_decimals(quantile(seq.rot_filtered, 0.5), 3)}};
  out["seconds"] = round_decimals(seconds, 2);
  std::printf("%s\n", json_text(out).c_str());
}

void print_table(const PoseBenchOptions& options, const FrameResults& f, const SequenceTally& seq, double seconds) {
  std::printf("\npose of a %.0f mm ARUCO_ORIGINAL marker (%d frames, seed %d: %.2f to %.2f m, tilted up to %.0f deg, "
              "640x480 barrel lens, blur %.1f px, noise %.0f; the camera known)\n",
              kSide * 1000, f.frames, options.seed, kNear, kFar, kMaxTilt, kBlur, kNoise);
  std::printf("%-14s %9s %8s %8s %9s %13s %10s\n", "detector", "found", "rot_med", "rot_p90", "trans_med",
              "flips>10deg", "rot_common");
  for (const PoseTally& t : f.tallies)
    std::printf("%-14s %4d/%-4d %8.2f %8.2f %8.2f%% %4d %7.1f%% %10.2f\n", t.detector.c_str(), t.detected, t.frames,
                quantile(t.rot_deg, 0.5), quantile(t.rot_deg, 0.9), quantile(t.trans_pct, 0.5), t.flips,
                100 * share(t.flips, t.detected), quantile(t.common_rot_deg, 0.5));
  std::printf("rotation errors in degrees, translation error in %% of the distance; rot_common: median over the %d "
              "frames all three found\n",
              f.common);
  const PoseTally& a = f.tallies[0];
  std::printf("arwb's ambiguity: %d of %d poses ambiguous (ratio >= %.1f); of its %d flips %d were flagged so, and in "
              "%d the alternative solution was the right one\n",
              a.ambiguous, a.detected, kAmbiguous, a.flips, a.flips_ambiguous, a.flips_alternative_right);
  std::printf("\nsequences: %d of %d frames, each along a smooth path through %d poses nearly facing the camera "
              "(tilted up to %.0f deg) at %.2f to %.2f m; arwb found the marker in %d frames (%d ambiguous)\n",
              kSequences, options.sequence_frames, kSequenceKeys, kSeqTilt, kSeqNear, kFar, seq.detected, seq.ambiguous);
  std::printf("flips per 100 frames: each frame alone %.1f, resolve_with_previous %.1f (it chose the other solution "
              "%d times), the Tracker (filtered corners) %.1f\n",
              100 * share(seq.flips_alone, seq.frames), 100 * share(seq.flips_tracked, seq.frames),
              seq.chosen_by_previous, 100 * share(seq.flips_filtered, seq.frames));
  std::printf("median rotation error: alone %.2f deg, resolve_with_previous %.2f deg, the Tracker %.2f deg\n",
              quantile(seq.rot_alone, 0.5), quantile(seq.rot_resolved, 0.5), quantile(seq.rot_filtered, 0.5));
  std::printf("\n%.1f s, one thread\n", seconds);
}

}  // namespace

int run_pose_bench(const PoseBenchOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  cv::setNumThreads(1);
  const PoseBench bench(unsigned(options.seed));
  const FrameResults frames = bench.single_frames(options.frames);
  const SequenceTally seq = bench.sequences(std::max(options.sequence_frames, 2));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (options.json) print_json(options, frames, seq, seconds);
  else print_table(options, frames, seq, seconds);
  return 0;
}

}  // namespace arwb
