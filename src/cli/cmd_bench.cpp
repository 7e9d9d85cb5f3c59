// arwb bench: arwb against OpenCV 4.6 aruco (default parameters, and its ArUco3 mode) and AprilTag 3 (AprilTag
// families), one thread, the same frames: median ms per frame by resolution (and by condition on the hard set),
// recall, false positives, corner error, and the ratios.
#include "cli/bench_pose.hpp"
#include "cli/bench_score.hpp"
#include "cli/bench_video.hpp"
#include "cli/bench_tracking.hpp"
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "peers/match.hpp"
#include "peers/peers.hpp"
#include "synth/synth_set.hpp"
#include "detect/detector.hpp"
#include "detect/kernels/simd.hpp"
#include "base/decimals.hpp"
#include "base/text.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <optional>

namespace arwb {
namespace {

using DetectFn = std::function<PeerResult(const cv::Mat&)>;

struct Row {
  std::string set, resolution, condition, detector;  // condition: a hard set's row for one hardship, over all sizes
  Tally tally;
  std::string group() const { return condition.empty() ? resolution : condition; }
};

// The peers arwb is compared with, in the order their columns are printed.
constexpr const char* kPeers[] = {"opencv", "aruco3", "apriltag"};

// The processor's name as Linux gives it (/proc/cpuinfo), for the figures' record; "unknown" elsewhere.
std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0)
      if (const size_t colon = line.find(':'); colon != std::string::npos) {
        const size_t from = line.find_first_not_of(" \t", colon + 1);
        return from == std::string::npos ? "unknown" : line.substr(from);
      }
  return "unknown";
}


// The sets a detection bench runs: one per dictionary and kind, or the folder's, each with the dictionaries its
// detectors search.
struct Set {
  std::string name;
  std::vector<SetItem> items;
  std::vector<Dictionary> dicts;
};

// What the command line asked for.
struct BenchArgs {
  bool as_json = false;
  std::string dir, dict_arg = "ARUCO_ORIGINAL,APRILTAG_36h11", params_path;
  int count = 90, seed = 1, reps = 3;
  std::string set_arg = "both", peers_arg = "opencv,aruco3,apriltag";
  PoseBenchOptions pose;
  bool pose_mode = false, tracking = false, video = false;
  bool has_dir = false;   // DIR was given
};

// The options, declared on `app` for `a` to receive.
void declare_options(CLI::App& app, BenchArgs& a) {
  app.add_option("DIR", a.dir, "a set with a truth.jsonl (see arwb synth)");
  app.add_option("--dict", a.dict_arg, "dictionaries, as for arwb detect (a DIR's truth names its own)")
      ->type_name("NAME[,NAME...]");
  app.add_option("--params", a.params_path, "a YAML preset of detector parameters for arwb")->type_name("FILE.yml");
  app.add_option("--count", a.count, "images per synthetic set; --pose: frames per sequence (200)")->type_name("N")->check(whole_number(1, 100000));
  app.add_option("--seed", a.seed, "the synthetic sets' seed")->type_name("S")->check(whole_number(0, 2147483647));
  app.add_option("--reps", a.reps, "runs of each detector per image; the fastest time is kept")
      ->type_name("R")
      ->check(whole_number(1, 100));
  app.add_flag("--json", a.as_json, "one JSON object instead of the table");
  app.add_option("--set", a.set_arg, "the synthetic sets to make (see arwb synth --set)")
      ->type_name("standard|hard|both")
      ->check(CLI::IsMember({"standard", "hard", "both"}));
  app.add_option("--peers", a.peers_arg,
                 "the detectors to compare arwb with, any of opencv, aruco3 and apriltag (apriltag only on AprilTag "
                 "families), or none")
      ->type_name("NAME[,NAME...]");
  app.add_flag("--pose", a.pose_mode,
               "instead: the pose of a rendered 50 mm marker of known pose by arwb and by OpenCV (detectMarkers, "
               "default and ArUco3 mode, + solvePnP IPPE_SQUARE), and sequences with and without "
               "resolve_with_previous");
  app.add_option("--frames", a.pose.frames, "--pose: frames rendered; --video: frames per sequence (60)")
      ->type_name("N")
      ->check(whole_number(1, 100000));
  app.add_flag("--tracking", a.tracking,
               "instead: the tracker's jitter on a still marker and lag on a moving one, filtered and raw "
               "(--count frames per sequence, --params for the tracking_* values)");
  app.add_flag("--video", a.video,
               "instead: synthetic video sequences at 640x480 to 3840x2160 (--count sequences per resolution and "
               "dictionary, 2 by default; --frames each), arwb searching every frame whole and in video mode "
               "(search_regions) against the peers, with the frames until a marker coming into view is found");
}

