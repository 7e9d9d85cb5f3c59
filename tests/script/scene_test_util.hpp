// Helpers for the scene tests (test_scene_lua, test_scene_sandbox, test_scene_database): a scene folder with
// media, a runtime on an offline media store, and hand-made tracks (no detector needed).
#pragma once

#include "media/media_store.hpp"
#include "script/scene_runtime.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace arwb::script::test {

using arwb::test::TempDir;
using arwb::test::write_file;

// The track_id of the hand-made track of an id (one print per id unless a test makes more).
inline uint64_t track_of(int id, int instance = 0) { return 1000u * (static_cast<uint64_t>(instance) + 1) + id; }

// A square marker of `side` pixels centred at (cx, cy), corners clockwise from the top-left.
inline TrackedMarker track(int id, double cx, double cy, double side = 60, bool detected = true,
                           double visible_s = 0, int instance = 0) {
  TrackedMarker t;
  t.id = id;
  t.instance = instance;
  t.track_id = track_of(id, instance);
  const float h = static_cast<float>(side / 2), x = static_cast<float>(cx), y = static_cast<float>(cy);
  t.corners = {cv::Point2f(x - h, y - h), cv::Point2f(x + h, y - h), cv::Point2f(x + h, y + h),
               cv::Point2f(x - h, y + h)};
  t.centre = {cx, cy};
  t.side_px = side;
  t.visible_s = visible_s;
  t.detected = detected;
  return t;
}

inline std::vector<TrackEvent> enters(std::initializer_list<int> ids) {
  std::vector<TrackEvent> e;
  for (int id : ids) e.push_back({TrackEvent::Kind::enter, id, track_of(id)});
  return e;
}

inline TrackEvent leave_event(int id, int instance = 0) {
  return {TrackEvent::Kind::leave, id, track_of(id, instance)};
}

inline void make_png(const std::filesystem::path& p, int w = 64, int h = 48) {
  std::filesystem::create_directories(p.parent_path());
  cv::Mat img(h, w, CV_8UC3, cv::Scalar(30, 120, 220));
  cv::circle(img, {w / 2, h / 2}, std::min(w, h) / 3, cv::Scalar(255, 255, 255), -1);
  ASSERT_TRUE(cv::imwrite(p.string(), img));
}

// A short MJPG AVI (10 frames of 64x48 at 10 fps), each frame a different grey.
inline void make_avi(const std::filesystem::path& p) {
  std::filesystem::create_directories(p.parent_path());
  cv::VideoWriter w(p.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, cv::Size(64, 48));
  ASSERT_TRUE(w.isOpened());
  for (int i = 0; i < 10; ++i) w.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(i * 20, i * 20, i * 20)));
}

// A runtime on an offline store, with the scene folder and one frame's input.
struct SceneFixture {
  explicit SceneFixture(ScriptLimits limits = {}) : runtime(store, limits) {}

  std::string write(const std::string& name, const std::string& text) {
    const std::string p = dir.str(name);
    write_file(p, text);
    return p;
  }

  std::vector<Overlay> update(const std::vector<TrackedMarker>& tracks, const std::vector<TrackEvent>& events = {},
                              double dt = 0.1) {
    tracks_ = tracks;
    events_ = events;
    SceneInput in;
    in.tracks = &tracks_;
    in.events = &events_;
    t_ += dt;
    in.t_s = t_;
    in.dt_s = dt;
    in.frame = frame;
    in.views = views;
    in.frame_index = ++frame_index;
    in.camera = camera;
    in.marker_side = marker_side;
    in.pose_unit = pose_unit;
    return runtime.update(in);
  }

  // The console lines containing `needle`.
  std::vector<ConsoleLine> lines(const std::string& needle) const {
    std::vector<ConsoleLine> out;
    for (const auto& l : runtime.status().console)
      if (l.text.find(needle) != std::string::npos) out.push_back(l);
    return out;
  }
  bool has(const std::string& needle) const { return !lines(needle).empty(); }
  // Every console line, for failure messages.
  std::string console() const {
    std::string s;
    for (const auto& l : runtime.status().console)
      s += std::to_string(l.level) + " x" + std::to_string(l.repeats) + " | " + l.text + "\n";
    return s;
  }
  // print() output (level 0) in order.
  std::vector<std::string> printed() const {
    std::vector<std::string> out;
    for (const auto& l : runtime.status().console)
      if (l.level == 0)
        for (int i = 0; i < l.repeats; ++i) out.push_back(l.text);
    return out;
  }

  // How many times print() wrote exactly this line.
  int count_printed(const std::string& text) const {
    const auto all = printed();
    return static_cast<int>(std::count(all.begin(), all.end(), text));
  }

  TempDir dir;
  media::MediaStore store{media::StoreMode::offline};
  SceneRuntime runtime;
  cv::Size frame{640, 480};
  const std::array<cv::Mat, kStageCount>* views = nullptr;
  uint64_t frame_index = 0;
  const Calibration* camera = nullptr;   // the tracks' poses' camera (3D media need it)
  double marker_side = 1;                 // the poses' marker side and its unit's name
  std::string pose_unit = "marker sides";

 private:
  std::vector<TrackedMarker> tracks_;
  std::vector<TrackEvent> events_;
  double t_ = 0;
};

inline const Overlay* find_overlay(const std::vector<Overlay>& overlays, int id, int mapping = -1) {
  for (const auto& o : overlays)
    if (o.marker_id == id && (mapping < 0 || o.mapping == mapping)) return &o;
  return nullptr;
}

inline int count_overlays(const std::vector<Overlay>& overlays, int id) {
  return static_cast<int>(std::count_if(overlays.begin(), overlays.end(), [&](const Overlay& o) { return o.marker_id == id; }));
}

}  // namespace arwb::script::test
