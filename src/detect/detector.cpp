// The detector: the stages of pipeline.hpp chained over one frame, in three steps, filling the trace.
// Step 1, find the quads (acquisition .. nested_filter): whole-image work on the calling thread. The search
// (decimation .. contours) runs on the decimated image, coarse_search once more on a coarser one; their contours are
// mapped back at once, so from contours on everything is in the grey image's pixels.
// Step 2, read them (corner_refinement .. identification), per quad, spread over threads: first as found
// (unrefined_miss_rate), then refined where that read could be a marker. On a decimated search, fine_search then
// searches the small shapes that did not close or read again at full resolution, and its quads are read the same way.
// Step 3, duplicates: one marker per id and place, its corners mapped back to the input image.
// Each stage's time and counts are its own: the trace lists the stages in the order they run here.
#include "detect/detector.hpp"

#include "detect/detector_run.hpp"

namespace arwb {

Detector::Detector(std::vector<Dictionary> dictionaries, DetectorParams params)
    : dictionaries_(std::move(dictionaries)), params_(params) {}

std::vector<Marker> Detector::detect(const cv::Mat& image, FrameTrace* trace, TraceLevel level, int threads,
                                     cv::Mat* acquired, const SearchHint* hint) const {
  FrameTrace local;
  FrameTrace& t = trace ? *trace : local;
  t = FrameTrace{};
  t.level = trace ? level : TraceLevel::off;
  t.width = image.cols;
  t.height = image.rows;
  if (image.empty() || dictionaries_.empty()) {
    if (acquired) acquired->release();
    return {};
  }
  DetectorRun run(*this, t, t.level, threads);
  // Step 1: find the quads.
  run.acquire(image, acquired);
  run.plan_search(hint);
  run.search();
  run.coarse_search();
  run.filter_sizes();
  run.fit_quads();
  run.filter_nested();
  // Step 2: read them; on a decimated search, search again at full resolution where that found no marker.
  run.read_quads();
  run.fine_search();
  run.record_reading();
  // Step 3: one marker per id and place.
  return run.drop_duplicates();
}

DetectorRun::DetectorRun(const Detector& detector, FrameTrace& trace, TraceLevel level, int threads)
    : detector_(detector),
      p_(detector.params()),
      t_(trace),
      timed_(level != TraceLevel::off),
      full_(level == TraceLevel::full),
      threads_(std::clamp(threads, 1, 64)),
      clock_(trace, timed_, full_) {
  for (const auto& d : detector.dictionaries())
    if (std::find(sizes_.begin(), sizes_.end(), d.marker_size()) == sizes_.end()) sizes_.push_back(d.marker_size());
}

void DetectorRun::acquire(const cv::Mat& image, cv::Mat* acquired) {
  // A colour frame is made grey where the stages look (GreyOnDemand); the full trace shows all of it.
  on_demand_ = stages::acquire_on_demand(image, detector_.acquisition(), &t_.scale_x, &t_.scale_y, acquired);
  if (full_) on_demand_.need_all();
  t_.work_width = grey().cols;
  t_.work_height = grey().rows;
  if (acquired) {
    // The caller works in the acquired image: it is the input from here on.
    t_.width = grey().cols;
    t_.height = grey().rows;
    t_.scale_x = t_.scale_y = 1;
  }
  clock_.close(Stage::acquisition, 1, 1, grey());
}

double DetectorRun::need(const cv::Rect& r) {
  if (on_demand_.colour().empty()) return 0.0;
  const auto t0 = StageClock::Clock::now();
  on_demand_.need(r);
  return clock_.charge_to_acquisition(StageClock::Clock::now() - t0);
}

void DetectorRun::plan_search(const SearchHint* hint) {
  // The whole frame, or around the markers earlier frames found (working pixels). One frame in, its regions out.
  std::vector<Quad> known;
  if (hint && hint->why_full.empty())
    for (const Quad& q : hint->known) {
      Quad w;
      for (int j = 0; j < 4; ++j)
        w[size_t(j)] = cv::Point2f(float((q[size_t(j)].x + 0.5) / t_.scale_x - 0.5),
                                   float((q[size_t(j)].y + 0.5) / t_.scale_y - 0.5));
      known.push_back(w);
    }
  plan_ = stages::plan_search(grey().size(), known, p_);
  factor_ = plan_.factor;
  coarse_ = p_.coarse_factor > 1 ? factor_ * p_.coarse_factor : 0;
  fine_on_ = factor_ > 1 && p_.fine_max_side_px > 0;
  if (timed_) {
    t_.search.whole = plan_.whole;
    t_.search.regions = plan_.regions;
    t_.search.factor = plan_.factor;
    t_.search.known = hint ? int(hint->known.size()) : 0;
    const std::string scale = factor_ == 1 ? std::string("every pixel") : "decimated " + std::to_string(factor_) + "x";
    t_.search.why = !hint ? "whole frame: a single image, " + scale
                    : !hint->why_full.empty() ? "whole frame: " + hint->why_full + ", " + scale
                    : plan_.whole ? "whole frame: no marker known, " + scale
                                  : "around " + std::to_string(known.size()) + " marker" +
                                        (known.size() == 1 ? "" : "s") + " of the previous frame, " + scale;
  }
  clock_.close(Stage::search_regions, 1, int(plan_.regions.size()));
}

std::vector<Marker> DetectorRun::drop_duplicates() {
  std::vector<stages::FoundMarker> found;
  std::vector<size_t> reading_of;   // per found marker, its reading
  for (int k : read_)
    if (readings_[size_t(k)].reached == 5) {
      const Reading& r = readings_[size_t(k)];
      found.push_back({r.corners, r.dict_index, r.match.id, contour_factor_[size_t(quads_[size_t(k)].contour)],
                       size_t(k)});
      reading_of.push_back(size_t(k));
    }
  std::vector<std::string> reasons;
  const std::vector<size_t> kept_found = stages::drop_duplicates(found, &reasons);
  std::vector<size_t> kept;
  std::vector<std::string> dup_reason(readings_.size());
  for (size_t i : kept_found) kept.push_back(reading_of[i]);
  for (size_t i = 0; i < found.size(); ++i) dup_reason[reading_of[i]] = std::move(reasons[i]);
  std::vector<Marker> markers;
  markers.reserve(kept.size());
  for (size_t k : kept) {
    const Reading& r = readings_[k];
    Marker m;
    m.id = r.match.id;
    m.dict = detector_.dictionaries()[size_t(r.dict_index)].name();
    m.hamming = r.match.hamming;
    m.rotation = r.match.rotation;
    for (int j = 0; j < 4; ++j) {
      // Working pixels to input pixels, pixel centres at integers in both.
      const cv::Point2f c = r.corners[size_t(j)];
      m.corners[size_t(j)] =
          cv::Point2f(float((c.x + 0.5) * t_.scale_x - 0.5), float((c.y + 0.5) * t_.scale_y - 0.5));
    }
    markers.push_back(m);
  }
  clock_.close(Stage::duplicates, int(found.size()), int(kept.size()));
  if (timed_) record_readings(kept, dup_reason);
  t_.markers = markers;
  t_.total_ms = clock_.frame_ms();
  return markers;
}

void DetectorRun::record_readings(const std::vector<size_t>& kept, const std::vector<std::string>& dup_reason) {
  for (int ki : read_) {
    const size_t k = size_t(ki);
    const int rec = quads_[k].record;
    if (rec < 0) continue;
    CandidateRecord& dst = t_.candidates[size_t(rec)];
    CandidateRecord& src = readings_[k].record;
    dst.warp = std::move(src.warp);
    dst.otsu_threshold = src.otsu_threshold;
    dst.stddev = src.stddev;
    dst.histogram = std::move(src.histogram);
    dst.bits = std::move(src.bits);
    dst.border_errors = src.border_errors;
    dst.border_cells = src.border_cells;
    dst.dict = std::move(src.dict);
    dst.read_as_found = src.read_as_found;
    dst.local_thresholds = src.local_thresholds;
    dst.per_rotation = src.per_rotation;
    dst.fate = std::move(src.fate);
    if (readings_[k].reached == 5 && !dup_reason[k].empty())
      dst.fate = Rejection{Stage::duplicates, "", 0, 0, dup_reason[k]};
  }
  for (int mi = 0; mi < int(kept.size()); ++mi) {
    const int rec = quads_[kept[size_t(mi)]].record;
    if (rec >= 0) t_.candidates[size_t(rec)].marker = mi;
  }
  if (full_) t_.contours = std::move(contours_);
}

}  // namespace arwb