// The options that do not apply to the benchmark asked for: the exit status after saying so, or nullopt.
std::optional<int> misplaced_options(const CommandLine& cl, const BenchArgs& a) {
  // --pose renders its own frames: the detection set's options would be silently ignored.
  if (int(a.pose_mode) + int(a.tracking) + int(a.video) > 1)
    return cl.usage_error("--pose, --tracking and --video are three benchmarks: give one");
  if (a.video)
    for (const char* other : {"DIR", "--set"})
      if (cl.app.count(other)) {
        print_problem("arwb bench: --video: %s does not apply (see arwb bench --help)\n", other);
        return 2;
      }
  if (a.pose_mode)
    for (const char* other : {"DIR", "--dict", "--params", "--reps", "--set", "--peers"})
      if (cl.app.count(other)) {
        print_problem("arwb bench: --pose: %s does not apply (see arwb bench --help)\n", other);
        return 2;
      }
  if (a.pose_mode && cl.app.count("--count") && a.count < 2)
    return cl.usage_error("--count: --pose's sequences need at least 2 frames each");
  if (!a.pose_mode && !a.video && cl.app.count("--frames")) {
    print_problem("arwb bench: --frames: only with --pose or --video (see arwb bench --help)\n");
    return 2;
  }
  return std::nullopt;
}

// The folder's set, or the synthetic sets --set asks for; nullopt after saying why there is nothing to run.
std::optional<std::vector<Set>> bench_sets(const BenchArgs& a, const std::vector<Dictionary>& dicts) {
  std::vector<Set> sets;
  if (a.has_dir) {
    std::vector<std::string> skipped;
    auto items = read_set(a.dir, &skipped);
    for (const auto& e : skipped) print_problem("%s\n", e.c_str());
    if (!items) print_problem("%s\n", items.error().c_str());
    if (!items || items->empty()) {
      print_problem("arwb bench: %s: no usable images\n", a.dir.c_str());
      return std::nullopt;
    }
    // The dictionaries the truth uses (--dict for a folder without markers).
    std::vector<Dictionary> used;
    for (const auto& it : *items)
      for (const auto& m : it.truth)
        if (std::none_of(used.begin(), used.end(), [&](const Dictionary& d) { return d.name() == m.dict; }))
          if (auto d = dictionary_by_name(m.dict)) used.push_back(*d);
    if (used.empty()) used = dicts;
    sets.push_back({a.dir, std::move(*items), std::move(used)});
    return sets;
  }
  for (const SetKind kind : {SetKind::standard, SetKind::hard}) {
    if (a.set_arg != "both" && (a.set_arg == "hard") != (kind == SetKind::hard)) continue;
    for (const Dictionary& d : dicts) {
      std::vector<SetItem> items;
      const auto& sizes = kind == SetKind::hard ? hard_sizes() : mixed_sizes();
      for (int i = 0; i < a.count; ++i) items.push_back(make_set_item({d}, sizes, uint64_t(a.seed), i, kind));
      sets.push_back({std::string(kind == SetKind::hard ? "hard " : "synthetic ") + d.name(), std::move(items), {d}});
    }
  }
  return sets;
}

// The detectors run on one set: arwb, and each peer asked for. Peers search one dictionary each: with several,
// each runs once per dictionary and the times add up. The functions refer to the members: not moved once made.
struct SetDetectors {
  SetDetectors(const std::vector<Dictionary>& used, const DetectorParams& params,
               const std::vector<std::string>& peers)
      : arwb(used, params) {
    auto wants = [&](const char* peer) { return std::find(peers.begin(), peers.end(), peer) != peers.end(); };
    fns.emplace_back("arwb", [this](const cv::Mat& img) {
      PeerResult r;
      const auto t0 = std::chrono::steady_clock::now();
      r.markers = arwb.detect(img);
      r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      return r;
    });
    for (const auto& d : used) {
      if (wants("opencv")) ocv.emplace_back(d.name());
      if (wants("aruco3")) aruco3.emplace_back(d.name(), true);
      if (wants("apriltag") && AprilTagPeer::supports(d.name())) april.emplace_back(d.name());
    }
    auto combine = [](auto& instances) {
      return [&instances](const cv::Mat& img) {
        PeerResult all;
        for (const auto& p : instances) {
          PeerResult r = p.detect(img);
          all.ms += r.ms;
          all.markers.insert(all.markers.end(), r.markers.begin(), r.markers.end());
        }
        return all;
      };
    };
    if (!ocv.empty()) fns.emplace_back("opencv", combine(ocv));
    if (!aruco3.empty()) fns.emplace_back("aruco3", combine(aruco3));
    if (!april.empty() && april.size() == used.size()) fns.emplace_back("apriltag", combine(april));
    // Named, not dropped: a peer asked for that cannot search every dictionary of the set.
    if (wants("apriltag") && april.size() != used.size())
      for (const auto& d : used)
        if (!AprilTagPeer::supports(d.name()))
          not_run.emplace_back("apriltag", "AprilTag reads its own families only (APRILTAG_*), not " + d.name());
  }
  SetDetectors(const SetDetectors&) = delete;
  SetDetectors& operator=(const SetDetectors&) = delete;

