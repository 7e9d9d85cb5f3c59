// The detector's step 2, read the quads: corner_refinement, perspective_removal, otsu, bit_grid, border_check and
// identification per quad, once per marker size, spread over threads; and the reading stages' records.
#include "detect/detector_run.hpp"

#include <opencv2/imgproc.hpp>

#include <atomic>
#include <thread>

namespace arwb {

// As found (the quad's corners unrefined, read before corner_refinement to decide whether to refine it): no quiet
// zone, and the nearest id may miss by unrefined_miss_rate x the code's bits more than the budget.
template <class Lap>
void DetectorRun::read_at(const Quad& q, int n, bool as_found, bool cut, Reading& r, Lap&& lap) const {
  const int cells = n + 2;
  const char* found = as_found ? " (read as found, before corner_refinement)" : "";
  r.record.read_as_found = as_found;
  cv::Mat warp = stages::remove_perspective(grey(), q, cells, p_);
  lap(1);
  r.reached = 1;
  const stages::OtsuResult o = stages::otsu(warp);
  r.record.otsu_threshold = o.threshold;
  r.record.stddev = o.stddev;
  if (full_) {
    r.record.warp = warp;
    r.record.histogram.assign(o.histogram.begin(), o.histogram.end());
  }
  lap(2);
  if (o.stddev < p_.otsu_min_stddev) {
    r.record.fate = Rejection{Stage::otsu, "otsu_min_stddev", o.stddev, p_.otsu_min_stddev,
                              fmt_msg("grey stddev %.1f < otsu_min_stddev %.1f: uniform patch", o.stddev,
                                      p_.otsu_min_stddev) + found};
    return;
  }
  r.reached = 2;
  cv::Mat bits = stages::sample_bits(warp, cells, o.threshold, p_);
  if (full_) r.record.bits = bits;
  lap(3);
  judge(q, n, as_found, cut, bits, &o, r, lap);
  // One threshold could not read it: read again with bit_grid's local thresholds, kept if that gets further.
  if (r.reached < 3 || r.reached == 5 || !p_.local_thresholds) return;
  auto read_again = [&](const cv::Mat& again_bits, const stages::OtsuResult* quiet) {
    Reading again;
    again.record = r.record;   // the view, its histogram and threshold; the fate is the new read's
    again.record.fate = Rejection{};
    again.record.local_thresholds = true;
    again.record.bits = full_ ? again_bits : cv::Mat();
    again.reached = 2;
    judge(q, n, as_found, cut, again_bits, quiet, again, lap);
    if (again.reached <= r.reached) return;
    again.ms = r.ms;
    r = std::move(again);
  };
  stages::LocalRead local = stages::read_local(grey(), q, warp, cells, p_);
  lap(3);
  if (local.ok && !local.stripe) read_again(local.bits, nullptr);
  // Planes through the cells' levels, for a view still missing its id, when it is viewed densely (view_scale > 1):
  // a small view's cell means blur into their neighbours', and planes through them read tiny markers as other ids.
  if (r.reached != 4 || warp.rows == cells * p_.warp_cell_px) return;
  const cv::Mat shaded = stages::read_shaded(warp, cells, bits, p_);
  lap(3);
  if (!shaded.empty()) read_again(shaded, &o);
}

// How many times as long as it is wide quad q is along the stripes its bits' inside reads as, when that is at least
// bar_min_aspect_rate (a bar's inside); 0 otherwise. The view's columns run from q[0] to q[1], its rows from q[0]
// to q[3] (square_to_quad). Judged on refined corners only: an unrefined small quad's sides are a pixel or two
// off, which moves its aspect by a third at 10 px.
double DetectorRun::bar_aspect(const Quad& q, const cv::Mat& bits) const {
  if (p_.bar_min_aspect_rate <= 0) return 0;
  const stages::Stripes s = stages::inner_stripes(bits);
  if (s == stages::Stripes::none) return 0;
  auto side = [&](int j) { return double(cv::norm(q[size_t((j + 1) % 4)] - q[size_t(j)])); };
  const double across = side(0) + side(2), down = side(1) + side(3);
  const double aspect = s == stages::Stripes::rows ? down / std::max(across, 1e-9) : across / std::max(down, 1e-9);
  return aspect >= p_.bar_min_aspect_rate ? aspect : 0;
}

// border_check and identification of bits read from quad q at marker size n. `o`: the view's Otsu result for the
// quiet zone check, or null when the bits' border ring already compared each cell with its quiet zone.
template <class Lap>
void DetectorRun::judge(const Quad& q, int n, bool as_found, bool cut, const cv::Mat& bits,
                        const stages::OtsuResult* o, Reading& r, Lap&& lap) const {
  const int cells = n + 2;
  const char* found = as_found ? " (read as found, before corner_refinement)" : "";
  const char* local = r.record.local_thresholds ? " (local_thresholds)" : "";
  r.record.border_errors = stages::border_errors(bits);
  r.record.border_cells = 4 * (cells - 1);
  // A quad cut from thin lines has its whole border black: the lines only darken, and the border is what says that
  // the region's edge there is a marker's (an outlined rectangle crossed by a line can read as a code inside).
  const int allowed = cut ? 0 : static_cast<int>(p_.border_max_error_rate * r.record.border_cells);
  // A black border inside a larger dark shape (a piece of some other pattern) has no light quiet zone.
  const stages::QuietZone quiet = !o || as_found || r.record.border_errors > allowed || p_.quiet_zone_max_dark_rate >= 1
                                      ? stages::QuietZone{}
                                      : stages::quiet_zone(grey(), q, cells, *o);
  lap(4);
  if (r.record.border_errors > allowed) {
    r.reached = 3;
    r.record.fate = Rejection{Stage::border_check, "border_max_error_rate", double(r.record.border_errors),
                              double(allowed),
                              (cut ? fmt_msg("%.0f white border cells in a quad cut from thin lines (cut_thin_lines), "
                                             "which must have none", r.record.border_errors, 0)
                                   : fmt_msg("%.0f white border cells > border_max_error_rate x %.0f = %.0f",
                                             r.record.border_errors, r.record.border_cells, allowed)) +
                                  local + found};
    return;
  }
  if (quiet.dark_share > p_.quiet_zone_max_dark_rate) {
    // The side as it lies on screen: where its middle is from the quad's centre.
    const cv::Point2f mid = 0.5f * (q[size_t(quiet.side)] + q[size_t((quiet.side + 1) % 4)]);
    const cv::Point2f off = mid - 0.25f * (q[0] + q[1] + q[2] + q[3]);
    const char* where = std::abs(off.x) > std::abs(off.y) ? (off.x > 0 ? "right" : "left")
                                                          : (off.y > 0 ? "bottom" : "top");
    r.reached = 3;
    r.record.fate = Rejection{
        Stage::border_check, "quiet_zone_max_dark_rate", quiet.dark_share, p_.quiet_zone_max_dark_rate,
        fmt_msg("%.0f %% of the quiet zone dark > quiet_zone_max_dark_rate %.0f %%", 100 * quiet.dark_share,
                100 * p_.quiet_zone_max_dark_rate) +
            " along its " + where + " side: part of a larger dark shape"};
    return;
  }
  r.reached = 4;
  // As found, a read may miss by this many bits more than the budget (the corners are off by up to the
  // decimation's factor, so cells near the border are sampled across it).
  const int slack = as_found ? static_cast<int>(p_.unrefined_miss_rate * n * n + 1e-9) : 0;
  const uint64_t code = stages::inner_code(bits);
  const std::vector<Dictionary>& dictionaries = detector_.dictionaries();
  DictMatch nearest{-1, 0, 65};
  int nearest_dict = -1;
  for (int di = 0; di < int(dictionaries.size()); ++di) {
    const Dictionary& d = dictionaries[size_t(di)];
    if (d.marker_size() != n) continue;
    const DictMatch m = d.nearest(code);
    if (nearest_dict < 0 || m.hamming < nearest.hamming) {
      nearest = m;
      nearest_dict = di;
      if (timed_) r.record.per_rotation = d.nearest_per_rotation(code);
    }
    if (m.hamming <= stages::correction_budget(d, p_) + slack) break;   // the first dictionary that claims it
  }
  const Dictionary& d = dictionaries[size_t(nearest_dict)];
  r.record.dict = d.name();
  const int budget = stages::correction_budget(d, p_);
  if (nearest.hamming > budget + slack) {
    r.record.fate =
        as_found ? Rejection{Stage::identification, "unrefined_miss_rate", double(nearest.hamming),
                             double(budget + slack),
                             fmt_msg("nearest id %.0f is %.0f bits away > budget %.0f", nearest.id, nearest.hamming,
                                     budget) +
                                 fmt_msg(" + unrefined_miss_rate x %.0f bits = %.0f", n * n, budget + slack) + local +
                                 found}
                 : Rejection{Stage::identification, "error_correction_rate", double(nearest.hamming),
                             double(budget),
                             fmt_msg("nearest id %.0f is %.0f bits away > budget %.0f (error_correction_rate"
                                     " x max_correction_bits)",
                                     nearest.id, nearest.hamming, budget) +
                                 local};
  } else if (const double along = as_found ? 0 : bar_aspect(q, bits); along > 0) {
    r.record.fate = Rejection{Stage::identification, "bar_min_aspect_rate", along, p_.bar_min_aspect_rate,
                              fmt_msg("id %.0f reads as stripes along a quad %.1f times as long as it is wide "
                                      "(bar_min_aspect_rate): a bar's inside, not a marker",
                                      nearest.id, along) +
                                  local};
  } else {
    r.reached = 5;
    r.dict_index = nearest_dict;
    r.match = nearest;
    for (int j = 0; j < 4; ++j) r.corners[size_t(j)] = q[size_t((j + nearest.rotation) % 4)];
  }
  lap(5);
}

// A quad is read as found first, where refinement is on and unrefined_miss_rate < 1; only if that read could be a
// marker are its corners refined and it is read again. Stopped there, its fate says so; either read's time counts to
// its stages.
void DetectorRun::read_one(size_t k) {
  const bool read_first = p_.corner_refinement && p_.unrefined_miss_rate < 1;
  const Quad& quad = quads_[k].quad;
  Reading best;
  best.reached = -1;
  for (int n : sizes_) {
    Reading r;
    auto t0 = StageClock::Clock::now();
    auto lap = [&](int stage_slot) {
      if (!timed_) return;
      const auto now = StageClock::Clock::now();
      r.ms[size_t(stage_slot)] += std::chrono::duration<double, std::milli>(now - t0).count();
      t0 = now;
    };
    bool refine = true;
    if (read_first) {
      read_at(quad, n, true, quads_[k].cut, r, lap);
      refine = r.reached == 5;
      if (refine) {
        Reading again;
        again.ms = r.ms;
        r = std::move(again);
      }
    }
    if (refine) {
      Quad q = quad;
      stages::refine_corners(grey(), q, n + 2, p_, contour_factor_[size_t(quads_[k].contour)]);
      lap(0);
      read_at(q, n, false, quads_[k].cut, r, lap);
    }
    if (r.reached > best.reached) best = std::move(r);
    if (best.reached == 5) break;
  }
  readings_[k] = std::move(best);
}

void DetectorRun::read_all(const std::vector<int>& which) {
  if (threads_ == 1 || which.size() < 2) {
    for (int k : which) read_one(size_t(k));
    return;
  }
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i; (i = next.fetch_add(1)) < which.size();) read_one(size_t(which[i]));
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < std::min<int>(threads_, int(which.size())); ++i) pool.emplace_back(worker);
  worker();
  for (auto& th : pool) th.join();
}

