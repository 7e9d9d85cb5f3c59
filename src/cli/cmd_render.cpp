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
#include "track/overlay_json.hpp"

#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
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
      // Escaped like every other line: neither a file name in a message nor a print() acts on the terminal. The
      // tabs print() puts between its arguments stay tabs, as in the window's console: a tab moves the cursor only.
      std::string text;
      for (size_t from = 0; from <= l.text.size();) {
        const size_t tab = std::min(l.text.find('\t', from), l.text.size());
        text += printable(std::string_view(l.text).substr(from, tab - from)) + (tab < l.text.size() ? "\t" : "");
        from = tab + 1;
      }
      std::fprintf(l.level == 0 ? stdout : stderr, "%s%s\n", l.level == 2 ? "scene: " : "", text.c_str());
    }
    shown = s.console.size();
  }
};

// The safety net under the scene limits (each call 250 ms, a frame's calls 150 ms): if one step of the scene has
// not returned after kStuckSeconds, something no limit foresaw holds it (a library call that never returns), and
// the render exits with a message rather than hang. A step also loads the media it shows the first time: a model
// within every limit (2 million triangles, 4 textures) can take seconds on a slow machine, and once took more than
// the 5 s this was, which stopped a good render with "stuck in a script?".
constexpr double kStuckSeconds = 60;

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
        print_problem("arwb render: %s has not returned after %g s (stuck in a script or a library call?); stopping\n",
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

// What the command line asked for.
struct RenderArgs {
  std::string scene_file, input, out, resize = "off", dict_opt, params_file, calib_file, overlays_file;
  int max_frames = 0, samples = 4;
  double fps_opt = 0, marker_size = 0;
  bool force = false;
};

// The options, declared on `app` for `a` to receive.
void declare_options(CLI::App& app, RenderArgs& a) {
  app.add_option("--scene", a.scene_file, "a Lua scene or the paper's XML database (docs/scene-api.md)")
      ->type_name("FILE.lua|FILE.xml")
      ->required();
  app.add_option("--input", a.input, "a video, a folder of images (name order), one image, or the synthetic source")
      ->type_name("VIDEO|DIR|IMAGE|synthetic")
      ->required();
  app.add_option("--out", a.out, "a video (.mp4, .avi, .mkv) or a folder for PNG frames")
      ->type_name("OUT.mp4|OUT.avi|DIR")
      ->required()
      ->check(out_kinds({".mp4", ".avi", ".mkv"}, true));
  app.add_option("--frames", a.max_frames, "stop after N frames; 0: the whole input (synthetic: 100)")
      ->type_name("N")
      ->check(whole_number(0, 10'000'000));
  app.add_option("--fps", a.fps_opt, "the scene's clock and the video's rate; 0: the input video's, else 20")
      ->type_name("F")
      ->check(real_number(0, 1000));
  add_resize_option(app, a.resize);
  app.add_option("--size", a.resize, "the old name of --resize")->group("")->check(resize_value());
  app.add_option("--dict", a.dict_opt, "the detector's dictionaries (default: the scene's `dictionary`, else "
                                       "ARUCO_ORIGINAL)")
      ->type_name("NAME[,NAME...]");
  app.add_option("--params", a.params_file, "a YAML preset of detector parameters")->type_name("FILE.yml");
  app.add_option("--calib", a.calib_file,
                 "the camera's calibration (XML or YAML, as arwb calibrate writes): poses, 3D media and media on "
                 "markers follow its lens model; without it, the paper's default values")
      ->type_name("FILE");
  app.add_option("--marker-size", a.marker_size,
                 "the printed marker's side, in the unit poses should be in (Lua's m.pose); default: marker sides")
      ->type_name("L")
      ->check(CLI::Range(0.0, 1e6));
  app.add_option("--samples", a.samples, "MSAA samples for the media's edges; 1 turns it off")
      ->type_name("N")
      ->check(whole_number(1, 16));
  app.add_option("--overlays", a.overlays_file,
                 "also write where each medium was drawn: one JSON line per frame (docs/command-line.md)")
      ->type_name("FILE.jsonl");
  app.add_flag("--force", a.force, "replace an existing OUT file, or frame_*.png files already in DIR (and the "
               "--overlays file)");
}

// Why --out may not be written (never overwrite what is there unless asked), or "".
std::string out_problem(const RenderArgs& a, bool to_video) {
  std::error_code ec;
  if (!a.overlays_file.empty() && fs::exists(a.overlays_file, ec) && !a.force)
    return "--overlays " + a.overlays_file + " exists; add --force to replace it";
  if (to_video) {
    if (fs::exists(a.out, ec) && !a.force) return "--out " + a.out + " exists; add --force to replace it";
    return "";
  }
  if (fs::exists(a.out, ec) && !fs::is_directory(a.out, ec)) return "--out " + a.out + " is a file, not a folder";
  if (fs::is_directory(a.out, ec) && !a.force) {
    for (const auto& e : fs::directory_iterator(a.out, ec)) {
      const std::string n = e.path().filename().string();
      if (n.rfind("frame_", 0) == 0 && e.path().extension() == ".png")
        return "--out " + a.out + " already holds frame_*.png; add --force to replace them";
    }
  }
  return "";
}

// The frames' camera: the calibration as read (none: the paper's default values), fitted to the frames' size
// when it changes, and the marker's side for poses.
struct FrameCamera {
  std::shared_ptr<const Calibration> calib;
  cv::Size size;   // the frame size `calib` was fitted to
  double marker_size = 0;

  // Gives the frame its camera; false after printing why the calibration does not fit the frame.
  bool give(Frame& f) {
    if (calib && size != f.image.size()) {
      Result<Calibration> c = calibration_for_size(*calib, f.image.size());
      if (!c) {
        print_problem("arwb render: --calib %s\n", c.error().c_str());
        return false;
      }
      calib = std::make_shared<const Calibration>(std::move(*c));
      size = f.image.size();
    }
    f.loaded_calibration = calib;
    f.pose_marker_side = marker_size > 0 ? marker_size : 1.0;
    f.pose_unit = marker_size > 0 ? "mm" : "marker sides";
    return true;
  }
};

// Where the pictures go: a video, opened at the first picture with its size, or PNG frames in a folder.
struct PictureOut {
  std::string out;
  bool to_video = false;
  double fps = 20;
  cv::VideoWriter writer;
  cv::Size size;
  std::string codec;

  // False after printing why the picture could not be written.
  bool write(const cv::Mat& picture, int frame) {
    if (to_video) {
      if (!writer.isOpened()) {
        size = picture.size();
        open_video_writer(writer, out, fps, size, &codec);
        if (!writer.isOpened()) {
          print_problem("arwb render: cannot write %s (FFmpeg refused every codec)\n", out.c_str());
          return false;
        }
      }
      writer.write(picture);
      return true;
    }
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06d.png", frame);
    const std::string path = (fs::path(out) / name).string();
    if (!cv::imwrite(path, picture)) {
      print_problem("arwb render: cannot write %s\n", path.c_str());
      return false;
    }
    size = picture.size();
    return true;
  }
};

// One input frame through the workbench's steps: detection (acquisition's resize its first stage), the stage
// pictures, the camera, the scene, the compositor; the picture then written. Times and counts add up for the
// summary.
struct FrameSteps {
  using Clock = std::chrono::steady_clock;
  Detector& detector;
  VideoSearch& video;   // the frames are one video's: each is searched around the last one's markers
  FrameCamera& camera;
  SceneStage& stage;
  SceneWatchdog& watchdog;
  ConsoleEcho& console;
  render::Compositor& compositor;
  PictureOut& pictures;
  DetectorParams params;
  std::FILE* overlays_out = nullptr;   // --overlays: a JSON line per frame
  double detect_ms = 0, scene_ms = 0, composite_ms = 0, write_ms = 0;
  int frames = 0, with_markers = 0, overlays = 0;

  static double ms_since(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  }

  // 0, or the exit status after printing why the render stops.
  int run(const cv::Mat& raw, double t) {
    Frame f;
    f.index = uint64_t(frames) + 1;
    f.time_s = t;
    f.params = params;   // the tracker's smoothing rows are in the preset too
    auto t0 = Clock::now();
    video.detect(detector, raw, &f.trace, TraceLevel::full, 1, &f.image);   // acquisition's resize: its first stage
    if (f.image.channels() == 1) cv::cvtColor(f.image, f.image, cv::COLOR_GRAY2BGR);
    render_stage_views(f.image, f.trace, f.views);
    if (!camera.give(f)) return 2;
    detect_ms += ms_since(t0);
    t0 = Clock::now();
    watchdog.begin("the scene on frame " + std::to_string(frames));
    stage.run(f, t, 1e9);   // offline: the file is read once
    watchdog.end();
    scene_ms += ms_since(t0);
    console.echo(f.scene);
    if (overlays_out) {
      const std::string line = nlohmann::ordered_json{{"frame", frames}, {"t", t}, {"width", f.image.cols},
                                                      {"height", f.image.rows},
                                                      {"overlays", overlays_json(f.overlays)}}.dump();
      if (std::fprintf(overlays_out, "%s\n", line.c_str()) < 0) {
        print_problem("arwb render: cannot write the --overlays file\n");
        return 1;
      }
    }
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
    if (!pictures.write(picture, frames)) return 1;
    write_ms += ms_since(t0);
    ++frames;
    return 0;
  }
};

}  // namespace