  const Detector arwb;
  std::vector<OpenCvArucoPeer> ocv, aruco3;
  std::vector<AprilTagPeer> april;
  std::vector<std::pair<std::string, DetectFn>> fns;   // in the order of the rows
  std::vector<std::pair<std::string, std::string>> not_run;   // a peer asked for, and why it cannot run here
};

// A peer that could not run on a set, and why.
struct NotRun {
  std::string set, detector, why;
};

// Fewer 640x480 images than this give a median of the trace's cost too noisy to print.
constexpr size_t kMinTraceCostImages = 3;

// What recording the trace costs, on the set's 640x480 images: the fastest of `reps` runs at each level.
void measure_trace_cost(const Detector& arwb, const std::vector<SetItem>& items, int reps,
                        std::array<std::vector<double>, 3>& trace_ms) {
  for (const auto& item : items) {
    if (item.image.cols != 640 || item.image.rows != 480) continue;
    for (int level = 0; level < 3; ++level) {
      double best = 1e18;
      for (int r = 0; r < reps; ++r) {
        FrameTrace t;
        const auto t0 = std::chrono::steady_clock::now();
        arwb.detect(item.image, &t, static_cast<TraceLevel>(level));
        best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      }
      trace_ms[size_t(level)].push_back(best);
    }
  }
}

// Every detector over the set's images, tallied by resolution and by condition; the set's rows appended: each
// resolution by size, each hardship, then all.
void bench_set(const Set& set, const SetDetectors& detectors, int reps, std::vector<Row>& rows) {
  std::map<std::string, std::map<std::string, Tally>> by_res;  // resolution -> detector -> tally
  std::map<std::string, std::map<std::string, Tally>> by_condition;
  // Each detector over all the images, one detector after another: taking turns on each image measured a
  // detector in the wake of the one before it (a small frame's runs right after another detector's run on a
  // 3840x2160 frame were slower for several runs; docs/detector-history.md, the eleventh round).
  for (const auto& [name, fn] : detectors.fns) {
    for (const auto& item : set.items) {
      const std::string res = std::to_string(item.image.cols) + "x" + std::to_string(item.image.rows);
      PeerResult first;
      double best = 1e18;
      for (int r = 0; r < reps; ++r) {
        PeerResult pr = fn(item.image);
        best = std::min(best, pr.ms);
        if (r == 0) first = std::move(pr);
      }
      std::vector<Tally*> tallies = {&by_res[res][name], &by_res["all"][name]};
      if (!item.condition.empty()) tallies.push_back(&by_condition[item.condition][name]);
      for (Tally* t : tallies) {
        t->ms.push_back(best);
        score(first.markers, item.truth, *t);
      }
    }
  }
  std::vector<std::string> order;
  for (const auto& [res, _] : by_res)
    if (res != "all") order.push_back(res);
  auto pixels = [](const std::string& res) {
    int w = 0, h = 0;
    std::sscanf(res.c_str(), "%dx%d", &w, &h);
    return long(w) * h;
  };
  std::sort(order.begin(), order.end(), [&](const auto& a, const auto& b) { return pixels(a) < pixels(b); });
  for (const auto& res : order)
    for (const auto& [name, _] : detectors.fns) rows.push_back({set.name, res, "", name, by_res.at(res).at(name)});
  for (const Hardship h : kHardships)
    if (const auto it = by_condition.find(std::string(hardship_name(h))); it != by_condition.end())
      for (const auto& [name, _] : detectors.fns)
        rows.push_back({set.name, "all", it->first, name, it->second.at(name)});
  for (const auto& [name, _] : detectors.fns) rows.push_back({set.name, "all", "", name, by_res.at("all").at(name)});
}

