// Chains the stages of pipeline.hpp over one frame and fills the trace.
// Step 1: find quads (acquisition .. nested_filter), whole-image work on the calling thread. The search
// (adaptive_threshold .. quad_fit) runs on the decimated image, and coarse_search once more on a coarser one; their
// contours and quads are mapped back at once, so from contours on everything is in the grey image's pixels.
// Step 2: read each quad (corner_refinement .. identification), per candidate, spread over threads: first as found
// (unrefined_miss_rate), then refined where that read could be a marker. On a decimated
// search, fine_search then searches the small shapes that did not close or read again at full resolution, and its
// quads are read the same way.
// Step 3: resolve duplicates and map corners back to the input image.
// Each stage's time and counts are its own: the trace lists the stages in the order they run here.
#include "detect/detector.hpp"

#include "detect/pipeline.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <thread>

namespace arwb {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// The per-candidate stages in the order read_one runs them, whose times are summed over candidates.
constexpr Stage kCandidateStages[] = {Stage::corner_refinement, Stage::perspective_removal, Stage::otsu,
                                      Stage::bit_grid, Stage::border_check, Stage::identification};
constexpr int kCandidateStageCount = static_cast<int>(std::size(kCandidateStages));

// What step 2 produces for one quad.
struct Reading {
  CandidateRecord record;
  int dict_index = -1;
  DictMatch match;
  Quad corners{};  // marker's own order, refined, working pixels
  std::array<double, kCandidateStageCount> ms{};
  int reached = 0;  // how far it got, to choose which reading to report when several sizes were tried
};

std::string fmt_msg(const char* f, double a, double b, double c = 0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

}  // namespace

Detector::Detector(std::vector<Dictionary> dictionaries, DetectorParams params)
    : dictionaries_(std::move(dictionaries)), params_(params) {}

std::vector<Marker> Detector::detect(const cv::Mat& image, FrameTrace* trace, TraceLevel level, int threads,
                                     cv::Mat* acquired, const SearchHint* hint) const {
  const DetectorParams& p = params_;
  FrameTrace local;
  FrameTrace& t = trace ? *trace : local;
  t = FrameTrace{};
  if (!trace) level = TraceLevel::off;
  t.level = level;
  const bool timed = level != TraceLevel::off, full = level == TraceLevel::full;
  const auto frame_start = Clock::now();
  t.width = image.cols;
  t.height = image.rows;
  if (image.empty() || dictionaries_.empty()) {
    if (acquired) acquired->release();
    return {};
  }

  auto stage_start = Clock::now();
  auto close_stage = [&](Stage s, int in, int out, cv::Mat img = {}) {
    if (!timed) return;
    t.stages.push_back(StageRecord{s, ms_since(stage_start), in, out, full ? img : cv::Mat()});
    stage_start = Clock::now();
  };

  // Step 1: find quads.
  // A colour frame is made grey where the stages look (GreyOnDemand); the full trace shows all of it.
  stages::GreyOnDemand on_demand = stages::acquire_on_demand(image, acquisition_, &t.scale_x, &t.scale_y, acquired);
  if (full) on_demand.need_all();
  const cv::Mat& grey = on_demand.image();
  t.work_width = grey.cols;
  t.work_height = grey.rows;
  if (acquired) {
    // The caller works in the acquired image: it is the input from here on.
    t.width = grey.cols;
    t.height = grey.rows;
    t.scale_x = t.scale_y = 1;
  }
  close_stage(Stage::acquisition, 1, 1, grey);
  // The grey pixels a later stage looks at, converted when it asks: acquisition's time (its record is the first),
  // not the asking stage's. Returns the time spent.
  auto need = [&](const cv::Rect& r) {
    if (on_demand.colour().empty()) return 0.0;
    const auto t0 = Clock::now();
    on_demand.need(r);
    if (!timed) return 0.0;
    const auto spent = Clock::now() - t0;
    stage_start += spent;
    const double ms = std::chrono::duration<double, std::milli>(spent).count();
    t.stages.front().ms += ms;
    return ms;
  };

  // search_regions: the whole frame, or around the markers earlier frames found (working pixels). One frame in,
  // its regions out; decimation .. contours take the regions in and give them out (contours: their black regions).
  std::vector<Quad> known;
  if (hint && hint->why_full.empty())
    for (const Quad& q : hint->known) {
      Quad w;
      for (int j = 0; j < 4; ++j)
        w[size_t(j)] = cv::Point2f(float((q[size_t(j)].x + 0.5) / t.scale_x - 0.5),
                                   float((q[size_t(j)].y + 0.5) / t.scale_y - 0.5));
      known.push_back(w);
    }
  const stages::SearchPlan plan = stages::plan_search(grey.size(), known, p);
  const int factor = plan.factor;
  if (timed) {
    t.search.whole = plan.whole;
    t.search.regions = plan.regions;
    t.search.factor = plan.factor;
    t.search.known = hint ? int(hint->known.size()) : 0;
    const std::string scale = factor == 1 ? std::string("every pixel") : "decimated " + std::to_string(factor) + "x";
    t.search.why = !hint ? "whole frame: a single image, " + scale
                   : !hint->why_full.empty() ? "whole frame: " + hint->why_full + ", " + scale
                   : plan.whole ? "whole frame: no marker known, " + scale
                                : "around " + std::to_string(known.size()) + " marker" + (known.size() == 1 ? "" : "s") +
                                      " of the previous frame, " + scale;
  }
  close_stage(Stage::search_regions, 1, int(plan.regions.size()));

  // decimation .. contours, once per region. The search's pictures are kept at the decimated size (the views
  // stretch them over the frame); with regions, the parts outside them are black.
  std::array<double, 3> search_ms{};
  auto search_lap = [&](int slot) {
    if (!timed) return;
    search_ms[size_t(slot)] += ms_since(stage_start);
    stage_start = Clock::now();
  };
  cv::Mat search_picture, binary_picture;
  cv::Mat whole_search;   // the first search's image of the whole frame, when it searched the whole frame
  cv::Mat whole_blocks;   // and its 2x2 block means, the threshold's (empty when its window took none)
  const bool one_region = plan.regions.size() == 1 && plan.regions[0].size() == grey.size();
  if (full && !one_region) {
    search_picture = cv::Mat::zeros(grey.rows / factor, grey.cols / factor, CV_8UC1);
    binary_picture = search_picture.clone();
  }
  std::vector<stages::SmallRegion> small;
  int regions = 0;
  std::vector<std::vector<cv::Point>> contours;
  std::vector<char> cut;   // per contour: cut by its region's edge
  // For fine_search's holes: each region's binary image and its contours (indices into `contours`).
  struct Searched {
    cv::Rect region;
    cv::Mat binary;
    size_t first, last;
  };
  std::vector<Searched> searched;
  for (const cv::Rect& r : plan.regions) {
    const cv::Mat search = stages::search_image(on_demand, r, factor);
    search_lap(0);
    const cv::Mat binary = stages::adaptive_threshold(search, p, one_region ? &whole_blocks : nullptr);
    search_lap(1);
    std::vector<stages::SmallRegion> region_small;
    std::vector<stages::SmallRegion>* small_out = !full ? nullptr : one_region ? &small : &region_small;
    int region_count = 0;
    std::vector<std::vector<cv::Point>> found =
        stages::find_contours(binary, p.min_perimeter_px, timed ? &region_count : nullptr, small_out, factor);
    regions += region_count;
    const size_t first = contours.size();
    if (one_region) {
      contours = std::move(found);
      found.clear();
      cut.assign(contours.size(), 0);
    }
    for (auto& c : found) {   // a region's contours, moved to the frame's pixels
      for (cv::Point& pt : c) pt += r.tl();
      cut.push_back(stages::cut_by_region(cv::boundingRect(c), r, grey.size(), factor));
      contours.push_back(std::move(c));
    }
    if (factor > 1 && p.fine_max_side_px > 0) searched.push_back({r, binary, first, contours.size()});
    for (auto& sm : region_small) {
      sm.bbox += r.tl();
      small.push_back(sm);
    }
    search_lap(2);
    if (one_region) whole_search = search;
    if (full) {
      if (one_region) {
        search_picture = search;
        binary_picture = binary;
      } else {
        const cv::Rect at(r.x / factor, r.y / factor, search.cols, search.rows);
        const cv::Rect inside = at & cv::Rect(0, 0, search_picture.cols, search_picture.rows);
        const cv::Rect from(inside.tl() - at.tl(), inside.size());
        search(from).copyTo(search_picture(inside));
        binary(from).copyTo(binary_picture(inside));
      }
    }
  }
  if (timed) {
    const Stage search_stages[] = {Stage::decimation, Stage::adaptive_threshold, Stage::contours};
    const cv::Mat pictures[] = {search_picture, binary_picture, {}};
    const int outs[] = {int(plan.regions.size()), int(plan.regions.size()), regions};
    for (int k = 0; k < 3; ++k)
      t.stages.push_back(StageRecord{search_stages[k], search_ms[size_t(k)], int(plan.regions.size()),
                                     outs[k], full ? pictures[k] : cv::Mat()});
    stage_start = Clock::now();
  }

  // coarse_search: the whole frame once more, coarse_factor times coarser than the first search, for large markers
  // (a frame searched by regions is already searched at its markers' scale). It shrinks the first search's image;
  // at an even factor, the threshold's 2x2 block means of it, a quarter of its pixels (at 640x480 the decimation
  // was a third of the stage). Its contours join the others; each contour keeps the factor it was found at
  // (`coarse`: the grey image's pixels a coarse one spans).
  std::vector<int> contour_factor(contours.size(), factor);
  const int coarse = p.coarse_factor > 1 ? factor * p.coarse_factor : 0;
  {
    const int fine_regions = regions;
    cv::Mat coarse_binary;
    if (plan.whole && coarse > 0 && std::min(grey.cols, grey.rows) / coarse >= 32) {
      const bool from_blocks = p.coarse_factor % 2 == 0 && !whole_blocks.empty();
      coarse_binary = stages::adaptive_threshold(
          from_blocks ? stages::decimate(whole_blocks, p.coarse_factor / 2) : stages::decimate(whole_search, p.coarse_factor),
          p);
      std::vector<std::vector<cv::Point>> found =
          stages::find_contours(coarse_binary, p.coarse_min_perimeter_px, nullptr, nullptr, coarse);
      for (auto& c : found) {
        ++regions;
        contours.push_back(std::move(c));
        cut.push_back(0);
        contour_factor.push_back(coarse);
      }
    }
    close_stage(Stage::coarse_search, fine_regions, regions, coarse_binary);
  }

  struct QuadCandidate {
    int record;   // index into t.candidates, or -1 when not traced
    int contour;
    Quad quad;
  };
  std::vector<QuadCandidate> quads;
  std::vector<int> size_passed;
  const cv::Size work_size = grey.size();
  auto add_record = [&](int contour_index, std::optional<Rejection> fate) -> int {
    CandidateRecord r;
    const auto& c = contours[size_t(contour_index)];
    r.contour = full ? contour_index : -1;
    r.bbox = cv::boundingRect(c);
    r.perimeter = stages::contour_length(c, contour_factor[size_t(contour_index)]);
    if (fate) r.fate = std::move(*fate);
    t.candidates.push_back(std::move(r));
    return int(t.candidates.size()) - 1;
  };
  // One record per traced contour and, at full, per region too small to trace (thousands at full resolution): made
  // in place, not moved again as the list grows.
  if (timed) t.candidates.reserve(contours.size() + small.size());
  if (full) {
    // Regions too small to trace: their box bounds the border they could have. The message from whole numbers
    // (snprintf's %f per speck was a third of the full trace's cost; to_string's pieces joined by + a tenth of it).
    for (const auto& s : small) {
      CandidateRecord& r = t.candidates.emplace_back();
      r.bbox = s.bbox;
      const int border = 2 * (s.bbox.width + s.bbox.height);
      r.perimeter = border;
      r.fate.stage = Stage::size_filter;
      r.fate.param = "min_perimeter_px";
      r.fate.value = r.perimeter;
      r.fate.limit = p.min_perimeter_px;
      // "border <= 12 px": short enough to live in the string itself (15 characters up to a border of 99 px),
      // where a longer message cost every speck an allocation (about a quarter of what the full trace adds at
      // 640x480); the fate's parameter, value and limit say what it was compared with.
      char text[32] = "border <= ";
      char* end = std::to_chars(text + 10, text + 26, border).ptr;
      *end++ = ' ';
      *end++ = 'p';
      *end++ = 'x';
      r.fate.message.assign(text, size_t(end - text));
    }
  }
  // fine_search takes the decimated search's small shapes that size_filter finds too short or quad_fit cannot
  // close: their boxes, in the grey image's pixels (a contour's points are block centres: its box covers whole
  // blocks).
  const bool fine_on = factor > 1 && p.fine_max_side_px > 0;
  std::vector<cv::Rect> fine_shapes;
  auto fine_shape = [&](int i) {
    if (!fine_on || contour_factor[size_t(i)] != factor) return;
    const cv::Rect b = cv::boundingRect(contours[size_t(i)]);
    const int h = (factor - 1) / 2;
    fine_shapes.emplace_back(b.x - h, b.y - h, b.width + factor - 1, b.height + factor - 1);
  };
  // size_filter, for contour i: true when it goes on to quad_fit.
  auto size_ok = [&](int i) {
    if (cut[size_t(i)]) {
      if (full)
        add_record(i, Rejection{Stage::size_filter, "region_margin_rate", 0, p.region_margin_rate,
                                "cut by the edge of its search region (region_margin_rate): a marker there is "
                                "searched whole on the next full search"});
      return false;
    }
    if (auto why = stages::size_filter(contours[size_t(i)], work_size, p, full, contour_factor[size_t(i)])) {
      if (why->param == "min_perimeter_px") fine_shape(i);
      if (full) add_record(i, std::move(why));
      return false;
    }
    return true;
  };
  for (int i = 0; i < int(contours.size()); ++i)
    if (size_ok(i)) size_passed.push_back(i);
  close_stage(Stage::size_filter, regions, int(size_passed.size()));

  // A quad of the coarse search that the first search found too (the same corners, to two coarse pixels) is not
  // read twice.
  auto found_before = [&](const Quad& q) -> int {
    const float tol = 2.0f * float(coarse);
    for (const auto& other : quads) {
      if (contour_factor[size_t(other.contour)] == coarse) continue;
      for (int shift = 0; shift < 4; ++shift) {
        bool same = true;
        for (int j = 0; j < 4 && same; ++j) {
          const cv::Point2f d = q[size_t(j)] - other.quad[size_t((j + shift) % 4)];
          same = std::abs(d.x) <= tol && std::abs(d.y) <= tol;
        }
        if (same) return other.contour;
      }
    }
    return -1;
  };
  // quad_fit, for contour i.
  auto fit = [&](int i) {
    Quad q;
    auto why = stages::fit_quad(contours[size_t(i)], work_size, p, &q, contour_factor[size_t(i)], timed);
    if (why) fine_shape(i);
    if (!why && coarse > 0 && contour_factor[size_t(i)] == coarse)
      if (const int twin = found_before(q); twin >= 0)
        why = Rejection{Stage::quad_fit, "coarse_factor", 0, double(p.coarse_factor),
                        "the same quad as contour " + std::to_string(twin) + ", found by the first search"};
    if (why) {
      if (timed) add_record(i, std::move(why));
      return;
    }
    const int rec = timed ? add_record(i, std::nullopt) : -1;
    if (rec >= 0) {
      t.candidates[size_t(rec)].has_quad = true;
      t.candidates[size_t(rec)].quad = q;
    }
    quads.push_back({rec, i, q});
  };
  for (int i : size_passed) fit(i);
  close_stage(Stage::quad_fit, int(size_passed.size()), int(quads.size()));

  // nested_filter over quads[from..]: the quads that stay (live), and per quad the one that replaced it or -1.
  std::vector<int> replaced_by;
  auto nest = [&](size_t from) {
    std::vector<Quad> quad_list;
    std::vector<int> factors;
    for (size_t i = from; i < quads.size(); ++i) {
      quad_list.push_back(quads[i].quad);
      factors.push_back(contour_factor[size_t(quads[i].contour)]);
    }
    const std::vector<int> by = stages::nested_filter(quad_list, p, &factors);
    std::vector<int> live;
    replaced_by.resize(quads.size(), -1);
    for (size_t j = 0; j < by.size(); ++j) {
      const size_t i = from + j;
      if (by[j] < 0) {
        live.push_back(int(i));
        continue;
      }
      const int outer = int(from) + by[j];
      replaced_by[i] = outer;
      if (quads[i].record >= 0)
        t.candidates[size_t(quads[i].record)].fate =
            Rejection{Stage::nested_filter, "min_marker_distance_rate", 0, p.min_marker_distance_rate,
                      // The contour's number only where the trace keeps the contours (the full one): below it,
                      // fine_search leaves some untraced and the numbers after them differ.
                      "same border as " +
                          (full ? "the quad of contour " + std::to_string(quads[size_t(outer)].contour)
                                : std::string("another quad")) +
                          " (closer than min_marker_distance_rate), kept as the outer one or the finer search's"};
    }
    return live;
  };
  const std::vector<int> live = nest(0);
  close_stage(Stage::nested_filter, int(quads.size()), int(live.size()));

  // Step 2: read each quad, once per distinct marker size.
  std::vector<int> sizes;
  for (const auto& d : dictionaries_)
    if (std::find(sizes.begin(), sizes.end(), d.marker_size()) == sizes.end()) sizes.push_back(d.marker_size());

  // readings[i] belongs to quads[i]; a quad merged into an outer one is read only when the outer one is no marker
  // (a white quiet zone on a grey page makes a quad one cell outside the marker).
  std::vector<Reading> readings(quads.size());
  // read_at: quad q read at marker size n into r, from perspective_removal to identification, `lap` timing each
  // stage. As found (the quad's corners unrefined, read before corner_refinement to decide whether to refine it):
  // no quiet zone, and the nearest id may miss by unrefined_miss_rate x the code's bits more than the budget.
  auto read_at = [&](const Quad& q, int n, bool as_found, Reading& r, auto&& lap) {
    const int cells = n + 2;
    const char* found = as_found ? " (read as found, before corner_refinement)" : "";
    r.record.read_as_found = as_found;
    cv::Mat warp = stages::remove_perspective(grey, q, cells, p);
    lap(1);
    r.reached = 1;
    const stages::OtsuResult o = stages::otsu(warp);
    r.record.otsu_threshold = o.threshold;
    r.record.stddev = o.stddev;
    if (full) {
      r.record.warp = warp;
      r.record.histogram.assign(o.histogram.begin(), o.histogram.end());
    }
    lap(2);
    if (o.stddev < p.otsu_min_stddev) {
      r.record.fate = Rejection{Stage::otsu, "otsu_min_stddev", o.stddev, p.otsu_min_stddev,
                                fmt_msg("grey stddev %.1f < otsu_min_stddev %.1f: uniform patch", o.stddev,
                                        p.otsu_min_stddev) + found};
      return;
    }
    r.reached = 2;
    cv::Mat bits = stages::sample_bits(warp, cells, o.threshold, p);
    if (full) r.record.bits = bits;
    lap(3);
    r.record.border_errors = stages::border_errors(bits);
    r.record.border_cells = 4 * (cells - 1);
    const int allowed = static_cast<int>(p.border_max_error_rate * r.record.border_cells);
    // A black border inside a larger dark shape (a piece of some other pattern) has no light quiet zone.
    const stages::QuietZone quiet = as_found || r.record.border_errors > allowed || p.quiet_zone_max_dark_rate >= 1
                                        ? stages::QuietZone{}
                                        : stages::quiet_zone(grey, q, cells, o);
    lap(4);
    if (r.record.border_errors > allowed) {
      r.reached = 3;
      r.record.fate = Rejection{Stage::border_check, "border_max_error_rate", double(r.record.border_errors),
                                double(allowed),
                                fmt_msg("%.0f white border cells > border_max_error_rate x %.0f = %.0f",
                                        r.record.border_errors, r.record.border_cells, allowed) + found};
      return;
    }
    if (quiet.dark_share > p.quiet_zone_max_dark_rate) {
      // The side as it lies on screen: where its middle is from the quad's centre.
      const cv::Point2f mid = 0.5f * (q[size_t(quiet.side)] + q[size_t((quiet.side + 1) % 4)]);
      const cv::Point2f off = mid - 0.25f * (q[0] + q[1] + q[2] + q[3]);
      const char* where = std::abs(off.x) > std::abs(off.y) ? (off.x > 0 ? "right" : "left")
                                                            : (off.y > 0 ? "bottom" : "top");
      r.reached = 3;
      r.record.fate = Rejection{
          Stage::border_check, "quiet_zone_max_dark_rate", quiet.dark_share, p.quiet_zone_max_dark_rate,
          fmt_msg("%.0f %% of the quiet zone dark > quiet_zone_max_dark_rate %.0f %%", 100 * quiet.dark_share,
                  100 * p.quiet_zone_max_dark_rate) +
              " along its " + where + " side: part of a larger dark shape"};
      return;
    }
    r.reached = 4;
    // As found, a read may miss by this many bits more than the budget (the corners are off by up to the
    // decimation's factor, so cells near the border are sampled across it).
    const int slack = as_found ? static_cast<int>(p.unrefined_miss_rate * n * n + 1e-9) : 0;
    const uint64_t code = stages::inner_code(bits);
    DictMatch nearest{-1, 0, 65};
    int nearest_dict = -1;
    for (int di = 0; di < int(dictionaries_.size()); ++di) {
      const Dictionary& d = dictionaries_[size_t(di)];
      if (d.marker_size() != n) continue;
      const DictMatch m = d.nearest(code);
      if (nearest_dict < 0 || m.hamming < nearest.hamming) {
        nearest = m;
        nearest_dict = di;
        if (timed) r.record.per_rotation = d.nearest_per_rotation(code);
      }
      if (m.hamming <= stages::correction_budget(d, p) + slack) break;  // first dictionary that claims it
    }
    const Dictionary& d = dictionaries_[size_t(nearest_dict)];
    r.record.dict = d.name();
    const int budget = stages::correction_budget(d, p);
    if (nearest.hamming > budget + slack) {
      r.record.fate =
          as_found ? Rejection{Stage::identification, "unrefined_miss_rate", double(nearest.hamming),
                               double(budget + slack),
                               fmt_msg("nearest id %.0f is %.0f bits away > budget %.0f", nearest.id,
                                       nearest.hamming, budget) +
                                   fmt_msg(" + unrefined_miss_rate x %.0f bits = %.0f", n * n, budget + slack) +
                                   found}
                   : Rejection{Stage::identification, "error_correction_rate", double(nearest.hamming),
                               double(budget),
                               fmt_msg("nearest id %.0f is %.0f bits away > budget %.0f (error_correction_rate"
                                       " x max_correction_bits)",
                                       nearest.id, nearest.hamming, budget)};
    } else {
      r.reached = 5;
      r.dict_index = nearest_dict;
      r.match = nearest;
      for (int j = 0; j < 4; ++j) r.corners[size_t(j)] = q[size_t((j + nearest.rotation) % 4)];
    }
    lap(5);
  };
  // A quad is read as found first, where refinement is on and unrefined_miss_rate < 1; only if that read could
  // be a marker are its corners refined and it is read again. Stopped there, its fate says so; either read's time
  // counts to its stages.
  const bool read_first = p.corner_refinement && p.unrefined_miss_rate < 1;
  auto read_one = [&](size_t k) {
    const Quad& quad = quads[k].quad;
    Reading best;
    best.reached = -1;
    for (int n : sizes) {
      Reading r;
      auto t0 = Clock::now();
      auto lap = [&](int stage_slot) {
        if (!timed) return;
        const auto now = Clock::now();
        r.ms[size_t(stage_slot)] += std::chrono::duration<double, std::milli>(now - t0).count();
        t0 = now;
      };
      bool refine = true;
      if (read_first) {
        read_at(quad, n, true, r, lap);
        refine = r.reached == 5;
        if (refine) {
          Reading again;
          again.ms = r.ms;
          r = std::move(again);
        }
      }
      if (refine) {
        Quad q = quad;
        stages::refine_corners(grey, q, n + 2, p, contour_factor[size_t(quads[k].contour)]);
        lap(0);
        read_at(q, n, false, r, lap);
      }
      if (r.reached > best.reached) best = std::move(r);
      if (best.reached == 5) break;
    }
    readings[k] = std::move(best);
  };

  const int nthreads = std::clamp(threads, 1, 64);
  auto read_all = [&](const std::vector<int>& which) {
    if (nthreads == 1 || which.size() < 2) {
      for (int k : which) read_one(size_t(k));
      return;
    }
    std::atomic<size_t> next{0};
    auto worker = [&] {
      for (size_t i; (i = next.fetch_add(1)) < which.size();) read_one(size_t(which[i]));
    };
    std::vector<std::thread> pool;
    for (int i = 1; i < std::min<int>(nthreads, int(which.size())); ++i) pool.emplace_back(worker);
    worker();
    for (auto& th : pool) th.join();
  };
  // The quads of `live` and then those of quads[from..] merged into one of them that is no marker.
  std::vector<int> read;
  auto read_live = [&](const std::vector<int>& kept_quads, size_t from) {
    read_all(kept_quads);
    std::vector<int> retry;
    for (size_t i = from; i < quads.size(); ++i)
      if (replaced_by[i] >= 0 && readings[size_t(replaced_by[i])].reached != 5) retry.push_back(int(i));
    read_all(retry);
    read.insert(read.end(), kept_quads.begin(), kept_quads.end());
    read.insert(read.end(), retry.begin(), retry.end());
  };
  // What reading a quad looks at: its corners' refinement reaches out (subpix_window_px + 1 a pass, a decimated
  // quad's first pass its factor), the quiet zone half a cell outside.
  auto need_around = [&](size_t from) {
    const int reach = (p.subpix_window_px + 1) * (p.subpix_max_iterations + 2) + 2 * factor + 4;
    for (size_t i = from; i < quads.size(); ++i) {
      const Quad& q = quads[i].quad;
      const cv::Rect box = cv::boundingRect(std::vector<cv::Point2f>(q.begin(), q.end()));
      const int margin = std::max(box.width, box.height) / 8 + reach;
      need(cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin));
    }
  };
  need_around(0);
  read_live(live, 0);