int cmd_render(int argc, char** argv) {
  CommandLine cl("arwb render",
                 "Composites the scene's media onto every input frame, as the workbench shows them, and writes a video "
                 "(.mp4: H.264 where FFmpeg has it, else MPEG-4 part 2; .avi: MJPG) or PNG frames frame_000000.png "
                 "upward into DIR. Needs no display.",
                 "Scene errors are printed as file:line: message; the render goes on with the rest of the scene.");
  RenderArgs a;
  declare_options(cl.app, a);
  if (const auto status = cl.parse(argc, argv)) return *status;
  auto usage_error = [&cl](const std::string& m) { return cl.usage_error(m); };
  AcquisitionSettings acq{.fps_cap = 0};
  apply_resize_option(a.resize, acq);
  SourceSpec spec;
  std::string err;
  if (!parse_source_spec(a.input, &spec, &err)) return usage_error("--input " + err);
  if (spec.kind == SourceKind::camera) return usage_error("--input " + a.input + ": render reads files; the workbench shows cameras");
  const bool to_video = is_video_name(a.out);
  if (const std::string problem = out_problem(a, to_video); !problem.empty()) return usage_error(problem);

  FrameCamera camera;
  camera.marker_size = a.marker_size;
  if (!a.calib_file.empty()) {
    Result<Calibration> c = read_calibration(a.calib_file);
    if (!c) {
      print_problem("arwb render: --calib %s\n", c.error().c_str());
      return 2;
    }
    camera.calib = std::make_shared<const Calibration>(std::move(*c));
  }

  SceneWatchdog watchdog;
  SceneStage stage(media::StoreMode::offline);
  watchdog.begin("loading the scene");
  const bool loaded = stage.load(a.scene_file);
  watchdog.end();
  if (!loaded) {
    print_problem("arwb render: %s\n", stage.status().error.c_str());
    return 1;
  }
  ConsoleEcho console;
  console.echo(stage.status());

  std::string dict_list = a.dict_opt.empty() ? stage.dictionary() : a.dict_opt;
  if (dict_list.empty()) dict_list = "ARUCO_ORIGINAL";
  auto dicts = dictionaries_option(dict_list, "arwb render");
  if (!dicts) return 2;
  DetectorParams params;
  if (!load_params_option(a.params_file, "arwb render", params)) return 2;
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
  const double fps = a.fps_opt > 0 ? a.fps_opt : (spec.kind == SourceKind::video && info0.native_fps > 0 ? info0.native_fps : 20.0);
  const int limit = a.max_frames > 0 ? a.max_frames : (spec.kind == SourceKind::synthetic ? 100 : 0);

  render::OffscreenContext gl;
  if (!gl.ok()) {
    print_problem("arwb render: %s\n", gl.error().c_str());
    return 1;
  }
  render::Compositor compositor(a.samples);
  PictureOut pictures{a.out, to_video, fps, {}, {}, {}};
  std::error_code ec;
  if (!to_video && !fs::is_directory(a.out, ec)) {
    fs::create_directories(a.out, ec);
    if (ec) {
      print_problem("arwb render: cannot create %s (%s)\n", a.out.c_str(), ec.message().c_str());
      return 1;
    }
  }

  std::unique_ptr<std::FILE, int (*)(std::FILE*)> overlays_out(nullptr, &std::fclose);
  if (!a.overlays_file.empty()) {
    overlays_out.reset(std::fopen(a.overlays_file.c_str(), "w"));
    if (!overlays_out) {
      print_problem("arwb render: cannot write --overlays %s (%s)\n", a.overlays_file.c_str(), std::strerror(errno));
      return 1;
    }
  }
  VideoSearch video;
  FrameSteps steps{detector, video, camera, stage, watchdog, console, compositor, pictures, params,
                   overlays_out.get()};
  int errors = 0;
  cv::Mat raw;
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
    if (const int status = steps.run(raw, t)) return status;
  }
  pictures.writer.release();
  if (steps.frames == 0) {
    print_problem("arwb render: %s gave no frames\n", a.input.c_str());
    return 1;
  }
  const double n = steps.frames;
  std::printf("rendered %d frames (%dx%d, %.3g fps) to %s%s%s\n", steps.frames, pictures.size.width,
              pictures.size.height, fps, a.out.c_str(), pictures.codec.empty() ? "" : " with ", pictures.codec.c_str());
  std::printf("markers on %d frames, %d overlays drawn; scene %s\n", steps.with_markers, steps.overlays,
              a.scene_file.c_str());
  std::printf("ms per frame: detect %.2f, scene %.2f, composite %.2f (MSAA x%d, %s), write %.2f\n",
              steps.detect_ms / n, steps.scene_ms / n, steps.composite_ms / n, compositor.samples(),
              gl.renderer().c_str(), steps.write_ms / n);
  return 0;
}

}  // namespace arwb
