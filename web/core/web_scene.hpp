// The phone player core's scene: the desktop's scene step (script::SceneStep: the tracker, the Lua sandbox with
// its limits, or the paper's XML database, and placement) on the markers WebDetector found, over media the page
// draws (recording_media.hpp). Plain C++ that knows nothing of JavaScript; exports.cpp exports it.
#pragma once
#include "recording_media.hpp"
#include "script/scene_step.hpp"
#include "web_detector.hpp"

#include <string>

namespace arwb::web {

class WebScene {
 public:
  WebScene();
  // Loads the scene file at `path` in the core's file system (the page puts the bundle's files under /bundle/).
  // {"ok": true|false, "error": "file:line: message", "dictionary": "NAME"|"", "mappings": [{"ids","media",
  // "placement","line"}]}.
  std::string load(const std::string& path);
  // A video's size and length as the page's <video> read them, by its path in the core's file system.
  void set_video(const std::string& path, int width, int height, double duration_s);
  // One frame at `t_s` seconds: the tracker and the scene on `d`'s last markers, with its camera and marker side.
  // {"tracks": [{"id","track","detected","corners"}], "overlays": overlays_json's, each video's also with "video":
  // {"t","playing","loop","duration"}, each text card's also with "card": {"lines","font_px","pad","line_h",
  // "ascent","width","height","colour":[r,g,b,a],"background":[r,g,b,a]} (its layout), "errors": [new error
  // lines], "scene": {"ok","error","mappings":[{"state","health","reason"}], "console": [the newest lines, when
  // there are new ones]}}.
  const std::string& step(WebDetector& d, double t_s);

 private:
  RecordingMedia media_;
  script::SceneStep step_;
  uint64_t console_serial_ = 0;
  uint64_t frame_index_ = 0;
  std::string result_;
};

}  // namespace arwb::web
