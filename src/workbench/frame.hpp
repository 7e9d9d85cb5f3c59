// One finished frame as the workbench's worker publishes it: the acquired image, the detector's trace and what
// the peer detectors found on the same image. The UI draws only from this (through a const reference).
#pragma once

#include "track/overlay.hpp"
#include "calibration/calibration_file.hpp"
#include "calibration/session.hpp"
#include "capture/source.hpp"
#include "track/tracker.hpp"
#include "peers/match.hpp"
#include "detect/params.hpp"
#include "detect/trace.hpp"
#include "inspect/trace_view.hpp"
#include "synth/synth.hpp"

#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace arwb {

// Another detector's markers on the same frame (OpenCV's aruco, AprilTag), in arwb's corner convention.
struct PeerDetections {
  std::string name;           // "opencv_aruco", "apriltag"
  std::string dict;
  std::vector<Marker> markers;
  double ms = 0;
  std::string error;          // when it could not run on this dictionary
  // arwb's markers of `dict` against these by the one matching rule (detect/match.hpp, arwb the reference),
  // matched by the worker: `reference` indices point into the frame's trace.markers, `found` into `markers`.
  MarkerMatching matching;
  int other_dicts = 0;        // arwb markers of other dictionaries, not compared
};

struct Frame {
  uint64_t index = 0;         // increases by one per published frame
  double time_s = 0;          // worker clock when it was captured
  cv::Mat image;              // BGR, after acquisition (the working image)
  FrameTrace trace;
  // What the trace was detected with: panels interpret the frame by these, not by the current settings, which
  // may have changed since (a frozen frame, or a frame still in flight when a slider moved).
  DetectorParams params;
  std::vector<std::string> dictionaries;
  // One picture per stage for the pipeline panel and snapshots (trace_view.hpp), made by the worker from the
  // full trace: stage images where the pipeline has them, drawings of contours, quads, frontal views and grids
  // otherwise. Empty below the full level.
  std::array<cv::Mat, kStageCount> views;
  // How they were drawn (the window's presentation mode asks for wide outlines and draws their text itself) and
  // their text, which the window then draws over them.
  StageViewStyle view_style;
  StageLabels view_labels;
  // The same, and the working image, shrunk to fit 192x144 for thumbnails: uploading full-size pictures of every
  // stage 20 times a second would cost a software renderer more than drawing the whole UI.
  std::array<cv::Mat, kStageCount> thumbs;
  cv::Mat image_thumb;
  std::vector<PeerDetections> peers;
  std::vector<TruthMarker> truth;   // synthetic source only, in working-image pixels
  SourceInfo source;
  double capture_ms = 0;      // reading the source (acquisition is the detector's first stage, timed in the trace)
  double detect_ms = 0;       // Detector::detect, trace included
  // The scene (Lua or XML database): markers over time, the media it places on this frame and its state.
  std::vector<TrackedMarker> tracks;
  // The camera the tracks' poses were computed with (the loaded calibration, or default_calibration's assumed
  // values for this frame's size) and the marker side they are in units of.
  Calibration pose_camera;
  double pose_marker_side = 1;
  std::string pose_unit = "marker sides";   // "mm" when a printed size was given (--marker-size, a bundle's)
  std::vector<Overlay> overlays;
  SceneStatus scene;
  // Calibration. The session's state while the Calibrate workspace is shown (null otherwise: no board is looked
  // for then); the board is found in `image`'s pixels.
  std::shared_ptr<const CalibrationSnapshot> calibration;
  // The name this frame's image was given to the board search under: the snapshot's detection is of this frame
  // when its frame_name is the same (the search runs behind the frames).
  std::string calibration_name;
  // The calibration given with --calib, made for this frame's size; null without one (or when it does not
  // fit the source: the log says why).
  std::shared_ptr<const Calibration> loaded_calibration;
  // The synthetic source's camera while it shows a calibration board, in the source's own pixels (where the board
  // is searched and solved): the truth a solve is compared with.
  std::optional<Calibration> calibration_truth;
  // `image` undistorted with the newest solve (or else the loaded calibration), when asked for and there is one;
  // `undistorted_by` says which ("the solve of 14 views", "cam.yml").
  cv::Mat undistorted;
  std::string undistorted_by;
};

// What the window calls the frame: a video's or folder's own number, as its slider says it ("frame 2", "image 2";
// the published count would say 25), else the count of frames published ("frame 25").
inline std::string frame_label(const Frame& f) {
  if (f.source.kind == SourceKind::video) return "frame " + std::to_string(f.source.position);
  if (f.source.kind == SourceKind::folder) return "image " + std::to_string(f.source.position);
  return "frame " + std::to_string(f.index);
}

}  // namespace arwb
