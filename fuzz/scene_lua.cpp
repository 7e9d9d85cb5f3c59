// Fuzz target: the Lua scene loader and runtime (src/script: SceneRuntime::load, then update()), as the workbench
// and `arwb render` run a scene: the input is the scene file (Lua, or XML when it starts with '<'), loaded from a
// scratch folder that also holds media/tile.png (and the example scenes' image names), then run for a few frames
// over three synthetic markers that enter, move, and leave. The limits are small (4 MiB, 200,000 instructions a
// call) so that no input runs long; the scene must never take the process down, whatever it does.
#include "fuzz_files.hpp"
#include "media/media_store.hpp"
#include "script/scene_runtime.hpp"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace {

arwb::TrackedMarker marker(int id, float x, float y, float side, double t) {
  arwb::TrackedMarker m;
  m.id = id;
  m.dict = "ARUCO_ORIGINAL";
  m.corners = {cv::Point2f(x, y), cv::Point2f(x + side, y), cv::Point2f(x + side, y + side), cv::Point2f(x, y + side)};
  m.centre = {x + side / 2, y + side / 2};
  m.side_px = side;
  m.first_seen_s = 0;
  m.last_seen_s = t;
  m.visible_s = t;
  m.detected = true;
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool ready = [] {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    // Real images for scenes to show (media paths resolve inside the scene's folder), also under the names the
    // example scenes of the seed corpus use. No video: decoding one on every input would slow the fuzzer down.
    std::filesystem::create_directories(arwb::fuzz::scratch_dir() / "media");
    const cv::Mat tile(16, 16, CV_8UC3, cv::Scalar(40, 160, 220));
    bool ok = true;
    for (const char* name : {"tile.png", "composition.png", "sunset.png", "flask.png"})
      ok = ok && cv::imwrite((arwb::fuzz::scratch_dir() / "media" / name).string(), tile);
    return ok;
  }();
  if (!ready) std::abort();

  const std::string path = arwb::fuzz::write_scratch("scene.lua", data, size);
  arwb::media::MediaStore store(arwb::media::StoreMode::offline);
  arwb::script::ScriptLimits limits;
  limits.memory_bytes = 4u << 20;
  limits.instructions_per_call = 200'000;
  limits.console_lines = 20;
  arwb::script::SceneRuntime runtime(store, limits);
  if (!runtime.load(path)) {
    if (runtime.status().error.empty()) std::abort();
    return 0;
  }

  // Markers 0, 1 and 2 enter; 1 moves and turns; 2 leaves; then all leave.
  constexpr int kFrames = 4;
  for (int f = 0; f < kFrames; ++f) {
    const double t = f / 20.0;
    std::vector<arwb::TrackedMarker> tracks;
    std::vector<arwb::TrackEvent> events;
    if (f < kFrames - 1) {
      tracks.push_back(marker(0, 100, 100, 80, t));
      const float step = static_cast<float>(f);
      tracks.push_back(marker(1, 300.f + 20.f * step, 120, 60.f + 10.f * step, t));
      if (f < 2) tracks.push_back(marker(2, 200, 300, 50, t));
    }
    if (f == 0) for (int id : {0, 1, 2}) events.push_back({arwb::TrackEvent::Kind::enter, id});
    if (f == 2) events.push_back({arwb::TrackEvent::Kind::leave, 2});
    if (f == kFrames - 1) for (int id : {0, 1}) events.push_back({arwb::TrackEvent::Kind::leave, id});
    arwb::script::SceneInput in;
    in.tracks = &tracks;
    in.events = &events;
    in.t_s = t;
    in.dt_s = f == 0 ? 0 : 1 / 20.0;
    in.frame = {640, 480};
    in.frame_index = static_cast<uint64_t>(f);
    const std::vector<arwb::Overlay> overlays = runtime.update(in);
    (void)overlays;
  }
  return 0;
}