// The row of detector `det` for the same set, resolution and condition as r.
const Row* find_row(const std::vector<Row>& rows, const Row& r, const char* det) {
  for (const auto& o : rows)
    if (o.set == r.set && o.resolution == r.resolution && o.condition == r.condition && o.detector == det) return &o;
  return nullptr;
}

void print_json(const std::vector<Row>& rows, const std::array<std::vector<double>, 3>& trace_ms,
                const std::vector<NotRun>& not_run,
                const std::vector<std::string>& peers, int reps) {
  using Json = nlohmann::ordered_json;
  Json out = {{"cpu", cpu_model()}, {"vector_code", simd_name(simd())}, {"threads", 1}, {"reps", reps},
              {"peers", peers}, {"rows", Json::array()}};
  for (const Row& r : rows) {
    const Tally& t = r.tally;
    Json row = {{"set", r.set}, {"resolution", r.resolution}};
    if (!r.condition.empty()) row["condition"] = r.condition;
    row.update(Json{{"detector", r.detector},
                {"images", t.ms.size()},
                {"median_ms", round_decimals(median(t.ms), 3)},
                {"markers", t.truth},
                {"found", t.found},
                {"recall", round_decimals(t.truth ? double(t.found) / t.truth : 1.0, 4)},
                {"false_positives", t.false_pos},
                {"false_positives_on_empty", t.false_pos_empty},
                {"empty_images", t.empty_images},
                {"corner_error_px", t.corner_n ? Json(round_decimals(t.corner_err / t.corner_n, 4)) : Json()}});
    if (r.detector == "arwb")
      for (const char* peer : kPeers)
        if (const Row* p = find_row(rows, r, peer))
          row[std::string("time_ratio_") + peer] = round_decimals(median(t.ms) / median(p->tally.ms), 3);
    out["rows"].push_back(std::move(row));
  }
  out["not_run"] = Json::array();
  for (const NotRun& n : not_run) out["not_run"].push_back({{"set", n.set}, {"detector", n.detector}, {"why", n.why}});
  if (trace_ms[0].size() >= kMinTraceCostImages)
    out["trace_cost_640x480"] = {{"images", trace_ms[0].size()},
                                 {"off_ms", round_decimals(median(trace_ms[0]), 3)},
                                 {"summary_ms", round_decimals(median(trace_ms[1]), 3)},
                                 {"full_ms", round_decimals(median(trace_ms[2]), 3)},
                                 {"full_over_off", round_decimals(median(trace_ms[2]) / median(trace_ms[0]), 3)}};
  std::printf("%s\n", json_text(out).c_str());
}

void print_table(const std::vector<Row>& rows, const std::array<std::vector<double>, 3>& trace_ms,
                 const std::vector<NotRun>& not_run, int reps) {
  std::printf("processor: %s; arwb's vector code: %s\n", cpu_model().c_str(), simd_name(simd()));
  std::string last_set;
  for (const Row& r : rows) {
    if (r.set != last_set) {
      Row all{r.set, "all", "", "arwb", {}};
      const Row* total = find_row(rows, all, "arwb");
      const size_t images = total ? total->tally.ms.size() : size_t(0);
      std::printf("\n%s (%zu image%s, one thread, fastest of %d run%s per image)\n", r.set.c_str(), images,
                  images == 1 ? "" : "s", reps, reps == 1 ? "" : "s");
      std::printf("%-12s %-9s %9s %8s %9s %6s %9s %11s %s\n", "resolution", "detector", "median_ms", "recall",
                  "found", "FP", "FP_empty", "corner_px", "time ratio");
      for (const NotRun& n : not_run)
        if (n.set == r.set) std::printf("(%s not run: %s)\n", n.detector.c_str(), n.why.c_str());
      last_set = r.set;
    }
    const Tally& t = r.tally;
    std::string ratio;
    if (r.detector == "arwb")
      for (const char* peer : kPeers)
        if (const Row* p = find_row(rows, r, peer)) {
          char buf[64];
          std::snprintf(buf, sizeof buf, "%s%.2fx %s", ratio.empty() ? "" : ", ", median(t.ms) / median(p->tally.ms),
                        peer);
          ratio += buf;
        }
    std::printf("%-12s %-9s %9.2f %7.1f%% %4d/%-4d %6d %5d/%-3d %11s %s\n", r.group().c_str(), r.detector.c_str(),
                median(t.ms), t.truth ? 100.0 * t.found / t.truth : 100.0, t.found, t.truth, t.false_pos,
                t.false_pos_empty, t.empty_images,
                t.corner_n ? decimals_text(t.corner_err / t.corner_n, 3).c_str() : "-", ratio.c_str());
  }
  if (!trace_ms[0].empty() && trace_ms[0].size() < kMinTraceCostImages)
    std::printf("\ntrace cost: not measured (%zu image%s at 640x480; a median needs %zu)\n", trace_ms[0].size(),
                trace_ms[0].size() == 1 ? "" : "s", kMinTraceCostImages);
  if (trace_ms[0].size() >= kMinTraceCostImages)
    std::printf("\ntrace cost at 640x480 (%zu images, median ms): off %.2f, summary %.2f (%.2fx), full %.2f (%.2fx)\n",
                trace_ms[0].size(), median(trace_ms[0]), median(trace_ms[1]), median(trace_ms[1]) / median(trace_ms[0]),
                median(trace_ms[2]), median(trace_ms[2]) / median(trace_ms[0]));
}

}  // namespace