  // fine_search: the decimated search's small shapes that quad_fit could not close or that did not read, searched
  // again at full resolution, where a small marker's border and cells are sharp. The contours traced there (its
  // `in`) go through size_filter, quad_fit and nested_filter, and the quads left (its `out`) are read as the others:
  // the per-candidate stages count them too; below the full trace the shapes cut by a region's edge are counted in
  // `in` untraced. A contour it drops has its fate here, with the parameter that decided.
  // Its own time is the search, fit and filter.
  StageRecord fine_record{Stage::fine_search, 0, 0, 0, {}};
  if (fine_on) {
    const auto fine_start = Clock::now();
    for (int k : read)
      if (readings[size_t(k)].reached != 5 && contour_factor[size_t(quads[size_t(k)].contour)] == factor) {
        const Quad& q = quads[size_t(k)].quad;
        fine_shapes.push_back(cv::boundingRect(std::vector<cv::Point2f>(q.begin(), q.end())));
      }
    // The quad-shaped holes of the first search's dark shapes, outside the markers read (their cells are their
    // holes): looked for now that those are known. A marker's own shape is looked into too: a small marker whose
    // quiet zone closed may have joined it, its inside a hole outside the marker.
    std::vector<Quad> markers;
    for (int k : read)
      if (readings[size_t(k)].reached == 5) markers.push_back(quads[size_t(k)].quad);
    for (const Searched& s : searched) {
      std::vector<cv::Rect> dark;
      for (size_t i = s.first; i < s.last; ++i) dark.push_back(cv::boundingRect(contours[i]));
      for (const cv::Rect& b : stages::quad_holes(s.binary, dark, s.region.tl(), grey.size(), p, factor, markers))
        if (!stages::cut_by_region(b, s.region, grey.size(), factor)) fine_shapes.push_back(b);
    }
    const std::vector<cv::Rect> fine = stages::plan_fine_search(fine_shapes, grey.size(), p);
    if (full && !fine.empty()) fine_record.image = cv::Mat::zeros(grey.size(), CV_8UC1);
    const size_t quads_before = quads.size(), records_before = t.candidates.size();
    double converting = 0;
    for (const cv::Rect& r : fine) {
      converting += need(r);
      const cv::Mat binary = stages::adaptive_threshold(grey(r), p);
      // A shape cut by the region's edge is dropped as it is found (size_filter's first test): untraced, and
      // counted, unless the full trace shows it.
      int untraced = 0;
      std::vector<std::vector<cv::Point>> found = stages::find_contours(
          binary, p.min_perimeter_px, nullptr, nullptr, 1, 0,
          full ? std::function<bool(const cv::Rect&)>()
               : [&](const cv::Rect& box) {
                   const bool cut_here = stages::cut_by_region(box + r.tl(), r, grey.size(), 1);
                   untraced += cut_here;
                   return !cut_here;
                 });
      fine_record.in += int(found.size()) + untraced;
      for (auto& c : found) {
        for (cv::Point& pt : c) pt += r.tl();
        cut.push_back(stages::cut_by_region(cv::boundingRect(c), r, grey.size(), 1));
        contours.push_back(std::move(c));
        contour_factor.push_back(1);
        const int i = int(contours.size()) - 1;
        if (size_ok(i)) fit(i);
      }
      if (full) binary.copyTo(fine_record.image(r));
    }
    const std::vector<int> fine_live = nest(quads_before);
    for (size_t k = records_before; k < t.candidates.size(); ++k) {
      Rejection& f = t.candidates[k].fate;
      if (f.stage == Stage::accepted) continue;   // a quad, read next
      f.stage = Stage::fine_search;
      if (f.param == "region_margin_rate") f.message = "cut by the edge of its region of the fine search";
    }
    fine_record.out = int(fine_live.size());
    fine_record.ms = ms_since(fine_start) - converting;
    readings.resize(quads.size());
    need_around(quads_before);
    read_live(fine_live, quads_before);
  }

