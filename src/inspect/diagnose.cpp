// explain_region reads a trace; sweep_region re-runs the detector. Neither draws nor writes files.
#include "inspect/diagnose.hpp"

#include "base/decimals.hpp"
#include "detect/pipeline.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstring>
#include <map>
#include <optional>

namespace arwb {
namespace {

std::string num(double v, int decimals = 1) { return decimals_text(v, decimals); }

// Positive width and height, inside [0,w]x[0,h].
cv::Rect2f clip_region(cv::Rect2f r, int w, int h) {
  if (r.width < 0) r.x += r.width, r.width = -r.width;
  if (r.height < 0) r.y += r.height, r.height = -r.height;
  const float x0 = std::clamp(r.x, 0.f, float(w)), x1 = std::clamp(r.x + r.width, 0.f, float(w));
  const float y0 = std::clamp(r.y, 0.f, float(h)), y1 = std::clamp(r.y + r.height, 0.f, float(h));
  return {x0, y0, x1 - x0, y1 - y0};
}

// Half-open boxes; a region of no size (a click) still overlaps the pixel it is on.
bool overlaps(const cv::Rect2f& r, float x0, float y0, float x1, float y1) {
  const float rx1 = r.x + std::max(r.width, 1e-3f), ry1 = r.y + std::max(r.height, 1e-3f);
  return r.x < x1 && x0 < rx1 && r.y < y1 && y0 < ry1;
}

bool contains(const cv::Rect2f& r, cv::Point2f p) {
  return p.x >= r.x && p.x <= r.x + r.width && p.y >= r.y && p.y <= r.y + r.height;
}

cv::Rect2f quad_box(const Quad& q) {
  float x0 = q[0].x, x1 = q[0].x, y0 = q[0].y, y1 = q[0].y;
  for (const auto& p : q) x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  return {x0, y0, x1 - x0, y1 - y0};
}

// A marker's centre in working pixels (markers are stored in input pixels).
cv::Point2f marker_centre_working(const Marker& m, double sx, double sy) {
  const cv::Point2f c = quad_centre(m.corners);
  return {float((c.x + 0.5) / sx - 0.5), float((c.y + 0.5) / sy - 0.5)};
}

// The candidate's box: its quad's where it has one, else its contour's (or small region's).
cv::Rect2f candidate_box(const CandidateRecord& c) {
  if (c.has_quad) {
    const cv::Rect2f b = quad_box(c.quad);
    return {b.x, b.y, b.width + 1, b.height + 1};
  }
  return cv::Rect2f(c.bbox);
}

// Intersection over union of two boxes; a region of no size (a click) counts as one pixel.
double iou(cv::Rect2f a, cv::Rect2f b) {
  a.width = std::max(a.width, 1.f), a.height = std::max(a.height, 1.f);
  b.width = std::max(b.width, 1.f), b.height = std::max(b.height, 1.f);
  const double inter = (a & b).area();
  const double uni = double(a.area()) + double(b.area()) - inter;
  return uni > 0 ? inter / uni : 0;
}

std::string upper_name(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  if (s.rfind("DICT_", 0) == 0) s = s.substr(5);
  return s;
}

std::string marker_name(const Marker& m) { return m.dict + " id " + std::to_string(m.id); }

std::string shape_of(const CandidateRecord& c) {
  if (c.has_quad) {
    const cv::Rect2f b = quad_box(c.quad);
    return "quad " + num(b.width + 1, 0) + "x" + num(b.height + 1, 0) + " px";
  }
  const std::string what = c.contour >= 0 ? "contour " : "region ";
  return what + std::to_string(c.bbox.width) + "x" + std::to_string(c.bbox.height) + " px";
}

// Which way to move the parameter that rejected a candidate so that it would pass.
std::string suggestion(const Rejection& r) {
  const std::string p(r.param);
  if (p.empty()) return "No parameter decides this; it is the candidate's shape or content.";
  if (p == "polygon_epsilon_rate")
    return r.value > r.limit ? "Raising polygon_epsilon_rate accepts rounder or blurrier quads."
                             : "Lowering polygon_epsilon_rate keeps more corners of the outline.";
  if (p == "min_marker_distance_rate")
    return "The outer quad of the same border is read instead; lowering min_marker_distance_rate keeps both.";
  if (p == "unrefined_miss_rate")
    return "Read before its corners were refined, it was too far from any id to refine; raising unrefined_miss_rate "
           "(1 refines every quad) reads it again refined.";
  if (p == "min_perimeter_px") return "Lowering min_perimeter_px below " + num(r.value, 0) + " would let it through.";
  if (p == "coarse_factor")
    return "The first search's quad of the same outline is read instead; coarse_factor 0 turns the coarse search off.";
  if (p == "region_margin_rate")
    return "The next full search (within full_search_interval frames) looks here whole; raising region_margin_rate "
           "widens the regions.";
  if (r.value < r.limit) return "Lowering " + p + " would let it through.";
  if (r.value > r.limit) return "Raising " + p + " would let it through.";
  return "";
}

}  // namespace

namespace {

// `advise`: end the summary with the parameter that would let the headline candidate through.
RegionReport explain(const FrameTrace& trace, cv::Rect2f region, bool advise) {
  RegionReport rep;
  const int w = trace.work_width > 0 ? trace.work_width : trace.width;
  const int h = trace.work_height > 0 ? trace.work_height : trace.height;
  rep.region = clip_region(region, w, h);
  const cv::Rect2f& r = rep.region;

  if (trace.level == TraceLevel::off) {
    // Only markers are recorded: say whether one is here, nothing more.
    for (const auto& m : trace.markers)
      if (contains(r, marker_centre_working(m, trace.scale_x, trace.scale_y))) {
        rep.lost_at = Stage::accepted;
        rep.summary = marker_name(m) + " is detected here. This trace is at level off, which records only markers.";
        return rep;
      }
    rep.lost_at = Stage::acquisition;  // unknown: nothing but markers was recorded
    rep.summary = "Nothing is detected here, and this trace is at level off, which records only markers: record a "
                  "full trace to see which stage lost it.";
    return rep;
  }

  for (int i = 0; i < int(trace.candidates.size()); ++i) {
    const CandidateRecord& c = trace.candidates[size_t(i)];
    bool hit = overlaps(r, float(c.bbox.x), float(c.bbox.y), float(c.bbox.x + c.bbox.width),
                        float(c.bbox.y + c.bbox.height));
    if (!hit && c.has_quad) {
      const cv::Rect2f b = quad_box(c.quad);
      hit = overlaps(r, b.x, b.y, b.x + b.width + 1, b.y + b.height + 1);
    }
    if (!hit) continue;
    RegionCandidate rc;
    rc.index = i;
    rc.fate = c.fate;
    if (c.fate.stage == Stage::accepted && c.marker >= 0 && c.marker < int(trace.markers.size())) {
      const Marker& m = trace.markers[size_t(c.marker)];
      rc.marker_id = m.id;
      rc.line = "#" + std::to_string(i) + " " + shape_of(c) + ": accepted: " + marker_name(m) + ", " +
                std::to_string(m.hamming) + " bits corrected";
    } else {
      rc.line = "#" + std::to_string(i) + " " + shape_of(c) + ": " + std::string(stage_name(c.fate.stage)) + ": " +
                c.fate.message;
    }
    rep.candidates.push_back(std::move(rc));
  }

  if (!rep.candidates.empty()) {
    // Markers first, then the candidate that covers the region best: the one the user drew the rectangle
    // around, not the page or the shadow that also overlaps it. Ties by the stage reached.
    std::vector<double> cover(trace.candidates.size(), 0.0);
    for (const RegionCandidate& rc : rep.candidates)
      cover[size_t(rc.index)] = iou(candidate_box(trace.candidates[size_t(rc.index)]), r);
    std::stable_sort(rep.candidates.begin(), rep.candidates.end(),
                     [&](const RegionCandidate& a, const RegionCandidate& b) {
                       const bool ma = a.fate.stage == Stage::accepted, mb = b.fate.stage == Stage::accepted;
                       if (ma != mb) return ma;
                       const double ca = cover[size_t(a.index)], cb = cover[size_t(b.index)];
                       if (ca != cb) return ca > cb;
                       return int(a.fate.stage) > int(b.fate.stage);
                     });
    rep.lost_at = Stage::accepted;
    const RegionCandidate& best = rep.candidates.front();
    const int others = int(rep.candidates.size()) - 1;
    if (best.fate.stage == Stage::accepted) {
      std::string found;
      int n = 0;
      for (const auto& rc : rep.candidates) {
        if (rc.fate.stage != Stage::accepted) break;
        const Marker& m = trace.markers[size_t(trace.candidates[size_t(rc.index)].marker)];
        found += (n++ ? ", " : "") + marker_name(m);
      }
      rep.summary = found + (n > 1 ? " are" : " is") + " detected here (candidate #" + std::to_string(best.index) +
                    ")";
      const int rejected = int(rep.candidates.size()) - n;
      if (rejected > 0) rep.summary += "; " + std::to_string(rejected) + " other candidate" +
                                       (rejected > 1 ? "s" : "") + " here " + (rejected > 1 ? "were" : "was") +
                                       " rejected";
      rep.summary += ".";
    } else {
      const CandidateRecord& c = trace.candidates[size_t(best.index)];
      rep.summary = "Nothing is detected here: " +
                    (others > 0 ? "of " + std::to_string(others + 1) + " candidates the one covering the region, "
                                : std::string()) +
                    "#" + std::to_string(best.index) + " (" + shape_of(c) + "), stopped at " +
                    std::string(stage_name(best.fate.stage)) + ": " + best.fate.message + "." +
                    (advise ? " " + suggestion(best.fate) : std::string());
    }
    return rep;
  }

  // No candidate here: find the earliest stage that had nothing.
  if (!trace.search.whole) {
    bool searched = false;
    for (const cv::Rect& s : trace.search.regions)
      searched = searched || overlaps(r, float(s.x), float(s.y), float(s.br().x), float(s.br().y));
    if (!searched) {
      rep.lost_at = Stage::search_regions;
      rep.summary = "This frame was not searched here: in video only the regions around the last frame's markers "
                    "are (" + trace.search.why + "). A marker here is found on the next whole search, within "
                    "full_search_interval frames; lower it to find new markers sooner.";
      return rep;
    }
  }
  const StageRecord* th = trace.stage(Stage::adaptive_threshold);
  if (trace.level != TraceLevel::full || !th || th->image.empty()) {
    rep.lost_at = Stage::size_filter;  // the latest it can have been: summary traces record from quad_fit on
    rep.summary = "Nothing here reached quad_fit. This is a summary-level trace without stage images or contours, "
                  "so whether adaptive_threshold, contours or size_filter lost it is unknown: record a full trace.";
    return rep;
  }
  const double f = trace.search_factor();  // the binary image is the decimated search's
  const cv::Rect roi = cv::Rect(cv::Point(int(std::floor(r.x / f)), int(std::floor(r.y / f))),
                                cv::Point(int(std::ceil((r.x + std::max(r.width, 1e-3f)) / f)),
                                          int(std::ceil((r.y + std::max(r.height, 1e-3f)) / f)))) &
                       cv::Rect(0, 0, th->image.cols, th->image.rows);
  const int foreground = roi.area() > 0 ? cv::countNonZero(th->image(roi)) : 0;
  if (foreground == 0) {
    rep.lost_at = Stage::adaptive_threshold;
    rep.summary = "adaptive_threshold found no pixel here darker than its neighbourhood mean by threshold_offset. "
                  "Lower threshold_offset for a faint or low-contrast marker, or raise threshold_window_px for a "
                  "large one whose border is wider than the window.";
    return rep;
  }
  int traced = 0;
  for (const auto& c : trace.contours) {
    if (c.empty()) continue;
    const cv::Rect b = cv::boundingRect(c);
    if (overlaps(r, float(b.x), float(b.y), float(b.x + b.width), float(b.y + b.height))) ++traced;
  }
  if (traced == 0) {
    rep.lost_at = Stage::contours;
    rep.summary = "adaptive_threshold found " + std::to_string(foreground) +
                  " foreground pixels here, but contours traced no border: their regions are too small to hold a "
                  "border of min_perimeter_px. Lower min_perimeter_px to find smaller markers.";
    return rep;
  }
  rep.lost_at = Stage::size_filter;
  rep.summary = std::to_string(traced) + " contours here were dropped by size_filter (min_perimeter_px, "
                "max_perimeter_rate) before quad_fit.";
  return rep;
}

}  // namespace

RegionReport explain_region(const FrameTrace& trace, cv::Rect2f region) { return explain(trace, region, true); }

// [SECTION] other dictionaries

namespace {

// The grid of a quad read as `n` x `n` inner bits, as the detector reads it (identification's input), or nothing
// when the frontal view is uniform or the border is not black.
std::optional<uint64_t> read_code(const cv::Mat& grey, Quad q, int n, const DetectorParams& p) {
  const int cells = n + 2;
  stages::refine_corners(grey, q, cells, p);
  const cv::Mat warp = stages::remove_perspective(grey, q, cells, p);
  const stages::OtsuResult o = stages::otsu(warp);
  if (o.stddev < p.otsu_min_stddev) return std::nullopt;
  const cv::Mat bits = stages::sample_bits(warp, cells, o.threshold, p);
  if (stages::border_errors(bits) > int(p.border_max_error_rate * 4 * (cells - 1))) return std::nullopt;
  return stages::inner_code(bits);
}

// The predefined dictionaries not searched, built once (dictionary_by_name caches them).
std::vector<Dictionary> unsearched(const std::vector<std::string>& searched) {
  std::vector<std::string> names;
  for (const auto& s : searched) names.push_back(upper_name(s));
  std::vector<Dictionary> out;
  for (const std::string& n : dictionary_names())
    if (std::find(names.begin(), names.end(), upper_name(n)) == names.end())
      if (auto d = dictionary_by_name(n)) out.push_back(std::move(*d));
  return out;
}

}  // namespace

std::vector<OtherDictionary> read_other_dictionaries(const FrameTrace& trace, const std::vector<int>& candidates,
                                                     const DetectorParams& params,
                                                     const std::vector<std::string>& searched) {
  std::vector<OtherDictionary> out;
  const StageRecord* acq = trace.stage(Stage::acquisition);
  if (trace.level != TraceLevel::full || !acq || acq->image.empty() || acq->image.type() != CV_8UC1) return out;
  const cv::Mat& grey = acq->image;
  const std::vector<Dictionary> dicts = unsearched(searched);
  if (dicts.empty()) return out;
  std::vector<int> sizes;
  for (const Dictionary& d : dicts)
    if (std::find(sizes.begin(), sizes.end(), d.marker_size()) == sizes.end()) sizes.push_back(d.marker_size());

  // Every quad of the frame that was read and not accepted (an inner quad merged into its outer one is the same
  // marker): which dictionaries read it, for the tie-break and for the region's own candidates.
  auto readings = [&](int index) {
    std::vector<OtherDictionary> hits;
    const CandidateRecord& c = trace.candidates[size_t(index)];
    if (!c.has_quad || c.fate.stage == Stage::accepted || c.fate.stage == Stage::nested_filter) return hits;
    for (int n : sizes) {
      const std::optional<uint64_t> code = read_code(grey, c.quad, n, params);
      if (!code) continue;
      for (const Dictionary& d : dicts) {
        if (d.marker_size() != n) continue;
        const DictMatch m = d.nearest(*code);
        if (m.id >= 0 && m.hamming <= stages::correction_budget(d, params))
          hits.push_back({index, d.name(), m.id, m.hamming, 0});
      }
    }
    return hits;
  };
  std::vector<std::vector<OtherDictionary>> region_hits;
  for (int i : candidates) region_hits.push_back(readings(i));
  if (std::all_of(region_hits.begin(), region_hits.end(), [](const auto& h) { return h.empty(); })) return out;
  std::map<std::string, int> in_frame;
  for (int i = 0; i < int(trace.candidates.size()); ++i)
    for (const OtherDictionary& h : readings(i)) ++in_frame[h.dict];
  std::map<std::string, int> dict_size;
  for (const Dictionary& d : dicts) dict_size[d.name()] = d.size();
  for (auto& hits : region_hits) {
    for (OtherDictionary& h : hits) h.in_frame = in_frame[h.dict];
    std::stable_sort(hits.begin(), hits.end(), [&](const OtherDictionary& a, const OtherDictionary& b) {
      if (a.in_frame != b.in_frame) return a.in_frame > b.in_frame;
      if (a.hamming != b.hamming) return a.hamming < b.hamming;
      return dict_size[a.dict] < dict_size[b.dict];
    });
    out.insert(out.end(), hits.begin(), hits.end());
  }
  return out;
}

RegionReport explain_region(const FrameTrace& trace, cv::Rect2f region, const DetectorParams& params,
                            const std::vector<std::string>& searched) {
  RegionReport rep = explain(trace, region, false);
  const bool detected = !rep.candidates.empty() && rep.candidates.front().fate.stage == Stage::accepted;
  if (!detected && !rep.candidates.empty()) {
    std::vector<int> indices;
    for (const RegionCandidate& rc : rep.candidates) indices.push_back(rc.index);
    rep.other_dictionaries = read_other_dictionaries(trace, indices, params, searched);
  }
  if (rep.other_dictionaries.empty()) return explain(trace, region, true);
  const OtherDictionary& o = rep.other_dictionaries.front();
  std::string list;
  for (const auto& s : searched) list += (list.empty() ? "" : ", ") + s;
  rep.advice = "This is a " + o.dict + " marker, id " + std::to_string(o.id) + " (candidate #" +
               std::to_string(o.candidate) + "): add that dictionary; the detector searches " +
               (list.empty() ? std::string("none") : list) + ".";
  rep.summary = rep.advice + " " + rep.summary;
  return rep;
}

// [SECTION] sweep

namespace {

constexpr int kDoubleSteps = 12;     // values tried each way for a real-valued parameter
constexpr int kIntSteps = 10;        // and for an integer one wider than that
constexpr int kMaxRuns = 460;        // singles and pairs together
constexpr int kMinPairRuns = 120;    // the pair grid always gets at least this many

// The parameters that most often decide whether a marker is found, each with the direction that finds more.
struct Promising {
  const char* name;
  int permissive;
};
constexpr Promising kPromising[] = {
    {"threshold_offset", -1},      {"threshold_window_px", +1},  {"min_perimeter_px", -1},
    {"polygon_epsilon_rate", +1},  {"otsu_min_stddev", -1},      {"border_max_error_rate", +1},
    {"error_correction_rate", +1}, {"unrefined_miss_rate", +1},
};

double nice_step(double raw) {
  const double e = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0})
    if (m * e >= raw * (1 - 1e-9)) return m * e;
  return 10 * e;
}