int cmd_bench(int argc, char** argv) {
  BenchArgs a;
  CommandLine cl("arwb bench",
                 "Runs arwb and its peers on one thread over the same images: OpenCV 4.6 cv::aruco::detectMarkers "
                 "with its default parameters (opencv) and in its ArUco3 mode (aruco3, useAruco3Detection) and, for "
                 "AprilTag families, AprilTag 3 with its default parameters (apriltag). Prints per resolution (and "
                 "per condition on a hard set): median ms per frame, recall, false positives (all, and on images "
                 "without markers), mean corner error of found markers, and arwb's time as a ratio of each peer's.",
                 "Without DIR, synthetic sets are made in memory for each dictionary: --count images of the standard "
                 "set (mixed 640x480, 1280x720 and 1920x1080) and of the hard set (low_contrast, tiny, low_light and "
                 "crossed in turn, up to 3840x2160), as --set says.");
  declare_options(cl.app, a);
  if (const auto status = cl.parse(argc, argv)) return *status;
  a.has_dir = cl.app.count("DIR") > 0;
  if (const auto status = misplaced_options(cl, a)) return *status;
  if (a.pose_mode) {
    a.pose.seed = a.seed;
    a.pose.json = a.as_json;
    if (cl.app.count("--count")) a.pose.sequence_frames = a.count;
    return run_pose_bench(a.pose);
  }
  DetectorParams params;
  if (!load_params_option(a.params_path, "arwb bench", params)) return 2;
  if (a.tracking) return bench_tracking({a.count, unsigned(a.seed), 6, 120, params}, a.as_json);
  std::vector<std::string> peers;
  if (a.peers_arg != "none")
    for (const std::string& name : split_list(a.peers_arg)) {
      if (std::find(std::begin(kPeers), std::end(kPeers), name) == std::end(kPeers))
        return cl.usage_error("--peers: unknown peer '" + name + "' (opencv, aruco3, apriltag or none)");
      if (std::find(peers.begin(), peers.end(), name) == peers.end()) peers.push_back(name);
    }
  if (a.has_dir && cl.app.count("--set")) return cl.usage_error("--set makes synthetic sets: not with DIR");
  const auto dicts = dictionaries_option(a.dict_arg, "arwb bench");
  if (!dicts) return 2;
  if (a.video) {
    VideoBenchOptions v;
    v.sequences = cl.app.count("--count") ? a.count : 2;
    v.frames = cl.app.count("--frames") ? a.pose.frames : 60;
    v.seed = unsigned(a.seed);
    v.reps = cl.app.count("--reps") ? a.reps : 1;
    v.dicts = *dicts;
    v.peers = peers;
    v.params = params;
    v.json = a.as_json;
    return bench_video(v);
  }
  cv::setNumThreads(1);  // every detector on one thread

  const std::optional<std::vector<Set>> sets = bench_sets(a, *dicts);
  if (!sets) return 1;
  std::vector<Row> rows;
  // What recording the trace costs, on the first set's 640x480 images: median ms at each level.
  std::array<std::vector<double>, 3> trace_ms;
  std::vector<NotRun> not_run;
  for (const Set& set : *sets) {
    const SetDetectors detectors(set.dicts, params, peers);
    for (const auto& [detector, why] : detectors.not_run) not_run.push_back({set.name, detector, why});
    if (trace_ms[0].empty()) measure_trace_cost(detectors.arwb, set.items, a.reps, trace_ms);
    bench_set(set, detectors, a.reps, rows);
  }
  if (a.as_json) print_json(rows, trace_ms, not_run, peers, a.reps);
  else print_table(rows, trace_ms, not_run, a.reps);
  return 0;
}

}  // namespace arwb
