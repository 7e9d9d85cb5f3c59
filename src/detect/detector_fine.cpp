// The detector's fine_search: on a decimated search, the small shapes that did not close or read, and the
// quad-shaped holes of its dark shapes, searched again at full resolution, where a small marker's border and cells
// are sharp; the quads found there are read as the others.
#include "detect/detector_run.hpp"

#include <opencv2/imgproc.hpp>

namespace arwb {

void DetectorRun::fine_search() {
  // The contours traced here (its `in`) go through size_filter, quad_fit and nested_filter, and the quads left (its
  // `out`) are read as the others: the reading stages count them too. Below the full trace the shapes cut by a
  // region's edge are counted in `in` untraced. A contour it drops has its fate here, with the parameter that
  // decided. Its own time is the search, fit and filter.
  if (!fine_on_) return;
  const auto start = StageClock::Clock::now();
  for (int k : read_)
    if (readings_[size_t(k)].reached != 5 && !quads_[size_t(k)].part &&
        contour_factor_[size_t(quads_[size_t(k)].contour)] == factor_) {
      const Quad& q = quads_[size_t(k)].quad;
      fine_shapes_.push_back(cv::boundingRect(std::vector<cv::Point2f>(q.begin(), q.end())));
    }
  // The quad-shaped holes of the first search's dark shapes, outside the markers read (their cells are their
  // holes): looked for now that those are known. A marker's own shape is looked into too: a small marker whose
  // quiet zone closed may have joined it, its inside a hole outside the marker.
  std::vector<Quad> markers;
  for (int k : read_)
    if (readings_[size_t(k)].reached == 5) markers.push_back(quads_[size_t(k)].quad);
  for (const Searched& s : searched_) {
    std::vector<cv::Rect> dark;
    for (size_t i = s.first; i < s.last; ++i) dark.push_back(cv::boundingRect(contours_[i]));
    for (const cv::Rect& b : stages::quad_holes(s.binary, dark, s.region.tl(), grey().size(), p_, factor_, markers))
      if (!stages::cut_by_region(b, s.region, grey().size(), factor_)) fine_shapes_.push_back(b);
  }
  const std::vector<cv::Rect> fine = stages::plan_fine_search(fine_shapes_, grey().size(), p_);
  if (full_ && !fine.empty()) fine_record_.image = cv::Mat::zeros(grey().size(), CV_8UC1);
  const size_t quads_before = quads_.size(), records_before = t_.candidates.size();
  double converting = 0;
  DetectorParams threshold = p_;
  threshold.threshold_offset = p_.fine_threshold_offset;
  for (const cv::Rect& r : fine) {
    converting += need(r);
    const cv::Mat binary = stages::adaptive_threshold(grey()(r), threshold);
    // A shape cut by the region's edge is dropped as it is found (size_filter's first test): untraced, and
    // counted, unless the full trace shows it.
    int untraced = 0;
    std::vector<std::vector<cv::Point>> found = stages::find_contours(
        binary, p_.min_perimeter_px, nullptr, nullptr, 1, 0,
        full_ ? std::function<bool(const cv::Rect&)>()
              : [&](const cv::Rect& box) {
                  const bool cut_here = stages::cut_by_region(box + r.tl(), r, grey().size(), 1);
                  untraced += cut_here;
                  return !cut_here;
                });
    fine_record_.in += int(found.size()) + untraced;
    for (auto& c : found) {
      for (cv::Point& pt : c) pt += r.tl();
      cut_.push_back(stages::cut_by_region(cv::boundingRect(c), r, grey().size(), 1));
      contours_.push_back(std::move(c));
      contour_factor_.push_back(1);
      const int i = int(contours_.size()) - 1;
      if (size_ok(i)) fit(i);
    }
    if (full_) binary.copyTo(fine_record_.image(r));
  }
  fine_record_.in += fit_parts();
  const std::vector<int> fine_live = nest(quads_before);
  for (size_t k = records_before; k < t_.candidates.size(); ++k) {
    Rejection& f = t_.candidates[k].fate;
    if (f.stage == Stage::accepted) continue;   // a quad, read next
    f.stage = Stage::fine_search;
    if (f.param == "region_margin_rate") f.message = "cut by the edge of its region of the fine search";
  }
  fine_record_.out = int(fine_live.size());
  fine_record_.ms = StageClock::ms_since(start) - converting;
  readings_.resize(quads_.size());
  need_around(quads_before);
  read_live(fine_live, quads_before);
}

}  // namespace arwb
