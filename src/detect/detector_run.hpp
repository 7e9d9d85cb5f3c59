// One frame's detection: the state the detector's steps share, from the grey image to the markers, and the steps
// themselves in the order Detector::detect runs them (the trace's). Internal to the detector: detector.cpp drives it,
// detector_find.cpp, detector_read.cpp and detector_fine.cpp hold the steps.
#pragma once

#include "detect/detector.hpp"
#include "detect/pipeline.hpp"
#include "detect/stage_clock.hpp"

#include <array>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace arwb {

// A trace message with up to three numbers.
inline std::string fmt_msg(const char* f, double a, double b, double c = 0) {
  char buf[200];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

// The per-candidate stages in the order a quad is read, whose times are summed over candidates.
inline constexpr Stage kReadingStages[] = {Stage::corner_refinement, Stage::perspective_removal, Stage::otsu,
                                           Stage::bit_grid, Stage::border_check, Stage::identification};
inline constexpr int kReadingStageCount = static_cast<int>(std::size(kReadingStages));

// What reading one quad produced.
struct Reading {
  CandidateRecord record;
  int dict_index = -1;
  DictMatch match;
  Quad corners{};   // the marker's own order, refined, working pixels
  std::array<double, kReadingStageCount> ms{};
  // How far it got: 1 warped, 2 past otsu, 3 border rejected, 4 identification tried, 5 identified (a marker).
  // Of the marker sizes tried, the reading that got furthest is kept.
  int reached = 0;
};

class DetectorRun {
 public:
  DetectorRun(const Detector& detector, FrameTrace& trace, TraceLevel level, int threads);

  // Step 1: find the quads.
  void acquire(const cv::Mat& image, cv::Mat* acquired);   // acquisition
  void plan_search(const SearchHint* hint);                 // search_regions
  void search();              // decimation, adaptive_threshold, contours: once per region
  void coarse_search();
  void filter_sizes();        // size_filter
  void fit_quads();           // quad_fit
  void filter_nested();       // nested_filter
  // Step 2: read them (corner_refinement .. identification); on a decimated search, fine_search.
  void read_quads();
  void fine_search();
  void record_reading();      // the reading stages' records, and fine_search's
  // Step 3: one marker per id and place, in the input image's pixels.
  std::vector<Marker> drop_duplicates();

 private:
  struct QuadCandidate {
    int record;   // index into the trace's candidates, or -1 when not traced
    int contour;
    Quad quad;
    bool cut = false;   // quad_fit cut it from thin lines (cut_thin_lines)
    bool part = false;  // of a shape split at thin lines (split_thin_lines): not searched again finer
  };
  // A region the first search searched, for fine_search's holes: its binary image and its contours' indices.
  struct Searched {
    cv::Rect region;
    cv::Mat binary;
    size_t first, last;
  };

  const cv::Mat& grey() const { return on_demand_.image(); }
  // Grey pixels a later stage looks at, converted now: acquisition's time. Returns it in milliseconds.
  double need(const cv::Rect& r);
  // A trace record for contour i with its fate (none: a quad, read next); its index.
  int add_record(int i, std::optional<Rejection> fate);
  // size_filter for contour i: true when it goes on to quad_fit.
  bool size_ok(int i);
  // quad_fit for contour i: its quad joins quads_, or its fate is recorded. A shape refused for its corners is
  // queued for split_thin_lines, unless it is a part of one (`may_split` false), and is one of fine_search's shapes.
  void fit(int i, bool may_split = true);
  // quad_fit's split_thin_lines: the parts of the shapes fit() queued, fitted in turn; their number.
  int fit_parts();
  // fine_search's shapes: a contour of the first search that did not close.
  void fine_shape(int i);
  // The contour of an earlier quad of the first search with these corners (to two coarse pixels), or -1.
  int found_before(const Quad& q) const;
  // nested_filter over quads_[from..]: the quads that stay; replaced_by_ says which replaced the others.
  std::vector<int> nest(size_t from);
  // Reading quad q at marker size n into r, from perspective_removal to identification; `as_found`: before
  // corner_refinement (unrefined_miss_rate). `lap(slot)` times each stage.
  template <class Lap>
  void read_at(const Quad& q, int n, bool as_found, bool cut, Reading& r, Lap&& lap) const;
  double bar_aspect(const Quad& q, const cv::Mat& bits) const;
  template <class Lap>
  void judge(const Quad& q, int n, bool as_found, bool cut, const cv::Mat& bits, const stages::OtsuResult* o,
             Reading& r, Lap&& lap) const;
  void read_one(size_t k);
  void read_all(const std::vector<int>& which);
  // Reads the quads of `kept` and then those of quads_[from..] merged into one that is no marker.
  void read_live(const std::vector<int>& kept, size_t from);
  // Converts the grey pixels reading quads_[from..] looks at.
  void need_around(size_t from);
  // The trace's candidate records of the quads read, from their readings; `dup_reason`: duplicates' fates.
  void record_readings(const std::vector<size_t>& kept, const std::vector<std::string>& dup_reason);

  const Detector& detector_;
  const DetectorParams& p_;
  FrameTrace& t_;
  const bool timed_, full_;
  const int threads_;
  StageClock clock_;

  stages::GreyOnDemand on_demand_;
  stages::SearchPlan plan_;
  int factor_ = 1;   // the first search's decimation
  int coarse_ = 0;   // the grey image's pixels a coarse search's pixel spans, 0 when there is none
  bool fine_on_ = false;

  std::vector<std::vector<cv::Point>> contours_;
  std::vector<char> cut_;            // per contour: cut by its region's edge
  std::vector<int> contour_factor_;  // per contour: the decimation it was found at
  std::vector<stages::SmallRegion> small_;
  int regions_ = 0;
  std::vector<Searched> searched_;
  cv::Mat whole_search_;   // the first search's image of the whole frame, when it searched the whole frame
  cv::Mat whole_blocks_;   // and its 2x2 block means, the threshold's (empty when its window took none)
  std::vector<cv::Rect> fine_shapes_;

  std::vector<int> size_passed_;
  std::vector<std::pair<int, int>> to_split_;   // fit()'s queue for split_thin_lines: contour, record (or -1)
  std::vector<QuadCandidate> quads_;
  std::vector<int> replaced_by_;
  std::vector<int> live_;

  std::vector<int> sizes_;           // the distinct marker sizes of the dictionaries
  std::vector<Reading> readings_;    // readings_[i] belongs to quads_[i]
  std::vector<int> read_;            // the quads read, in order
  StageRecord fine_record_{Stage::fine_search, 0, 0, 0, {}};
};

}  // namespace arwb
