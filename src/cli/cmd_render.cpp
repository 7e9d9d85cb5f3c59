// arwb render: the paper's player and export, offline. Every input frame goes through the same steps as in the
// workbench (detection, tracker, the scene, placement, the OpenGL compositor), then into a video or PNG frames.
// Runs without a display (EGL), so a demo can be rendered on a server and shared.
#include "calibration/calibration_file.hpp"
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "base/text.hpp"
#include "workbench/scene_stage.hpp"
#include "detect/detector.hpp"
#include "detect/video_search.hpp"
#include "synth/synthetic_source.hpp"
#include "inspect/trace_view.hpp"
#include "render/compositor.hpp"
#include "render/offscreen.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace arwb {
namespace {

namespace fs = std::filesystem;

bool is_video_name(const std::string& out) {
  const std::string ext = fs::path(out).extension().string();
  return ext == ".mp4" || ext == ".avi" || ext == ".mkv" || ext == ".MP4" || ext == ".AVI" || ext == ".MKV";
}

// Console lines the scene added since the last call, to stderr (the scene's print output to stdout).
struct ConsoleEcho {
  uint64_t serial = 0;
  size_t shown = 0;
  void echo(const SceneStatus& s) {
    if (s.console_serial == serial) return;
    serial = s.console_serial;
    // Lines are collapsed by the scene (repeats); print each distinct line once, when it first appears.
    if (shown > s.console.size()) shown = 0;
    for (size_t i = shown; i < s.console.size(); ++i) {
      const ConsoleLine& l = s.console[i];
      // Escaped like every other line: neither a file name in a message nor a print() acts on the terminal.
      std::fprintf(l.level == 0 ? stdout : stderr, "%s%s\n", l.level == 2 ? "scene: " : "", printable(l.text).c_str());
    }
    shown = s.console.size();
  }
};

// The safety net under the scene limits (each call 250 ms, a frame's calls 150 ms): if one step of the scene has
// not returned after kStuckSeconds, something no limit foresaw holds it (a library call that never returns), and
// the render exits with a message rather than hang.
constexpr double kStuckSeconds = 5;

class SceneWatchdog {
 public:
  SceneWatchdog() : thread_([this] { watch(); }) {}
  ~SceneWatchdog() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  void begin(const std::string& what) {
    std::lock_guard lock(mutex_);
    what_ = what;
    since_ = std::chrono::steady_clock::now();
    armed_ = true;
  }
  void end() {
    std::lock_guard lock(mutex_);
    armed_ = false;
  }