void DetectorRun::read_live(const std::vector<int>& kept, size_t from) {
  // A quad merged into an outer one is read only when the outer one is no marker (a white quiet zone on a grey page
  // makes a quad one cell outside the marker).
  read_all(kept);
  std::vector<int> retry;
  for (size_t i = from; i < quads_.size(); ++i)
    if (replaced_by_[i] >= 0 && readings_[size_t(replaced_by_[i])].reached != 5) retry.push_back(int(i));
  read_all(retry);
  read_.insert(read_.end(), kept.begin(), kept.end());
  read_.insert(read_.end(), retry.begin(), retry.end());
}

void DetectorRun::need_around(size_t from) {
  // What reading a quad looks at: its corners' refinement reaches out (subpix_window_px + 1 a pass, a decimated
  // quad's first pass its factor), the quiet zone half a cell outside.
  const int reach = (p_.subpix_window_px + 1) * (p_.subpix_max_iterations + 2) + 2 * factor_ + 4;
  for (size_t i = from; i < quads_.size(); ++i) {
    const Quad& q = quads_[i].quad;
    const cv::Rect box = cv::boundingRect(std::vector<cv::Point2f>(q.begin(), q.end()));
    const int margin = std::max(box.width, box.height) / 8 + reach;
    need(cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin));
  }
}