double round_sig(double v, int digits) {
  if (v == 0) return 0;
  const double e = std::pow(10.0, std::floor(std::log10(std::fabs(v))) - digits + 1);
  return std::round(v / e) * e;
}

// Values of one parameter on one side of `cur`, nearest first, inside its range.
std::vector<double> side_values(const ParamInfo& info, double cur, int dir) {
  const double end = dir > 0 ? info.max_value : info.min_value;
  const double span = std::fabs(end - cur);
  std::vector<double> out;
  if (span <= 0) return out;
  auto push = [&](double v) {
    v = std::clamp(v, info.min_value, info.max_value);
    if ((v - cur) * dir <= 1e-12) return;
    if (!out.empty() && (v - out.back()) * dir <= 1e-12) return;
    out.push_back(v);
  };
  if (info.integer) {
    const bool odd = std::strcmp(info.name, "threshold_window_px") == 0;  // the window is always made odd
    const int unit = odd ? 2 : 1;
    const int count = int(span) / unit;
    for (int k = 1; k <= std::min(count, kIntSteps); ++k) {
      // Unit steps near the current value, then spreading out to the end of the range.
      double d = count <= kIntSteps ? k * unit
                                    : std::max<double>(k * unit, std::round(span * std::pow(double(k) / kIntSteps, 2) /
                                                                             unit) * unit);
      d = std::min(d, span);
      double v = cur + dir * d;
      if (odd) v = double(int(v) | 1);
      if (odd && int(v) == (int(cur) | 1)) continue;
      push(v);
    }
    return out;
  }
  if (cur > 0 && end > 0 && std::max(cur, end) / std::min(cur, end) > 20) {
    // Orders of magnitude away: geometric steps with round values.
    for (int k = 1; k <= kDoubleSteps; ++k)
      push(k == kDoubleSteps ? end : round_sig(cur * std::pow(end / cur, double(k) / kDoubleSteps), 2));
    return out;
  }
  // Round steps, aligned to multiples of the step, ending at the range's end.
  const double step = nice_step(span / kDoubleSteps);
  const double k0 = dir > 0 ? std::floor(cur / step + 1e-9) + 1 : std::ceil(cur / step - 1e-9) - 1;
  for (int i = 0; i <= kDoubleSteps + 1; ++i) {
    const double v = std::round((k0 + dir * i) * step * 1e9) / 1e9;
    if ((v - end) * dir >= 0) break;
    push(v);
  }
  push(end);
  return out;
}

