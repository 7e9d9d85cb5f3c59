// arwb bench --video (bench_video.hpp says what is measured).
#include "cli/bench_video.hpp"

#include "base/decimals.hpp"
#include "cli/bench_score.hpp"
#include "cli/cli_common.hpp"
#include "detect/detector.hpp"
#include "peers/peers.hpp"
#include "detect/video_search.hpp"
#include "synth/synth.hpp"
#include "synth/synthetic_world.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <set>

namespace arwb {
namespace {

constexpr double kPaperFps = 20;            // the paper's acquisition rate
constexpr int kAppearAfter = 20;       // the covered marker comes into view this many frames (and up to 4 more) in
const cv::Size kSizes[] = {{640, 480}, {1280, 720}, {1920, 1080}, {3840, 2160}};

struct Seq {
  cv::Size size;
  int appear = 0;    // the frame the covered marker comes into view
};

// A detector over one sequence: `start` before its first frame, then `run` per frame.
struct Contender {
  std::string name;
  std::function<void()> start;
  std::function<PeerResult(const cv::Mat&, bool repeat)> run;   // repeat: the same frame again, for timing
};

struct Figures {
  Tally tally;
  std::vector<double> delays;   // per sequence: frames from coming into view to found (-1: never)
};

std::string res_name(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

// The marker that comes into view: lying in the frame's top-left corner, away from the moving group, shown from
// frame `appear` on (a card taken off it). Drawn after the world's optics: sharp, at a print's contrast.
struct Newcomer {
  int id = -1;
  Quad corners{};
};

Newcomer newcomer_for(const Dictionary& dict, const SyntheticFrame& at, cv::Size size) {
  Newcomer n;
  double side = 0;
  for (const TruthMarker& m : at.markers) side += quad_perimeter(m.corners) / 4;
  side = at.markers.empty() ? 0.1 * size.height : 0.7 * side / double(at.markers.size());
  for (int id = 200; id < dict.size() && n.id < 0; ++id) {
    bool used = false;
    for (const TruthMarker& m : at.markers) used = used || m.id == id;
    if (!used && unambiguous(dict, id)) n.id = id;
  }
  const cv::Point2f c(float(0.09 * size.width + side / 2), float(0.12 * size.height + side / 2));
  const float h = float(side / 2);
  n.corners = Quad{cv::Point2f(c.x - h, c.y - h), {c.x + h, c.y - h}, {c.x + h, c.y + h}, {c.x - h, c.y + h}};
  return n;
}

SyntheticFrame frame_of(const SyntheticWorld& world, const Dictionary& dict, int k, const Newcomer& n, bool shown) {
  SyntheticFrame f = world.render(k / kPaperFps);
  if (shown && n.id >= 0) {
    draw_marker(f.image, dict, n.id, n.corners, 1.0, 4, 30, 215);
    f.markers.push_back({n.id, dict.name(), n.corners});
  }
  return f;
}

using Clock = std::chrono::steady_clock;
// resolution -> detector -> figures; "all" sums the resolutions.
using ByResolution = std::map<std::string, std::map<std::string, Figures>>;

// What the sequences gave, for the report.
struct VideoFigures {
  std::map<std::string, ByResolution> by_dict;
  std::vector<std::string> names;   // the detectors, in the order they first ran
  int total_frames = 0;
};

// The detectors on one dictionary's sequences: arwb searching each frame whole, arwb in video mode, the peers.
// The functions refer to `det`, which outlives them.
std::vector<Contender> contenders_for(const Dictionary& dict, const Detector& det,
                                      const std::vector<std::string>& peers) {
  auto video = std::make_shared<VideoSearch>();
  std::vector<Contender> contenders;
  auto timed = [](auto&& f) {
    PeerResult r;
    const auto t0 = Clock::now();
    r.markers = f();
    r.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    return r;
  };
  contenders.push_back(
      {"arwb", [] {}, [&det, timed](const cv::Mat& img, bool) { return timed([&] { return det.detect(img); }); }});
  // Video mode: a rerun of the same frame (for timing) starts from the state before it.
  auto before = std::make_shared<VideoSearch>();
  contenders.push_back({"arwb-video", [video] { video->reset(); },
                        [&det, video, before, timed](const cv::Mat& img, bool repeat) {
                          if (repeat) *video = *before;
                          else *before = *video;
                          return timed([&] { return video->detect(det, img); });
                        }});
  for (const std::string& peer : peers) {
    if (peer == "apriltag") {
      if (!AprilTagPeer::supports(dict.name())) continue;
      auto p = std::make_shared<AprilTagPeer>(dict.name());
      contenders.push_back({peer, [] {}, [p](const cv::Mat& img, bool) { return p->detect(img); }});
    } else {
      auto p = std::make_shared<OpenCvArucoPeer>(dict.name(), peer == "aruco3");
      contenders.push_back({peer, [] {}, [p](const cv::Mat& img, bool) { return p->detect(img); }});
    }
  }
  return contenders;
}

// One sequence's frames: the world's moving group, and the newcomer shown from frame seq.appear on.
struct Sequence {
  Seq seq;
  Newcomer newcomer;
  std::vector<SyntheticFrame> frames;
  std::set<int> world_ids;   // the group's markers: not in a frame's truth when cut by its edge or overlapped
};

Sequence make_sequence(const Dictionary& dict, const VideoBenchOptions& o, size_t si, int q) {
  const cv::Size size = kSizes[si];
  SyntheticWorld world(size, 600.0 * size.width / 640, o.seed * 7919u + unsigned(si * 31 + size_t(q)));
  SyntheticControls ctl = world.controls();
  ctl.dict = dict.name();
  ctl.markers = 4;
  ctl.distance_m = 0.6 + 0.5 * q;
  world.set_controls(ctl);
  Sequence s;
  s.seq = Seq{size, kAppearAfter + int((si * 3 + size_t(q)) % 5)};
  s.newcomer = newcomer_for(dict, world.render(s.seq.appear / kPaperFps), size);
  for (int k = 0; k < o.frames; ++k) {
    s.frames.push_back(frame_of(world, dict, k, s.newcomer, k >= s.seq.appear));
    for (const TruthMarker& m : s.frames.back().markers)
      if (m.id != s.newcomer.id) s.world_ids.insert(m.id);
  }
  return s;
}

// One detector over one sequence, the fastest of `reps` runs per frame, tallied under the sequence's resolution
// and "all", with the frames it took to find the newcomer.
void run_sequence(const Contender& c, const Sequence& s, int reps, ByResolution& figs) {
  const int hidden = s.newcomer.id;
  const std::string res = res_name(s.seq.size);
  c.start();
  int delay = -1;
  for (int k = 0; k < int(s.frames.size()); ++k) {
    PeerResult first;
    double best = 1e18;
    for (int r = 0; r < reps; ++r) {
      PeerResult pr = c.run(s.frames[size_t(k)].image, r > 0);
      best = std::min(best, pr.ms);
      if (r == 0) first = std::move(pr);
    }
    if (delay < 0 && hidden >= 0 && k >= s.seq.appear)
      for (const Marker& m : first.markers)
        if (m.id == hidden) delay = k - s.seq.appear;
    // A group marker found while the world leaves it out of the truth (partly out of view, or its quiet zone
    // overlapped by a nearer one) is neither found nor a false positive.
    const std::vector<TruthMarker>& truth = s.frames[size_t(k)].markers;
    std::vector<Marker> counted;
    for (const Marker& m : first.markers) {
      const bool in_truth =
          std::any_of(truth.begin(), truth.end(), [&](const TruthMarker& t) { return t.id == m.id; });
      if (in_truth || !s.world_ids.count(m.id)) counted.push_back(m);
    }
    for (const std::string& at : {std::string("all"), res}) {
      Tally& t = figs[at][c.name].tally;
      t.ms.push_back(best);
      score(counted, truth, t);
    }
  }
  if (hidden >= 0 && s.seq.appear < int(s.frames.size()))
    for (const std::string& at : {std::string("all"), res}) figs[at][c.name].delays.push_back(delay);
}

// "mean / worst" frames until the newcomer was found, and how many sequences never found it; the mean and the
// worst also as numbers (-1 when it was never found).
std::string delay_text(const std::vector<double>& d, double* mean_out, double* max_out) {
  double sum = 0, worst = 0;
  int never = 0;
  for (double v : d) {
    if (v < 0) ++never;
    else sum += v, worst = std::max(worst, v);
  }
  const int found = int(d.size()) - never;
  *mean_out = found ? sum / found : -1;
  *max_out = found ? worst : -1;
  char buf[64];
  if (d.empty()) return std::string("-");
  std::snprintf(buf, sizeof buf, "%.1f / %.0f%s", found ? sum / found : 0.0, worst,
                never ? (" (" + std::to_string(never) + " never)").c_str() : "");
  return std::string(buf);
}

// Every row in print order: fn(dictionary, resolution, detector, its figures, every detector's at that place).
template <class Fn>
void each_row(const VideoFigures& v, const std::string& only_dict, Fn&& fn) {
  std::vector<std::string> resolutions;
  for (const cv::Size s : kSizes) resolutions.push_back(res_name(s));
  resolutions.push_back("all");
  for (const auto& [dict, by_res] : v.by_dict) {
    if (!only_dict.empty() && dict != only_dict) continue;
    for (const std::string& res : resolutions) {
      const auto it = by_res.find(res);
      if (it == by_res.end()) continue;
      for (const std::string& name : v.names)
        if (const auto f = it->second.find(name); f != it->second.end()) fn(dict, res, name, f->second, it->second);
    }
  }
}

void print_json(const VideoBenchOptions& o, const VideoFigures& v) {
  using Json = nlohmann::ordered_json;
  Json out = {{"threads", 1}, {"reps", o.reps}, {"fps", kPaperFps}, {"frames_per_sequence", o.frames},
              {"sequences_per_resolution", o.sequences}, {"full_search_interval", o.params.full_search_interval},
              {"rows", Json::array()}};
  each_row(v, "", [&](const std::string& dict, const std::string& res, const std::string& name, const Figures& f,
                      const std::map<std::string, Figures>& here) {
    const Tally& t = f.tally;
    double dm = 0, dx = 0;
    delay_text(f.delays, &dm, &dx);
    Json row = {{"dictionary", dict}, {"resolution", res}, {"detector", name}, {"frames", t.ms.size()},
                {"median_ms", round_decimals(median(t.ms), 3)}, {"mean_ms", round_decimals(mean(t.ms), 3)},
                {"markers", t.truth}, {"found", t.found},
                {"recall", round_decimals(t.truth ? double(t.found) / t.truth : 1.0, 4)},
                {"false_positives", t.false_pos},
                {"corner_error_px", t.corner_n ? Json(round_decimals(t.corner_err / t.corner_n, 4)) : Json()},
                {"new_marker_sequences", f.delays.size()},
                {"new_marker_never_found", std::count(f.delays.begin(), f.delays.end(), -1.0)},
                {"new_marker_frames_mean", dm < 0 ? Json() : Json(round_decimals(dm, 2))},
                {"new_marker_frames_max", dx < 0 ? Json() : Json(dx)}};
    if (name == "arwb-video")
      for (const auto& [other, of] : here)
        if (other != name) {
          row["median_ratio_" + other] = round_decimals(median(t.ms) / median(of.tally.ms), 3);
          row["mean_ratio_" + other] = round_decimals(mean(t.ms) / mean(of.tally.ms), 3);
        }
    out["rows"].push_back(std::move(row));
  });
  std::printf("%s\n", json_text(out).c_str());
}

void print_table(const VideoBenchOptions& o, const VideoFigures& v) {
  std::printf("Video: %d frames in %d sequences per resolution and dictionary at %g fps (%d frames in all), one "
              "thread, fastest of %d run%s per frame;\n"
              "arwb-video searches around the last frame's markers, whole every %d frames (full_search_interval)\n",
              o.frames, o.sequences, kPaperFps, v.total_frames, o.reps, o.reps == 1 ? "" : "s",
              o.params.full_search_interval);
  for (const auto& entry : v.by_dict) {
    const std::string& dict = entry.first;
    std::printf("\n%s\n%-10s %-11s %9s %8s %8s %6s %9s %22s %s\n", dict.c_str(), "resolution", "detector",
                "median_ms", "mean_ms", "recall", "FP", "corner_px", "new marker after", "arwb-video's time");
    each_row(v, dict, [&](const std::string&, const std::string& res, const std::string& name, const Figures& f,
                          const std::map<std::string, Figures>& here) {
      const Tally& t = f.tally;
      double dm = 0, dx = 0;
      std::string ratio;
      if (name == "arwb-video")
        for (const std::string& other : v.names)
          if (const auto of = here.find(other); other != name && of != here.end()) {
            char buf[96];
            std::snprintf(buf, sizeof buf, "%s%.2fx %s", ratio.empty() ? "" : ", ",
                          median(t.ms) / median(of->second.tally.ms), other.c_str());
            ratio += buf;
          }
      std::printf("%-10s %-11s %9.2f %8.2f %7.1f%% %6d %9s %22s %s\n", res.c_str(), name.c_str(), median(t.ms),
                  mean(t.ms), t.truth ? 100.0 * t.found / t.truth : 100.0, t.false_pos,
                  t.corner_n ? decimals_text(t.corner_err / t.corner_n, 3).c_str() : "-",
                  delay_text(f.delays, &dm, &dx).c_str(), ratio.c_str());
    });
  }
  std::printf("\n(new marker after: frames from a marker coming into view until found, mean / worst over the "
              "sequences; median ratios)\n");
}

}  // namespace

int bench_video(const VideoBenchOptions& o) {
  cv::setNumThreads(1);
  VideoFigures v;
  for (const Dictionary& dict : o.dicts) {
    const Detector det({dict}, o.params);
    const std::vector<Contender> contenders = contenders_for(dict, det, o.peers);
    for (const Contender& c : contenders)
      if (std::find(v.names.begin(), v.names.end(), c.name) == v.names.end()) v.names.push_back(c.name);
    for (size_t si = 0; si < std::size(kSizes); ++si)
      for (int q = 0; q < o.sequences; ++q) {
        const Sequence s = make_sequence(dict, o, si, q);
        v.total_frames += int(s.frames.size());
        for (const Contender& c : contenders) run_sequence(c, s, o.reps, v.by_dict[dict.name()]);
      }
  }
  if (o.json) print_json(o, v);
  else print_table(o, v);
  return 0;
}

}  // namespace arwb