void DetectorRun::read_quads() {
  readings_.resize(quads_.size());
  need_around(0);
  read_live(live_, 0);
}

void DetectorRun::record_reading() {
  if (!timed_) return;
  // Counts: how many readings entered each reading stage and how many left it (the next one's entry).
  std::array<int, kReadingStageCount + 1> entered{};
  std::array<double, kReadingStageCount> ms{};
  for (int k : read_) {
    const Reading& r = readings_[size_t(k)];
    for (int s = 0; s < kReadingStageCount; ++s) ms[size_t(s)] += r.ms[size_t(s)];
    // A quad stopped in its read as found leaves at the stage that stopped it, as if refined: corner_refinement's
    // in and out are the quads read, and corner_refinement and perspective_removal drop nothing.
    entered[0]++;
    if (r.reached >= 1) entered[1]++, entered[2]++;
    if (r.reached >= 2) entered[3]++, entered[4]++;
    if (r.reached >= 4) entered[5]++;
    if (r.reached >= 5) entered[6]++;
  }
  for (int s = 0; s < kReadingStageCount; ++s)
    clock_.record({kReadingStages[s], ms[size_t(s)], entered[size_t(s)], entered[size_t(s + 1)], {}});
  clock_.record(std::move(fine_record_));
}

}  // namespace arwb