struct ParamValues {
  const ParamInfo* info = nullptr;
  double cur = 0;       // as set
  std::vector<double> down, up;
};

// The resize is not tried: it is acquisition's (one resize, before the frame reaches the detector's table).
ParamValues values_for(const ParamInfo& info, const DetectorParams& p) {
  ParamValues pv;
  pv.info = &info;
  pv.cur = get_param(p, info);
  pv.down = side_values(info, pv.cur, -1);
  pv.up = side_values(info, pv.cur, +1);
  return pv;
}

struct Trial {
  int a = -1;
  double va = 0;
  int b = -1;
  double vb = 0;
  double cost = 0;
};

}  // namespace

SweepResult sweep_region(const cv::Mat& image, const Detector& detector, cv::Rect2f region,
                         std::function<void(double)> progress, const std::atomic<bool>* cancel) {
  SweepResult res;
  if (image.empty()) {
    res.message = "no image to sweep";
    return res;
  }
  const DetectorParams base = detector.params();
  Detector det = detector;
  FrameTrace t0;
  const std::vector<Marker> before = det.detect(image, &t0, TraceLevel::off);
  res.runs = 1;
  // Region and marker centres in the working pixels (the detector's acquisition, which no trial changes).
  const double sx = t0.scale_x, sy = t0.scale_y;
  const cv::Rect2f r = clip_region(region, t0.work_width, t0.work_height);
  const cv::Point2f rc(r.x + r.width / 2, r.y + r.height / 2);
  auto marker_here = [&](const std::vector<Marker>& ms) -> const Marker* {
    const Marker* best = nullptr;
    double best_d = 1e30;
    for (const auto& m : ms) {
      const cv::Point2f c = marker_centre_working(m, sx, sy);
      if (!contains(r, c)) continue;
      const double d = cv::norm(c - rc);
      if (d < best_d) best_d = d, best = &m;
    }
    return best;
  };
  if (const Marker* m = marker_here(before)) {
    res.found = true;
    res.marker = *m;
    res.message = marker_name(*m) + " is already detected here with the current parameters";
    if (progress) progress(1.0);
    return res;
  }

  // A marker of a dictionary that is not searched is found by adding the dictionary, whatever the parameters:
  // say so before trying any of them.
  if (!(cancel && cancel->load())) {
    FrameTrace full;
    det.detect(image, &full, TraceLevel::full);
    ++res.runs;
    std::vector<std::string> searched;
    for (const Dictionary& d : det.dictionaries()) searched.push_back(d.name());
    const RegionReport rep = explain_region(full, r, base, searched);
    if (!rep.other_dictionaries.empty()) {
      const OtherDictionary& o = rep.other_dictionaries.front();
      const CandidateRecord& c = full.candidates[size_t(o.candidate)];
      res.found = true;
      res.add_dictionary = o.dict;
      res.marker.id = o.id;
      res.marker.dict = o.dict;
      for (int k = 0; k < 4; ++k)   // back to input pixels, as detected markers are
        res.marker.corners[size_t(k)] = {float((c.quad[size_t(k)].x + 0.5) * sx - 0.5),
                                         float((c.quad[size_t(k)].y + 0.5) * sy - 0.5)};
      res.marker.hamming = o.hamming;
      res.message = "adding the dictionary " + o.dict + " finds " + o.dict + " id " + std::to_string(o.id) +
                    "; no parameter needs to change";
      if (progress) progress(1.0);
      return res;
    }
  }

  const auto table = param_table();
  std::vector<ParamValues> values;
  for (const auto& info : table) {
    values.push_back(values_for(info, base));
    if (!is_detector_param(info)) values.back().down.clear(), values.back().up.clear();   // no effect on detection
  }
  auto cost = [&](int i, double v) {
    const ParamInfo& info = *values[size_t(i)].info;
    return std::fabs(v - values[size_t(i)].cur) / (info.max_value - info.min_value);
  };

  std::vector<Trial> singles;
  for (int i = 0; i < int(values.size()); ++i)
    for (const auto* side : {&values[size_t(i)].down, &values[size_t(i)].up})
      for (double v : *side) singles.push_back({i, v, -1, 0, cost(i, v)});
  std::stable_sort(singles.begin(), singles.end(), [](const Trial& x, const Trial& y) { return x.cost < y.cost; });

  // Pairs among the promising parameters: two values on the side that finds more, one on the other.
  std::vector<std::pair<int, std::vector<double>>> grid;
  for (const auto& pr : kPromising) {
    int i = 0;
    while (i < int(table.size()) && std::strcmp(table[size_t(i)].name, pr.name) != 0) ++i;
    if (i == int(table.size())) continue;
    const ParamValues& pv = values[size_t(i)];
    const auto& more = pr.permissive < 0 ? pv.down : pv.up;
    const auto& less = pr.permissive < 0 ? pv.up : pv.down;
    std::vector<double> vs;
    if (!more.empty()) {
      vs.push_back(more[more.size() / 3]);
      if (more.size() >= 3) vs.push_back(more[2 * more.size() / 3]);
    }
    if (!less.empty()) vs.push_back(less[less.size() / 2]);
    if (!vs.empty()) grid.emplace_back(i, std::move(vs));
  }
  std::vector<Trial> pairs;
  for (size_t g = 0; g < grid.size(); ++g)
    for (size_t h = g + 1; h < grid.size(); ++h)
      for (double va : grid[g].second)
        for (double vb : grid[h].second)
          pairs.push_back({grid[g].first, va, grid[h].first, vb, cost(grid[g].first, va) + cost(grid[h].first, vb)});
  std::stable_sort(pairs.begin(), pairs.end(), [](const Trial& x, const Trial& y) { return x.cost < y.cost; });
  const int pair_budget = std::max(kMinPairRuns, kMaxRuns - int(singles.size()));
  if (int(pairs.size()) > pair_budget) pairs.resize(size_t(pair_budget));
  if (int(singles.size()) > kMaxRuns - int(pairs.size())) singles.resize(size_t(kMaxRuns - int(pairs.size())));
  const double planned = double(singles.size() + pairs.size());

  auto describe = [&](int i, double v) {
    const ParamValues& pv = values[size_t(i)];
    return std::string(pv.info->name) + " " + num(pv.cur, 4) + " -> " + num(v, 4);
  };
  // The pair grid is coarse: move each of the two values back towards its current value as far as the marker
  // stays found (nearest to current first, so the first hit is the smallest change).
  auto refine_pair = [&](Trial t, Marker& m) {
    for (int which = 0; which < 2; ++which) {
      const int i = which == 0 ? t.a : t.b;
      double& v = which == 0 ? t.va : t.vb;
      const ParamValues& pv = values[size_t(i)];
      const auto& side = v < pv.cur ? pv.down : pv.up;
      for (double closer : side) {
        if (std::fabs(closer - pv.cur) >= std::fabs(v - pv.cur)) break;
        if (cancel && cancel->load()) return t;
        DetectorParams p = base;
        if (!set_param(p, *values[size_t(t.a)].info, which == 0 ? closer : t.va) ||
            !set_param(p, *values[size_t(t.b)].info, which == 1 ? closer : t.vb))
          continue;
        det.set_params(p);
        const std::vector<Marker> found = det.detect(image);
        ++res.runs;
        if (const Marker* hit = marker_here(found)) {
          m = *hit;
          v = closer;
          break;
        }
      }
    }
    return t;
  };
  auto try_all = [&](const std::vector<Trial>& trials) -> bool {
    for (const Trial& t : trials) {
      if (cancel && cancel->load()) return false;
      DetectorParams p = base;
      if (!set_param(p, *values[size_t(t.a)].info, t.va)) continue;
      if (t.b >= 0 && !set_param(p, *values[size_t(t.b)].info, t.vb)) continue;
      det.set_params(p);
      const std::vector<Marker> found = det.detect(image);
      ++res.runs;
      if (progress) progress(std::min(1.0, (res.runs - 1) / planned));
      if (const Marker* m = marker_here(found)) {
        res.found = true;
        res.marker = *m;
        Trial best = t;
        if (t.b >= 0) best = refine_pair(t, res.marker);
        res.changes.push_back({values[size_t(best.a)].info->name, values[size_t(best.a)].cur, best.va});
        std::string what = describe(best.a, best.va);
        if (best.b >= 0) {
          res.changes.push_back({values[size_t(best.b)].info->name, values[size_t(best.b)].cur, best.vb});
          what += " and " + describe(best.b, best.vb);
        }
        res.message = what + (best.b >= 0 ? " find " : " finds ") + marker_name(res.marker);
        return true;
      }
    }
    return false;
  };
  const bool done = try_all(singles) || try_all(pairs);
  if (!done) {
    if (cancel && cancel->load()) {
      res.message = "cancelled after " + std::to_string(res.runs) + " runs";
    } else {
      std::string names;
      for (size_t g = 0; g < grid.size(); ++g) names += (g ? ", " : "") + std::string(table[size_t(grid[g].first)].name);
      res.message = "no change of one parameter, nor of two among " + names + ", finds a marker here (" +
                    std::to_string(res.runs) + " runs)";
    }
  }
  if (progress) progress(1.0);
  return res;
}

}  // namespace arwb