  if (timed) {
    // Counts: how many readings entered each per-candidate stage and how many left it (the next one's entry).
    std::array<int, kCandidateStageCount + 1> entered{};
    std::array<double, kCandidateStageCount> ms{};
    for (int k : read) {
      const Reading& r = readings[size_t(k)];
      for (int s = 0; s < kCandidateStageCount; ++s) ms[size_t(s)] += r.ms[size_t(s)];
      // reached: 1 warped, 2 past otsu, 3 border rejected, 4 identification tried, 5 identified. A quad stopped
      // in its read as found leaves at the stage that stopped it, as if refined: corner_refinement's in and out
      // are the quads read, and corner_refinement and perspective_removal drop nothing.
      entered[0]++;
      if (r.reached >= 1) entered[1]++, entered[2]++;
      if (r.reached >= 2) entered[3]++, entered[4]++;
      if (r.reached >= 4) entered[5]++;
      if (r.reached >= 5) entered[6]++;
    }
    for (int s = 0; s < kCandidateStageCount; ++s)
      t.stages.push_back(StageRecord{kCandidateStages[s], ms[size_t(s)], entered[size_t(s)],
                                     entered[size_t(s + 1)], {}});
    t.stages.push_back(std::move(fine_record));
    stage_start = Clock::now();
  }

