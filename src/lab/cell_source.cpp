#include "lab/cell_source.hpp"

#include "base/decimals.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace arwb::lab {

std::string cell_name(const Cell& cell) {
  // A sides_px plan's cell by its side (its printed size was derived from it), the added axes when not the default.
  std::string s = cell.side_px > 0 ? decimals_text(cell.side_px, 1) + " px" : decimals_text(cell.size_mm, 1) + " mm";
  s += " at " + decimals_text(cell.distance_m, 2) + " m, " + decimals_text(cell.lux, 0) + " lx";
  if (cell.tilt_deg >= 0) s += ", tilt " + decimals_text(cell.tilt_deg, 1);
  if (cell.blur_px > 0) s += ", blur " + decimals_text(cell.blur_px, 2);
  if (cell.noise > 0) s += ", noise " + decimals_text(cell.noise, 2);
  if (cell.occlusion > 0) s += ", occluded " + decimals_text(cell.occlusion, 2);
  return s;
}

LabCellSource::LabCellSource(const LabPlan& plan, const LabOptions& options, std::vector<int> ids,
                             size_t cell_index, int frame)
    : renderer_(plan, options, std::move(ids)), dictionary_(plan.dictionary), cell_index_(cell_index),
      position_(std::clamp(frame, 0, std::max(0, renderer_.frames_per_cell() - 1))) {
  const std::vector<Cell> cells = plan.cells(options.camera.camera_matrix(0, 0));
  if (cell_index < cells.size()) cell_ = cells[cell_index];
}

SourceStatus LabCellSource::next(double now_s, cv::Mat& out) {
  const int n = renderer_.frames_per_cell();
  if (playback_.playing && n > 0) {
    // One frame a second (times the speed), as a folder's images play.
    const double period = 1.0 / std::clamp(playback_.speed, 0.1, 8.0);
    if (last_advance_s_ < 0) last_advance_s_ = now_s;
    if (now_s - last_advance_s_ >= period) {
      last_advance_s_ = now_s;
      if (position_ + 1 < n) ++position_;
      else if (playback_.loop) position_ = 0;
    }
  }
  if (position_ == shown_) return {FrameStatus::same, {}};
  frame_ = renderer_.render(cell_index_, position_);
  shown_ = position_;
  truth_.clear();
  if (frame_.image.empty()) {
    // A frame whose marker could not be placed wholly in view is not one of the measure; shown as a plain grey
    // picture so stepping through the cell keeps its numbering.
    const cv::Size size = renderer_.camera_size();
    frame_.image = cv::Mat(size, CV_8UC3, cv::Scalar(128, 128, 128));
  } else if (!frame_.empty && frame_.visible) {
    truth_.push_back(TruthMarker{frame_.id, dictionary_, frame_.corners});
  }
  out = frame_.image.clone();
  return {FrameStatus::ok, {}};
}

SourceInfo LabCellSource::info() const {
  SourceInfo i;
  i.kind = SourceKind::lab;
  i.name = "lab: " + cell_name(cell_);
  i.size = renderer_.camera_size();
  i.position = position_;
  i.count = renderer_.frames_per_cell();
  char b[200];
  if (shown_ < 0) {
    i.item.clear();
  } else if (frame_.empty) {
    std::snprintf(b, sizeof b, "frame %d of %d: no marker (what a detector reports here is a false positive)",
                  shown_ + 1, i.count);
    i.item = b;
  } else if (!frame_.visible) {
    std::snprintf(b, sizeof b, "frame %d of %d: the marker could not be placed in view (not counted)", shown_ + 1,
                  i.count);
    i.item = b;
  } else {
    std::snprintf(b, sizeof b,
                  "frame %d of %d: %s id %d, turned %.0f deg, tilted %.0f deg about x and %.0f about y (%.0f in all)%s",
                  shown_ + 1, i.count, dictionary_.c_str(), frame_.id, frame_.roll_deg, frame_.tilt_x_deg,
                  frame_.tilt_y_deg, frame_.tilt_deg, frame_.occluded_side >= 0 ? ", one side covered" : "");
    i.item = b;
    if (const std::string light = frame_.light.text(); !light.empty()) i.item += "; " + light;
  }
  return i;
}

void LabCellSource::step(int delta) {
  playback_.playing = false;
  seek(position_ + delta);
}

void LabCellSource::seek(int position) {
  const int n = renderer_.frames_per_cell();
  position_ = n > 0 ? (playback_.loop ? ((position % n) + n) % n : std::clamp(position, 0, n - 1)) : 0;
}

}  // namespace arwb::lab
