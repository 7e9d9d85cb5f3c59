// The WebAssembly core's detector: what the phone player's worker calls, as plain C++ that knows nothing of
// JavaScript (exports.cpp is the thin C layer emscripten exports). It runs the desktop's own Detector on frames the
// page hands over as RGBA (a canvas's pixels), so a bundle finds on a phone what it finds on the desktop.
#pragma once
#include "calibration/calibration_file.hpp"
#include "detect/detector.hpp"
#include "detect/video_search.hpp"

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <string>
#include <vector>

namespace arwb::web {

class WebDetector {
 public:
  WebDetector();   // ARUCO_ORIGINAL, the desktop's default parameters
  // "NAME[,NAME...]" as `arwb detect --dict` takes them. Empty on success, else the message naming what was wrong;
  // the dictionaries in use are then unchanged.
  std::string set_dictionaries(const std::string& list);
  // One parameter of the detector's table by its name, as presets, sliders and Lua set it. Empty or the message.
  std::string set_param(const std::string& name, double value);
  // The camera poses are computed with: the calibration file at `path` (read as the desktop reads it; the page puts
  // the bundle's file there first), fitted to each frame's size as `arwb detect --calib` fits it, or with "" the
  // paper's default camera for the frame's size (marked assumed). `marker_side` > 0: each marker gains its pose with
  // tvec in that unit; 0: no poses. Empty on success, else the message (the camera is then unchanged).
  std::string set_camera(const std::string& path, double marker_side);
  // The frame buffer the page writes into: width * height * 4 bytes of RGBA, kept until the next call.
  uint8_t* frame(int width, int height);
  // Detects in the frame last written, as the desktop's live view does: in video mode (detect/video_search.hpp),
  // around the last frame's markers, and the whole frame every full_search_interval frames (1: always, as `arwb
  // detect` searches still images). The result as one JSON object: {"width","height","ms","markers":[{"id",
  // "dict","corners":[[x,y] x4],"hamming"[,"pose"]}],"stages":{name: ms}} with corners at full precision in the
  // frame's pixels and each stage's time from the trace; or {"error": "..."} when there is no frame. With a
  // camera, "pose": {"rvec","tvec","error_px","ambiguity","alternative":{"rvec","tvec","error_px"},"camera":
  // "assumed"|"calibrated","axes":[[x,y] x4]}, as `arwb detect --json --marker-size` gives it, at full precision,
  // with the image points of the marker's origin and the ends of its x, y and z axes (one side long, through the
  // lens, as the workbench draws them); a calibration that
  // does not fit the frame's size gives "camera_error" instead of poses.
  const std::string& detect();

  // The markers of the last detect(), and its frame's size.
  const std::vector<Marker>& markers() const { return markers_; }
  cv::Size frame_size() const { return {width_, height_}; }
  // The camera for a frame of this size (the calibration fitted to it, or the default camera), or null and the
  // reason it has none.
  const Calibration* camera_for(int width, int height, std::string* error);
  // The markers' side poses are measured in (0: no poses).
  double marker_side() const { return marker_side_; }

 private:

  std::unique_ptr<Detector> detector_;
  VideoSearch video_;   // forgotten when the dictionaries or a parameter change
  std::optional<Calibration> calibration_;   // read from set_camera's path; none: the default camera
  double marker_side_ = 0;
  std::map<std::pair<int, int>, Result<Calibration>> sized_;   // by frame size
  std::vector<uint8_t> rgba_;
  int width_ = 0, height_ = 0;
  std::vector<Marker> markers_;
  std::string result_;
};

}  // namespace arwb::web
