// The detector's step 1, find the quads: the search (decimation, adaptive_threshold, contours) over each region,
// coarse_search, size_filter, quad_fit and nested_filter.
#include "detect/detector_run.hpp"

#include <opencv2/imgproc.hpp>

#include <charconv>

namespace arwb {

void DetectorRun::search() {
  // Once per region. The search's pictures are kept at the decimated size (the views stretch them over the frame);
  // with regions, the parts outside them are black.
  std::array<double, 3> ms{};
  cv::Mat search_picture, binary_picture;
  const bool one_region = plan_.regions.size() == 1 && plan_.regions[0].size() == grey().size();
  if (full_ && !one_region) {
    search_picture = cv::Mat::zeros(grey().rows / factor_, grey().cols / factor_, CV_8UC1);
    binary_picture = search_picture.clone();
  }
  for (const cv::Rect& r : plan_.regions) {
    const cv::Mat search = stages::search_image(on_demand_, r, factor_);
    ms[0] += clock_.lap();
    const cv::Mat binary = stages::adaptive_threshold(search, p_, one_region ? &whole_blocks_ : nullptr);
    ms[1] += clock_.lap();
    std::vector<stages::SmallRegion> region_small;
    std::vector<stages::SmallRegion>* small_out = !full_ ? nullptr : one_region ? &small_ : &region_small;
    int region_count = 0;
    std::vector<std::vector<cv::Point>> found =
        stages::find_contours(binary, p_.min_perimeter_px, timed_ ? &region_count : nullptr, small_out, factor_);
    regions_ += region_count;
    const size_t first = contours_.size();
    if (one_region) {
      contours_ = std::move(found);
      found.clear();
      cut_.assign(contours_.size(), 0);
    }
    for (auto& c : found) {   // a region's contours, moved to the frame's pixels
      for (cv::Point& pt : c) pt += r.tl();
      cut_.push_back(stages::cut_by_region(cv::boundingRect(c), r, grey().size(), factor_));
      contours_.push_back(std::move(c));
    }
    if (fine_on_) searched_.push_back({r, binary, first, contours_.size()});
    for (auto& sm : region_small) {
      sm.bbox += r.tl();
      small_.push_back(sm);
    }
    ms[2] += clock_.lap();
    if (one_region) whole_search_ = search;
    if (full_) {
      if (one_region) {
        search_picture = search;
        binary_picture = binary;
      } else {
        const cv::Rect at(r.x / factor_, r.y / factor_, search.cols, search.rows);
        const cv::Rect inside = at & cv::Rect(0, 0, search_picture.cols, search_picture.rows);
        const cv::Rect from(inside.tl() - at.tl(), inside.size());
        search(from).copyTo(search_picture(inside));
        binary(from).copyTo(binary_picture(inside));
      }
    }
  }
  const int n = int(plan_.regions.size());
  clock_.record({Stage::decimation, ms[0], n, n, search_picture});
  clock_.record({Stage::adaptive_threshold, ms[1], n, n, binary_picture});
  clock_.record({Stage::contours, ms[2], n, regions_, {}});
  contour_factor_.assign(contours_.size(), factor_);
}

void DetectorRun::coarse_search() {
  // The whole frame once more, coarser, for large markers (a frame searched by regions is already searched at its
  // markers' scale). Its contours join the others, each keeping the factor it was found at.
  const int fine_regions = regions_;
  cv::Mat binary;
  if (plan_.whole && coarse_ > 0 && std::min(grey().cols, grey().rows) / coarse_ >= 32)
    for (auto& c : stages::coarse_search(whole_search_, whole_blocks_, coarse_, p_, &binary)) {
      ++regions_;
      contours_.push_back(std::move(c));
      cut_.push_back(0);
      contour_factor_.push_back(coarse_);
    }
  clock_.close(Stage::coarse_search, fine_regions, regions_, binary);
}

int DetectorRun::add_record(int i, std::optional<Rejection> fate) {
  CandidateRecord r;
  const auto& c = contours_[size_t(i)];
  r.contour = full_ ? i : -1;
  r.bbox = cv::boundingRect(c);
  r.perimeter = stages::contour_length(c, contour_factor_[size_t(i)]);
  if (fate) r.fate = std::move(*fate);
  t_.candidates.push_back(std::move(r));
  return int(t_.candidates.size()) - 1;
}

void DetectorRun::fine_shape(int i) {
  // Its box in the grey image's pixels (a contour's points are block centres: its box covers whole blocks).
  if (!fine_on_ || contour_factor_[size_t(i)] != factor_) return;
  const cv::Rect b = cv::boundingRect(contours_[size_t(i)]);
  const int h = (factor_ - 1) / 2;
  fine_shapes_.emplace_back(b.x - h, b.y - h, b.width + factor_ - 1, b.height + factor_ - 1);
}

bool DetectorRun::size_ok(int i) {
  if (cut_[size_t(i)]) {
    if (full_)
      add_record(i, Rejection{Stage::size_filter, "region_margin_rate", 0, p_.region_margin_rate,
                              "cut by the edge of its search region (region_margin_rate): a marker there is "
                              "searched whole on the next full search"});
    return false;
  }
  if (auto why = stages::size_filter(contours_[size_t(i)], grey().size(), p_, full_, contour_factor_[size_t(i)])) {
    if (why->param == "min_perimeter_px") fine_shape(i);
    if (full_) add_record(i, std::move(why));
    return false;
  }
  return true;
}

void DetectorRun::filter_sizes() {
  // One record per traced contour and, at full, per region too small to trace (thousands at full resolution): made
  // in place, not moved again as the list grows.
  if (timed_) t_.candidates.reserve(contours_.size() + small_.size());
  if (full_) {
    // Regions too small to trace: their box bounds the border they could have.
    for (const auto& s : small_) {
      CandidateRecord& r = t_.candidates.emplace_back();
      r.bbox = s.bbox;
      const int border = 2 * (s.bbox.width + s.bbox.height);
      r.perimeter = border;
      r.fate.stage = Stage::size_filter;
      r.fate.param = "min_perimeter_px";
      r.fate.value = r.perimeter;
      r.fate.limit = p_.min_perimeter_px;
      // "border <= 12 px": short enough to live in the string itself (no allocation a speck); the fate's
      // parameter, value and limit say what it was compared with.
      char text[32] = "border <= ";
      char* end = std::to_chars(text + 10, text + 26, border).ptr;
      *end++ = ' ';
      *end++ = 'p';
      *end++ = 'x';
      r.fate.message.assign(text, size_t(end - text));
    }
  }
  for (int i = 0; i < int(contours_.size()); ++i)
    if (size_ok(i)) size_passed_.push_back(i);
  clock_.close(Stage::size_filter, regions_, int(size_passed_.size()));
}

int DetectorRun::found_before(const Quad& q) const {
  const float tol = 2.0f * float(coarse_);
  for (const auto& other : quads_) {
    if (contour_factor_[size_t(other.contour)] == coarse_) continue;
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
}

void DetectorRun::fit(int i, bool may_split) {
  Quad q;
  bool cut = false;
  auto why = stages::fit_quad(contours_[size_t(i)], grey().size(), p_, &q, contour_factor_[size_t(i)], timed_, &cut);
  // A part of a split shape is not searched again finer: its shape is, when it is small enough.
  if (why && may_split) fine_shape(i);
  const bool split = may_split && why && why->param == "polygon_epsilon_rate" && p_.split_thin_lines_px > 0;
  // A quad of the coarse search that the first search found too is not read twice.
  if (!why && coarse_ > 0 && contour_factor_[size_t(i)] == coarse_)
    if (const int twin = found_before(q); twin >= 0)
      why = Rejection{Stage::quad_fit, "coarse_factor", 0, double(p_.coarse_factor),
                      "the same quad as contour " + std::to_string(twin) + ", found by the first search"};
  if (why) {
    const int rec = timed_ ? add_record(i, std::move(why)) : -1;
    if (split) to_split_.emplace_back(i, rec);
    return;
  }
  const int rec = timed_ ? add_record(i, std::nullopt) : -1;
  if (rec >= 0) {
    t_.candidates[size_t(rec)].has_quad = true;
    t_.candidates[size_t(rec)].quad = q;
  }
  quads_.push_back({rec, i, q, cut, !may_split});
}

int DetectorRun::fit_parts() {
  const std::vector<std::pair<int, int>> shapes = std::move(to_split_);
  to_split_.clear();
  int parts = 0;
  for (const auto& [i, rec] : shapes) {
    const int f = contour_factor_[size_t(i)];
    std::vector<std::vector<cv::Point>> found = stages::split_thin_lines(contours_[size_t(i)], f, p_);
    if (rec >= 0 && !found.empty())
      t_.candidates[size_t(rec)].fate.message +=
          fmt_msg("; split at lines up to %g px wide (split_thin_lines_px): %.0f parts fitted again",
                  p_.split_thin_lines_px, double(found.size()));
    // A part too short or too long for size_filter is dropped untraced: a line's end, or the rest of the shape.
    for (auto& c : found)
      if (!stages::size_filter(c, grey().size(), p_, false, f)) {
        contours_.push_back(std::move(c));
        contour_factor_.push_back(f);
        cut_.push_back(cut_[size_t(i)]);
        ++parts;
        fit(int(contours_.size()) - 1, false);
      }
  }
  return parts;
}

void DetectorRun::fit_quads() {
  for (int i : size_passed_) fit(i);
  const int parts = fit_parts();
  clock_.close(Stage::quad_fit, int(size_passed_.size()) + parts, int(quads_.size()));
}

std::vector<int> DetectorRun::nest(size_t from) {
  std::vector<Quad> quad_list;
  std::vector<int> factors;
  for (size_t i = from; i < quads_.size(); ++i) {
    quad_list.push_back(quads_[i].quad);
    factors.push_back(contour_factor_[size_t(quads_[i].contour)]);
  }
  const std::vector<int> by = stages::nested_filter(quad_list, p_, &factors);
  std::vector<int> live;
  replaced_by_.resize(quads_.size(), -1);
  for (size_t j = 0; j < by.size(); ++j) {
    const size_t i = from + j;
    if (by[j] < 0) {
      live.push_back(int(i));
      continue;
    }
    const int outer = int(from) + by[j];
    replaced_by_[i] = outer;
    if (quads_[i].record >= 0)
      t_.candidates[size_t(quads_[i].record)].fate =
          Rejection{Stage::nested_filter, "min_marker_distance_rate", 0, p_.min_marker_distance_rate,
                    // The contour's number only where the trace keeps the contours (the full one): below it,
                    // fine_search leaves some untraced and the numbers after them differ.
                    "same border as " +
                        (full_ ? "the quad of contour " + std::to_string(quads_[size_t(outer)].contour)
                               : std::string("another quad")) +
                        " (closer than min_marker_distance_rate), kept as the outer one or the finer search's"};
  }
  return live;
}

void DetectorRun::filter_nested() {
  live_ = nest(0);
  clock_.close(Stage::nested_filter, int(quads_.size()), int(live_.size()));
}

}  // namespace arwb
