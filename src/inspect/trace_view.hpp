// Pictures of a frame's trace, one per stage: what the pipeline panel shows as thumbnails and what a snapshot
// writes as PNGs. The pipeline itself never draws; this reads its trace afterwards.
//
// Stages that work on the whole image are drawn at the working image's size, so they line up pixel for pixel
// with the live view: acquisition (grey), adaptive_threshold (binary), contours, size_filter, quad_fit,
// nested_filter, corner_refinement and duplicates (drawings over a dimmed frame). Stages that work on each
// candidate's frontal view are mosaics of tiles, one per candidate that reached them: perspective_removal,
// otsu, bit_grid, border_check and identification.
#pragma once

#include "detect/trace.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <string>
#include <vector>

namespace arwb {

// True for the stages drawn as mosaics of per-candidate tiles (not aligned with the frame).
bool stage_view_is_mosaic(Stage s);

// `in` shrunk to fit `fit` for a thumbnail: the mean of each k x k block, k the smallest whole number that fits
// (OpenCV's area resize has a fast path for whole-number factors, and the worker makes 18 thumbnails a frame);
// the last columns and rows that make no whole block, fewer than k, are left out. Empty in, empty out.
void thumbnail(const cv::Mat& in, cv::Mat& out, cv::Size fit = {192, 144});

// One line saying what a stage's picture shows on this frame where the picture alone could mislead, "" for the
// others. decimation and adaptive_threshold: the factor the search ran at ("searched at 1/2 (320x240), ...", or
// "decimation factor 1: ... the grey image itself"), and whether only regions around the markers of the frame
// before were searched (the rest of the picture black).
std::string stage_view_caption(const FrameTrace& t, Stage s);

// A picture's text as data (a mosaic tile's "#12" above it and "37 d1" below, the duplicates' marker ids,
// "none") for a viewer that draws it in its own type over the picture: centred on `centre` (picture pixels,
// pixel centres at integers), within a strip `height` picture pixels tall (0: over the picture, no strip).
struct StageLabel {
  cv::Point2f centre;
  float height = 0;
  std::string text;
  cv::Vec3b colour{220, 220, 220};   // BGR, as drawn into the picture
};
using StageLabels = std::array<std::vector<StageLabel>, kStageCount>;

// How the pictures are drawn. The defaults suit a picture seen near its own size (a snapshot's PNG, the
// workbench's normal mode): outlines 1 px, the text drawn in. A projector asks for wider outlines (`line`
// picture pixels; corner marks and ids' boxes grow with it) and draws the text itself (`text` false: the label
// strips are left empty, twice as tall, room for the viewer's type).
struct StageViewStyle {
  int line = 1;
  bool text = true;
  bool operator==(const StageViewStyle&) const = default;
};

// Fills `out[stage]` for every stage the trace has (full level); others are left empty. BGR images. `labels`,
// when given, receives every picture's text, drawn in or not.
void render_stage_views(const cv::Mat& working_bgr, const FrameTrace& trace, std::array<cv::Mat, kStageCount>& out,
                        const StageViewStyle& style = {}, StageLabels* labels = nullptr);

}  // namespace arwb