  // Step 3: duplicates. A marker inside another marker keeps the larger one. The same id seen twice in one place
  // keeps the reading of the finer search (its quad started nearer the corners: the coarse search's blocks of eight
  // pixels can start a low-contrast quad on a shadow's edge), or of the two from one search the larger.
  std::vector<size_t> accepted;
  for (int k : read)
    if (readings[size_t(k)].reached == 5) accepted.push_back(size_t(k));
  std::sort(accepted.begin(), accepted.end(), [&](size_t a, size_t b) {
    const double pa = quad_perimeter(readings[a].corners), pb = quad_perimeter(readings[b].corners);
    return pa != pb ? pa > pb : a < b;
  });
  std::vector<size_t> kept;
  std::vector<std::string> dup_reason(readings.size());
  for (size_t k : accepted) {
    const Reading& r = readings[k];
    const cv::Point2f centre = quad_centre(r.corners);
    bool drop = false;
    for (size_t& o : kept) {
      const Reading& big = readings[o];
      std::vector<cv::Point2f> poly(big.corners.begin(), big.corners.end());
      const bool inside = cv::pointPolygonTest(poly, centre, false) >= 0;
      if (inside) {
        drop = true;
        const bool same = r.dict_index == big.dict_index && r.match.id == big.match.id;
        if (same && contour_factor[size_t(quads[k].contour)] < contour_factor[size_t(quads[o].contour)]) {
          dup_reason[o] = "id " + std::to_string(r.match.id) + " read by a finer search here";
          o = k;
          break;
        }
        dup_reason[k] = same ? "id " + std::to_string(r.match.id) + " already found here"
                             : "inside marker " + std::to_string(big.match.id);
        break;
      }
    }
    if (!drop) kept.push_back(k);
  }
  std::sort(kept.begin(), kept.end(), [&](size_t a, size_t b) {
    const Reading &ra = readings[a], &rb = readings[b];
    if (ra.dict_index != rb.dict_index) return ra.dict_index < rb.dict_index;
    if (ra.match.id != rb.match.id) return ra.match.id < rb.match.id;
    return a < b;
  });
  std::vector<Marker> markers;
  markers.reserve(kept.size());
  for (size_t k : kept) {
    const Reading& r = readings[k];
    Marker m;
    m.id = r.match.id;
    m.dict = dictionaries_[size_t(r.dict_index)].name();
    m.hamming = r.match.hamming;
    m.rotation = r.match.rotation;
    for (int j = 0; j < 4; ++j) {
      // Working pixels to input pixels, pixel centres at integers in both.
      const cv::Point2f c = r.corners[size_t(j)];
      m.corners[size_t(j)] = cv::Point2f(float((c.x + 0.5) * t.scale_x - 0.5), float((c.y + 0.5) * t.scale_y - 0.5));
    }
    markers.push_back(m);
  }
  close_stage(Stage::duplicates, int(accepted.size()), int(kept.size()));

