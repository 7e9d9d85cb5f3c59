// "Why isn't my marker detected?": given a region of a frame (the rectangle a user drags on the live view),
// say what became of everything the pipeline saw there, whether it is a marker of a dictionary that is not
// searched, and find the smallest parameter change that makes a marker appear in it.
#pragma once

#include "detect/detector.hpp"
#include "detect/params.hpp"
#include "detect/trace.hpp"

#include <opencv2/core.hpp>

#include <atomic>
#include <functional>
#include <string>
#include <vector>

namespace arwb {

struct RegionCandidate {
  int index = -1;          // into FrameTrace::candidates
  Rejection fate;          // fate.stage == Stage::accepted for markers
  int marker_id = -1;      // when accepted
  std::string line;        // one line for the UI: "#12 quad 48x50 px: otsu: stddev 3.1 < otsu_min_stddev 5"
};

// A candidate that reads as a marker of a predefined dictionary the detector does not search.
struct OtherDictionary {
  int candidate = -1;      // into FrameTrace::candidates
  std::string dict;        // the predefined name, "6X6_250"
  int id = -1;
  int hamming = 0;         // bits corrected, within that dictionary's budget under the same parameters
  int in_frame = 0;        // candidates of the whole frame that read in this dictionary
};

struct RegionReport {
  cv::Rect2f region;                       // working-image pixels, clipped to the frame
  std::vector<RegionCandidate> candidates; // every candidate whose contour or quad overlaps the region: markers
                                           // first, then the ones covering the region best (largest
                                           // intersection over union of their box with it), then by stage
  // Filled by the overload that knows the searched dictionaries, when nothing is detected here: the first is
  // the advice ("this is a 6X6_250 marker, id 23: add that dictionary"), the others the other readings.
  std::vector<OtherDictionary> other_dictionaries;
  std::string advice;                      // with other_dictionaries: "This is a 6X6_250 marker, id 23 ..."; the
                                           // summary starts with it
  // When no candidate overlaps: the earliest stage that had nothing there (adaptive_threshold: no foreground
  // pixels; contours: no border long enough to be traced; size_filter; quad_fit). Stage::accepted otherwise.
  // A summary trace cannot tell the first three apart: size_filter, the latest it can be. A trace at level off
  // records no stages: acquisition.
  Stage lost_at = Stage::accepted;
  std::string summary;                     // one or two sentences for the UI
};

// Needs a full-level trace (stage images and every contour); with a summary trace it says so in `summary`.
RegionReport explain_region(const FrameTrace& trace, cv::Rect2f region);
// The same, and when nothing is detected in the region, its candidates read as every predefined dictionary not
// in `searched` (names as the detector was given them) under `params`: the summary then names the dictionary
// and id before any parameter advice.
RegionReport explain_region(const FrameTrace& trace, cv::Rect2f region, const DetectorParams& params,
                            const std::vector<std::string>& searched);

// The region's candidates (`candidates`, indices into trace.candidates, best first) read as the predefined
// dictionaries not in `searched`. Each quad of the frame is read once per marker size (4x4 to 7x7) from the
// trace's grey image and looked up in every dictionary of that size, instead of re-running the detector per
// dictionary. The first entry is the advice: the first candidate that reads at all, in the dictionary that
// reads the most candidates of the frame (the smallest such dictionary on ties, so a photograph of ids up to
// 203 reads as 6X6_250, not 6X6_50 or 6X6_1000). Empty below the full level (no grey image).
std::vector<OtherDictionary> read_other_dictionaries(const FrameTrace& trace, const std::vector<int>& candidates,
                                                     const DetectorParams& params,
                                                     const std::vector<std::string>& searched);

struct SweepChange {
  std::string param;       // a parameter table name
  double from = 0, to = 0;
};

struct SweepResult {
  bool found = false;
  std::vector<SweepChange> changes;   // the smallest change found (one parameter, or two when none alone works)
  Marker marker;                      // the marker it revealed in the region
  int runs = 0;                       // detector runs made
  std::string message;                // "threshold_offset 7 -> 4 finds ARUCO_ORIGINAL id 12" or why none did
  std::string add_dictionary;         // the change is no parameter but this dictionary, added to the searched
};

// First reads the region's candidates as the predefined dictionaries the detector does not search (one run with
// a full trace): a marker of another dictionary is found by adding it, not by any parameter. Then tries each
// parameter of the table over its range, nearest values first, and reports the change that is
// smallest relative to the parameter's range and makes a marker whose centre lies in `region` detected.
// `image` is the working image the trace came from. `progress` (0..1) and `cancel` may be null; the sweep
// stops early when cancel becomes true.
SweepResult sweep_region(const cv::Mat& image, const Detector& detector, cv::Rect2f region,
                         std::function<void(double)> progress = {}, const std::atomic<bool>* cancel = nullptr);

}  // namespace arwb
