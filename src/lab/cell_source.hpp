// One cell of a lab plan as a frame source: its frames exactly as the run rendered them (LabFrameRenderer), one
// at a time, so the workbench shows them in the live view with their full trace, the marker's truth beside them,
// and "Why not detected?" can be asked of any frame a detector missed. Paused on a frame until stepped or sought;
// playing shows one frame a second (times the speed), as a folder of images does.
#pragma once

#include "lab/run.hpp"
#include "synth/truth_source.hpp"

#include <string>
#include <vector>

namespace arwb::lab {

// How a cell is named everywhere (the Lab panel, the source's name, the log): "26 mm at 2 m, 500 lx", with the
// added axes other than their defaults ("20 px at 1 m, 850 lx, tilt 60, blur 1.5").
std::string cell_name(const Cell& cell);

class LabCellSource : public TruthSource {
 public:
  // `ids` as the run drew them (LabResults::ids or lab_marker_ids); starts on `frame`.
  LabCellSource(const LabPlan& plan, const LabOptions& options, std::vector<int> ids, size_t cell_index,
                int frame = 0);
  SourceStatus next(double now_s, cv::Mat& out) override;
  SourceInfo info() const override;
  void set_playback(const Playback& p) override { playback_ = p; }
  void step(int delta) override;
  void seek(int position) override;
  const std::vector<TruthMarker>& truth() const override { return truth_; }
  // The frame shown last (its marker, pose, whether it is one of the empty frames).
  const LabFrame& frame() const { return frame_; }

 private:
  LabFrameRenderer renderer_;
  std::string dictionary_;
  size_t cell_index_;
  Cell cell_;
  int position_ = 0, shown_ = -1;
  Playback playback_{false, true, 1.0};
  double last_advance_s_ = -1;
  LabFrame frame_;
  std::vector<TruthMarker> truth_;
};

}  // namespace arwb::lab
