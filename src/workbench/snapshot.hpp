// A snapshot of one frame for a bug report or a lesson: the frame, every stage image, the candidates' frontal
// views and bit grids, and the trace as JSON, in a new folder of their own.
#pragma once

#include "detect/trace.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <string>
#include <vector>

namespace arwb {

struct SnapshotResult {
  bool ok = false;
  std::string dir;                 // the folder made, even when a later write failed
  std::vector<std::string> files;  // written, relative to dir ("frame.png", "03_contours.png", "trace.json" ...: the stage number, then its name)
  std::string error;               // when !ok: what failed, naming the path
};

// Makes parent_dir/snapshot-YYYYMMDD-HHMMSS (local time), or -2, -3 ... when that exists (an existing folder is
// never written into), creating parent_dir if needed, and writes: frame.png; NN_<stage_name>.png for each stage
// with a picture (NN the stage's index; the stage view from `views` when given (trace_view.hpp), else the image
// the trace kept); candidates/NNN_warp.png and NNN_bits.png (NNN the candidate's index) for
// candidates with a frontal view; trace.json (trace_to_json). Never throws.
SnapshotResult write_snapshot(const std::string& parent_dir, const cv::Mat& frame, const FrameTrace& trace,
                              const std::array<cv::Mat, kStageCount>* views = nullptr);

}  // namespace arwb