 private:
  void watch() {
    std::unique_lock lock(mutex_);
    while (!stop_) {
      if (armed_ && std::chrono::duration<double>(std::chrono::steady_clock::now() - since_).count() > kStuckSeconds) {
        print_problem("arwb render: %s has not returned after %g s (stuck in a script?); stopping\n",
                     what_.c_str(), kStuckSeconds);
        std::fflush(stdout);
        std::fflush(stderr);
        std::_Exit(1);   // the stuck thread cannot be stopped or joined; nothing else is left to save
      }
      wake_.wait_for(lock, std::chrono::milliseconds(100));
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false, armed_ = false;
  std::string what_;
  std::chrono::steady_clock::time_point since_;
  std::thread thread_;
};

}  // namespace

int cmd_render(int argc, char** argv) {
  CommandLine cl("arwb render",
                 "Composites the scene's media onto every input frame, as the workbench shows them, and writes a video "
                 "(.mp4: H.264 where FFmpeg has it, else MPEG-4 part 2; .avi: MJPG) or PNG frames frame_000000.png "
                 "upward into DIR. Needs no display.",
                 "Scene errors are printed as file:line: message; the render goes on with the rest of the scene.");
  std::string scene_file, input, out, size_text, dict_opt, params_file, calib_file;
  int max_frames = 0, samples = 4;
  double fps_opt = 0, marker_size = 0;
  bool force = false;
  cl.app.add_option("--scene", scene_file, "a Lua scene or the paper's XML database (docs/scene-api.md)")
      ->type_name("FILE.lua|FILE.xml")
      ->required();
  cl.app.add_option("--input", input, "a video, a folder of images (name order), one image, or the synthetic source")
      ->type_name("VIDEO|DIR|IMAGE|synthetic")
      ->required();
  cl.app.add_option("--out", out, "a video (.mp4, .avi, .mkv) or a folder for PNG frames")
      ->type_name("OUT.mp4|OUT.avi|DIR")
      ->required();
  cl.app.add_option("--frames", max_frames, "stop after N frames; 0: the whole input (synthetic: 100)")
      ->type_name("N")
      ->check(whole_number(0, 10'000'000));
  cl.app.add_option("--fps", fps_opt, "the scene's clock and the video's rate; 0: the input video's, else 20")
      ->type_name("F")
      ->check(real_number(0, 1000));
  cl.app.add_option("--size", size_text,
                    "resize frames to WxH first, as the workbench's acquisition does (default: the input's size)")
      ->type_name("WxH")
      ->check(frame_size({16, 16}, {8192, 8192}));
  cl.app.add_option("--dict", dict_opt, "the detector's dictionaries (default: the scene's `dictionary`, else "
                                        "ARUCO_ORIGINAL)")
      ->type_name("NAME[,NAME...]");
  cl.app.add_option("--params", params_file, "a YAML preset of detector parameters")->type_name("FILE.yml");
  cl.app.add_option("--calib", calib_file,
                    "the camera's calibration (XML or YAML, as arwb calibrate writes): poses, 3D media and media on "
                    "markers follow its lens model; without it, the paper's default values")
      ->type_name("FILE");
  cl.app.add_option("--marker-size", marker_size,
                    "the printed marker's side, in the unit poses should be in (Lua's m.pose); default: marker sides")
      ->type_name("L")
      ->check(CLI::Range(0.0, 1e6));
  cl.app.add_option("--samples", samples, "MSAA samples for the media's edges; 1 turns it off")
      ->type_name("N")
      ->check(whole_number(1, 16));
  cl.app.add_flag("--force", force, "replace an existing OUT file, or frame_*.png files already in DIR");
  if (const auto status = cl.parse(argc, argv)) return *status;
  auto usage_error = [&cl](const std::string& m) { return cl.usage_error(m); };
  AcquisitionSettings acq;
  acq.fps_cap = 0;
  acq.resize = false;
  if (!size_text.empty()) {
    acq.resize = true;
    acq.size = *parse_frame_size(size_text);  // checked by frame_size
  }
  SourceSpec spec;
  std::string err;
  if (!parse_source_spec(input, &spec, &err)) return usage_error("--input " + err);
  if (spec.kind == SourceKind::camera) return usage_error("--input " + input + ": render reads files; the workbench shows cameras");

  // Never overwrite what is there unless asked.
  const bool to_video = is_video_name(out);
  std::error_code ec;
  if (to_video) {
    if (fs::exists(out, ec) && !force) return usage_error("--out " + out + " exists; add --force to replace it");
  } else {
    if (fs::exists(out, ec) && !fs::is_directory(out, ec)) return usage_error("--out " + out + " is a file, not a folder");
    if (fs::is_directory(out, ec) && !force) {
      for (const auto& e : fs::directory_iterator(out, ec)) {
        const std::string n = e.path().filename().string();
        if (n.rfind("frame_", 0) == 0 && e.path().extension() == ".png")
          return usage_error("--out " + out + " already holds frame_*.png; add --force to replace them");
      }
    }
  }

  std::shared_ptr<const Calibration> calib;   // as read; fitted to the frames' size at the first frame
  if (!calib_file.empty()) {
    Result<Calibration> c = read_calibration(calib_file);
    if (!c) {
      print_problem("arwb render: --calib %s\n", c.error().c_str());
      return 2;
    }
    calib = std::make_shared<const Calibration>(std::move(*c));
  }
  cv::Size calib_size;   // the frame size `calib` was fitted to

  SceneWatchdog watchdog;
  SceneStage stage(media::StoreMode::offline);
  watchdog.begin("loading the scene");
  const bool loaded = stage.load(scene_file);
  watchdog.end();
  if (!loaded) {
    print_problem("arwb render: %s\n", stage.status().error.c_str());
    return 1;
  }
  ConsoleEcho console;
  console.echo(stage.status());

  std::string dict_list = dict_opt.empty() ? stage.dictionary() : dict_opt;
  if (dict_list.empty()) dict_list = "ARUCO_ORIGINAL";
  auto dicts = dictionaries_option(dict_list, "arwb render");
  if (!dicts) return 2;
  DetectorParams params;
  if (!load_params_option(params_file, "arwb render", params)) return 2;
  Detector detector(std::move(*dicts), params);
  detector.set_acquisition(acq);

  auto source = open_source(spec, &err);
  if (!source) {
    print_problem("arwb render: %s\n", err.c_str());
    return 1;
  }
  Playback pb;
  pb.loop = false;
  source->set_playback(pb);
  const SourceInfo info0 = source->info();
  const double fps = fps_opt > 0 ? fps_opt : (spec.kind == SourceKind::video && info0.native_fps > 0 ? info0.native_fps : 20.0);
  const int limit = max_frames > 0 ? max_frames : (spec.kind == SourceKind::synthetic ? 100 : 0);

  render::OffscreenContext gl;
  if (!gl.ok()) {
    print_problem("arwb render: %s\n", gl.error().c_str());
    return 1;
  }
  render::Compositor compositor(samples);
  cv::VideoWriter writer;
  if (!to_video && !fs::is_directory(out, ec)) {
    fs::create_directories(out, ec);
    if (ec) {
      print_problem("arwb render: cannot create %s (%s)\n", out.c_str(), ec.message().c_str());
      return 1;
    }
  }

  using Clock = std::chrono::steady_clock;
  auto ms_since = [](Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); };
  double detect_ms = 0, scene_ms = 0, composite_ms = 0, write_ms = 0;
  int frames = 0, with_markers = 0, overlays = 0, errors = 0;
  cv::Size size;
  std::string codec;
  cv::Mat raw;
  VideoSearch video;   // the frames are one video's: each is searched around the last one's markers
  for (int i = 0; limit == 0 || i < limit; ++i) {
    if (i > 0) source->step(1);
    const double t = i / fps;
    const SourceStatus st = source->next(t, raw);
    if (st.status == FrameStatus::end || st.status == FrameStatus::gone) break;
    if (st.status == FrameStatus::same && spec.kind != SourceKind::synthetic) break;   // one image: done
    if (st.status == FrameStatus::error) {
      print_problem("arwb render: %s\n", st.message.c_str());
      if (++errors > 100) break;
      continue;
    }
    if (raw.empty()) continue;
    Frame f;
    f.index = uint64_t(frames) + 1;
    f.time_s = t;
    f.params = params;   // the tracker's smoothing rows are in the preset too
    auto t0 = Clock::now();
    video.detect(detector, raw, &f.trace, TraceLevel::full, 1, &f.image);   // acquisition's resize: its first stage
    if (f.image.channels() == 1) cv::cvtColor(f.image, f.image, cv::COLOR_GRAY2BGR);
    render_stage_views(f.image, f.trace, f.views);
    if (calib && calib_size != f.image.size()) {
      Result<Calibration> c = calibration_for_size(*calib, f.image.size());
      if (!c) {
        print_problem("arwb render: --calib %s\n", c.error().c_str());
        return 2;
      }
      calib = std::make_shared<const Calibration>(std::move(*c));
      calib_size = f.image.size();
    }
    f.loaded_calibration = calib;
    f.pose_marker_side = marker_size > 0 ? marker_size : 1.0;
    detect_ms += ms_since(t0);
    t0 = Clock::now();
    watchdog.begin("the scene on frame " + std::to_string(frames));
    stage.run(f, t, 1e9);   // offline: the file is read once
    watchdog.end();
    scene_ms += ms_since(t0);
    console.echo(f.scene);
    if (!f.trace.markers.empty()) ++with_markers;
    overlays += int(f.overlays.size());
    t0 = Clock::now();
    if (!compositor.draw(f.image, f.index, f.overlays)) {
      print_problem("arwb render: %s\n", compositor.error().c_str());
      return 1;
    }
    const cv::Mat picture = compositor.read();
    composite_ms += ms_since(t0);
    t0 = Clock::now();
    if (to_video) {
      if (!writer.isOpened()) {
        size = picture.size();
        open_video_writer(writer, out, fps, size, &codec);
        if (!writer.isOpened()) {
          print_problem("arwb render: cannot write %s (FFmpeg refused every codec)\n", out.c_str());
          return 1;
        }
      }
      writer.write(picture);
    } else {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%06d.png", frames);
      const std::string path = (fs::path(out) / name).string();
      if (!cv::imwrite(path, picture)) {
        print_problem("arwb render: cannot write %s\n", path.c_str());
        return 1;
      }
      size = picture.size();
    }
    write_ms += ms_since(t0);
    ++frames;
  }
  writer.release();
  if (frames == 0) {
    print_problem("arwb render: %s gave no frames\n", input.c_str());
    return 1;
  }
  const double n = frames;
  std::printf("rendered %d frames (%dx%d, %.3g fps) to %s%s%s\n", frames, size.width, size.height, fps, out.c_str(),
              codec.empty() ? "" : " with ", codec.c_str());
  std::printf("markers on %d frames, %d overlays drawn; scene %s\n", with_markers, overlays, scene_file.c_str());
  std::printf("ms per frame: detect %.2f, scene %.2f, composite %.2f (MSAA x%d, %s), write %.2f\n", detect_ms / n,
              scene_ms / n, composite_ms / n, compositor.samples(), gl.renderer().c_str(), write_ms / n);
  return 0;
}

}  // namespace arwb
