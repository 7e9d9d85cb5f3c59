// The WebAssembly core's detector: what the phone player's worker calls, as plain C++ that knows nothing of
// JavaScript (exports.cpp is the thin C layer emscripten exports). It runs the desktop's own Detector on frames the
// page hands over as RGBA (a canvas's pixels), so a bundle finds on a phone what it finds on the desktop.
#pragma once
#include "detect/detector.hpp"

#include <cstdint>
#include <memory>
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
  // The frame buffer the page writes into: width * height * 4 bytes of RGBA, kept until the next call.
  uint8_t* frame(int width, int height);
  // Detects in the frame last written. The result as one JSON object: {"width","height","ms","markers":[{"id",
  // "dict","corners":[[x,y] x4],"hamming"}],"stages":{name: ms}} with corners at full precision in the frame's
  // pixels and each stage's time from the trace; or {"error": "..."} when there is no frame.
  const std::string& detect();

 private:
  std::unique_ptr<Detector> detector_;
  std::vector<uint8_t> rgba_;
  int width_ = 0, height_ = 0;
  std::string result_;
};

}  // namespace arwb::web
