// `arwb bench --pose`: the pose of one rendered marker of known pose (synth/marker_view.hpp) as arwb gives it
// (Detector + estimate_marker_pose) and as OpenCV does (detectMarkers, default and ArUco3 mode, then solvePnP
// with IPPE_SQUARE) on the same frames, the camera known; and what resolve_with_previous buys along a smooth
// synthetic sequence.
#pragma once

namespace arwb {

struct PoseBenchOptions {
  int frames = 400;            // single frames
  int sequence_frames = 200;   // frames in each of the three sequences; at least 2
  int seed = 1;
  bool json = false;
};

// Prints the table (or one JSON object) and returns the exit status.
int run_pose_bench(const PoseBenchOptions& options);

}  // namespace arwb