  if (timed) {
    for (int ki : read) {
      const size_t k = size_t(ki);
      const int rec = quads[k].record;
      if (rec < 0) continue;
      CandidateRecord& dst = t.candidates[size_t(rec)];
      CandidateRecord& src = readings[k].record;
      dst.warp = std::move(src.warp);
      dst.otsu_threshold = src.otsu_threshold;
      dst.stddev = src.stddev;
      dst.histogram = std::move(src.histogram);
      dst.bits = std::move(src.bits);
      dst.border_errors = src.border_errors;
      dst.border_cells = src.border_cells;
      dst.dict = std::move(src.dict);
      dst.read_as_found = src.read_as_found;
      dst.per_rotation = src.per_rotation;
      dst.fate = std::move(src.fate);
      if (readings[k].reached == 5 && !dup_reason[k].empty())
        dst.fate = Rejection{Stage::duplicates, "", 0, 0, dup_reason[k]};
    }
    for (int mi = 0; mi < int(kept.size()); ++mi) {
      const int rec = quads[kept[size_t(mi)]].record;
      if (rec >= 0) t.candidates[size_t(rec)].marker = mi;
    }
    if (full) t.contours = std::move(contours);
  }
  t.markers = markers;
  t.total_ms = ms_since(frame_start);
  return markers;
}

}  // namespace arwb
