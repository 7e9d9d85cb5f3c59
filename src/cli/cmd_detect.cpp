// arwb detect: markers in images, folders of images and videos, as text or one JSON line per frame. With a
// calibration (--calib), each marker's corners also as an ideal pinhole camera would see them (lens distortion
// removed); with a marker size (--marker-size), each marker's pose (pose/marker_pose.hpp), through the
// calibration or else the paper's default camera, marked as assumed.
#include "calibration/calibration_file.hpp"
#include "pose/marker_pose.hpp"
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "detect/detector.hpp"
#include "inspect/diagnose.hpp"
#include "detect/video_search.hpp"
#include "capture/image_io.hpp"
#include "capture/video_reader.hpp"
#include "base/decimals.hpp"
#include "base/json_text.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/videoio.hpp>

#include <chrono>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace arwb {
namespace {

struct Output {
  bool json = false;
  int frames = 0;
  std::optional<Calibration> calib;                        // --calib as read
  std::map<std::pair<int, int>, Calibration> calib_sized;  // ... for each frame size met (scaled when needed)
  double marker_size = 0;                                  // --marker-size; 0: no pose
  // In a video, each id's pose on the previous frame (when the id was there once): it resolves the ambiguity.
  std::map<std::pair<std::string, int>, cv::Vec3d> previous;
  std::set<std::string> looked;   // sources whose first frame without markers was read as other dictionaries
};

// A frame with no marker whose quads read as a dictionary not searched: said on stderr in one line, as the Why
// panel says it. Only the first such frame of a source is looked at, traced whole (what the full trace costs):
// a video's other empty frames would each cost that again.
void hint_other_dictionary(Output& out, const std::string& source, const cv::Mat& image, const Detector& det,
                           int threads) {
  if (!out.looked.insert(source).second) return;
  FrameTrace trace;
  det.detect(image, &trace, TraceLevel::full, threads);
  std::vector<int> all(trace.candidates.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = int(i);
  std::vector<std::string> searched;
  for (const Dictionary& d : det.dictionaries()) searched.push_back(d.name());
  const std::vector<OtherDictionary> other = read_other_dictionaries(trace, all, det.params(), searched);
  if (other.empty()) return;
  const OtherDictionary& o = other.front();
  print_problem("%s: 0 markers; %d quad%s read as %s: try --dict %s\n", source.c_str(), o.in_frame,
                o.in_frame == 1 ? "" : "s", o.dict.c_str(), o.dict.c_str());
}

nlohmann::ordered_json vec_json(const cv::Vec3d& v) {
  return {round_decimals(v[0], 6), round_decimals(v[1], 6), round_decimals(v[2], 6)};
}

// Each marker's pose, or nullopt where it has none (no --marker-size, a degenerate quad). In a video the previous
// frame's pose of the same id (seen once there and here) chooses between the two solutions of an ambiguous view.
std::vector<std::optional<MarkerPose>> poses_of(Output& out, const std::vector<Marker>& markers,
                                                const Calibration& camera, bool video_frame) {
  std::vector<std::optional<MarkerPose>> poses(markers.size());
  if (out.marker_size <= 0) return poses;
  std::map<std::pair<std::string, int>, int> count;
  for (const Marker& m : markers) ++count[{m.dict, m.id}];
  std::map<std::pair<std::string, int>, cv::Vec3d> now;
  for (size_t i = 0; i < markers.size(); ++i) {
    const auto key = std::make_pair(markers[i].dict, markers[i].id);
    poses[i] = estimate_marker_pose(markers[i].corners, out.marker_size, camera);
    if (!poses[i] || count[key] != 1) continue;
    if (auto it = out.previous.find(key); video_frame && it != out.previous.end())
      poses[i] = resolve_with_previous(*poses[i], it->second);
    now[key] = poses[i]->pose.rvec;
  }
  out.previous = std::move(now);
  return poses;
}

nlohmann::ordered_json pose_json(const MarkerPose& p) {
  using Json = nlohmann::ordered_json;
  const PoseAngles a = pose_angles(p.pose);
  return Json{{"rvec", vec_json(p.pose.rvec)},
              {"tvec", vec_json(p.pose.tvec)},
              {"error_px", round_decimals(p.pose.error_px, 4)},
              {"ambiguity", round_decimals(p.ambiguity, 4)},
              {"alternative", {{"rvec", vec_json(p.alternative.rvec)},
                               {"tvec", vec_json(p.alternative.tvec)},
                               {"error_px", round_decimals(p.alternative.error_px, 4)}}},
              {"chosen_by_previous", p.chosen_by_previous},
              {"camera", p.assumed_camera ? "assumed" : "calibrated"},
              {"distance", round_decimals(a.distance, 6)},
              {"tilt_deg", round_decimals(a.tilt_deg, 3)},
              {"yaw_deg", round_decimals(a.yaw_deg, 3)},
              {"pitch_deg", round_decimals(a.pitch_deg, 3)},
              {"roll_deg", round_decimals(a.roll_deg, 3)}};
}

// The calibration for a frame of `size`, or null with the reason printed once per source and size (an aspect
// ratio the calibration was not made for: its corners would be wrong everywhere).
const Calibration* calibration_for(Output& out, const std::string& source, cv::Size size) {
  const auto key = std::make_pair(size.width, size.height);
  if (auto it = out.calib_sized.find(key); it != out.calib_sized.end()) return &it->second;
  Result<Calibration> c = calibration_for_size(*out.calib, size);
  if (!c) {
    print_problem("%s: %s (skipped)\n", source.c_str(), c.error().c_str());
    return nullptr;
  }
  return &out.calib_sized.emplace(key, std::move(*c)).first->second;
}

std::vector<cv::Point2f> undistorted(const Calibration& c, const Marker& m) {
  std::vector<cv::Point2f> in(m.corners.begin(), m.corners.end()), outp;
  cv::undistortPoints(in, outp, cv::Mat(c.camera_matrix), cv::Mat(c.distortion), cv::noArray(),
                      cv::Mat(c.camera_matrix));
  return outp;
}

// `video`: the video's search state (a frame of a video is searched around the last frame's markers), or null for
// a still image.
void report(Output& out, const std::string& source, int frame, const cv::Mat& image, const Detector& det,
            int threads, VideoSearch* video = nullptr) {
  // The markers' pixels are the image's, also when --resize detected them at another size (`work`).
  const cv::Size size = image.size(), work = acquisition_size(size, det.acquisition());
  const Calibration* calib = nullptr;
  if (out.calib && !(calib = calibration_for(out, source, size))) return;
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Marker> markers =
      video ? video->detect(det, image, nullptr, TraceLevel::off, threads) : det.detect(image, nullptr, TraceLevel::off, threads);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ++out.frames;
  if (markers.empty()) hint_other_dictionary(out, source, image, det, threads);
  const Calibration camera = calib ? *calib : default_calibration(size);
  const std::vector<std::optional<MarkerPose>> poses = poses_of(out, markers, camera, frame > 0);
  if (out.json) {
    using Json = nlohmann::ordered_json;
    Json line = {{"source", source}, {"frame", frame}, {"width", size.width}, {"height", size.height},
                 {"ms", round_decimals(ms, 3)}, {"markers", Json::array()}};
    if (work != size) line["detected_at"] = {work.width, work.height};
    for (size_t i = 0; i < markers.size(); ++i) {
      const Marker& m = markers[i];
      Json corners = Json::array();
      for (const auto& c : m.corners) corners.push_back({round_decimals(c.x, 3), round_decimals(c.y, 3)});
      Json marker = {{"id", m.id}, {"dict", m.dict}, {"corners", std::move(corners)}, {"hamming", m.hamming}};
      if (calib) {
        Json ideal = Json::array();
        for (const cv::Point2f& c : undistorted(*calib, m)) ideal.push_back({round_decimals(c.x, 3), round_decimals(c.y, 3)});
        marker["corners_undistorted"] = std::move(ideal);
      }
      if (poses[i]) marker["pose"] = pose_json(*poses[i]);
      line["markers"].push_back(std::move(marker));
    }
    // A path need not be UTF-8: invalid bytes are replaced rather than thrown on.
    std::fputs((json_text(line) + "\n").c_str(), stdout);
  } else {
    std::printf("%s", source.c_str());
    if (frame > 0 || source.empty()) std::printf(" frame %d", frame);
    std::printf(": %zu marker%s (%dx%d", markers.size(), markers.size() == 1 ? "" : "s", size.width, size.height);
    if (work != size) std::printf(", detected at %dx%d", work.width, work.height);
    std::printf(", %.2f ms)\n", ms);
    for (size_t i = 0; i < markers.size(); ++i) {
      const Marker& m = markers[i];
      std::printf("  id %d %s hamming %d corners", m.id, m.dict.c_str(), m.hamming);
      for (const auto& c : m.corners) std::printf(" (%.2f, %.2f)", c.x, c.y);
      if (calib) {
        std::printf(" undistorted");
        for (const cv::Point2f& c : undistorted(*calib, m)) std::printf(" (%.2f, %.2f)", c.x, c.y);
      }
      std::printf("\n");
      if (const auto& p = poses[i]) {
        const PoseAngles a = pose_angles(p->pose);
        std::printf("    pose: t (%.4g, %.4g, %.4g), distance %.4g, tilt %.1f deg, error %.2f px, ambiguity %.2f%s%s\n",
                    p->pose.tvec[0], p->pose.tvec[1], p->pose.tvec[2], a.distance, a.tilt_deg, p->pose.error_px,
                    p->ambiguity, p->ambiguity >= 0.3 ? (p->chosen_by_previous ? " (ambiguous: the previous frame chose)"
                                                                               : " (ambiguous: see the alternative)")
                                                      : "",
                    p->assumed_camera ? " [assumed camera: no --calib]" : "");
      } else if (out.marker_size > 0) {
        // Said, not left out: a quad of no area, or one no pose of the marker projects to through this camera.
        std::printf("    pose: none (no pose of the marker projects to these corners through this camera)\n");
      }
    }
  }
  std::fflush(stdout);
}

void run_video(Output& out, const std::string& path, const Detector& det, int threads) {
  if (Status st = check_input_file(path, kVideoFile); !st) {
    print_problem("%s\n", st.error().c_str());
    return;
  }
  cv::VideoCapture cap;
  try {
    cap.open(path, cv::CAP_FFMPEG);
  } catch (const cv::Exception&) {
    print_problem("%s: cannot open video (unreadable or unsupported)\n", path.c_str());
    return;
  }
  if (!cap.isOpened()) {
    print_problem("%s: cannot open video (unreadable or unsupported)\n", path.c_str());
    return;
  }
  const double declared = cap.get(cv::CAP_PROP_FRAME_COUNT);
  int frame = 0;
  cv::Mat image;
  VideoSearch video;
  for (;;) {
    bool ok = false;
    try {
      ok = cap.read(image);
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (!ok || image.empty()) break;
    report(out, path, frame++, image, det, threads, &video);
  }
  if (frame == 0) print_problem("%s: video has no readable frame\n", path.c_str());
  else if (declared > 0 && frame < static_cast<int>(declared) - 1)
    print_problem("%s: video ended early, after %d of %.0f declared frames\n", path.c_str(), frame, declared);
}

void run_image(Output& out, const std::string& path, const Detector& det, int threads) {
  LoadedImage img = load_image(path);
  if (!img.ok()) {
    print_problem("%s\n", img.error.c_str());
    return;
  }
  report(out, path, 0, img.image, det, threads);
}

}  // namespace

int cmd_detect(int argc, char** argv) {
  CommandLine cl("arwb detect",
                 "Detects markers in each PATH: an image, a folder (its images in name order) or a video. A video's "
                 "frames are searched as video: around the markers the frame before found, at their scale, and "
                 "whole every full_search_interval frames (a preset with full_search_interval: 1 searches every "
                 "frame whole).",
                 "Problems with one PATH are reported on stderr and the others still processed; the exit status is "
                 "non-zero only when no frame could be processed.");
  Output out;
  std::string dict_arg = "ARUCO_ORIGINAL", params_path, calib_path, resize = "off";
  int threads = 1;
  std::vector<std::string> paths;
  cl.app.add_option("PATH", paths, "an image, a folder of images or a video")->required();
  cl.app.add_option("--dict", dict_arg,
                    "dictionaries searched in one pass, OpenCV's names without DICT_, case-insensitive, or a custom "
                    "dictionary file in OpenCV's YAML format")
      ->type_name("NAME[,NAME...]");
  cl.app.add_option("--params", params_path, "a YAML preset of detector parameters (see arwb's parameter table)")
      ->type_name("FILE.yml");
  cl.app.add_option("--calib", calib_path,
                    "a camera calibration (arwb calibrate's file, OpenCV's, the paper's cameraMatrix.xml with its "
                    "distCoeffs.xml beside it, or ROS's ost.yaml; scaled to frames of another size with the same "
                    "aspect ratio): each marker's corners are also given with the lens distortion removed "
                    "(corners_undistorted)")
      ->type_name("FILE");
  cl.app.add_option("--marker-size", out.marker_size,
                    "the markers' side on their outer black edge, in the unit the pose's position is wanted in (50 "
                    "for mm, 0.05 for m): each marker gains its pose (both solutions of a view's ambiguity, their "
                    "errors, the ambiguity ratio); without --calib through a default camera of 60 degrees across, "
                    "marked assumed")
      ->type_name("L")
      ->check(real_number(0.0001, 100000));
  add_resize_option(cl.app, resize);
  cl.app.add_option("--threads", threads, "threads for the detector")->type_name("N")->check(whole_number(1, 64));
  cl.app.add_flag("--json", out.json,
                  "one line per frame: {\"source\",\"frame\",\"width\",\"height\",\"ms\",\"markers\":[...]}");
  if (const auto status = cl.parse(argc, argv)) return *status;

  const auto dicts = dictionaries_option(dict_arg, "arwb detect");
  if (!dicts) return 2;
  DetectorParams params;
  if (!load_params_option(params_path, "arwb detect", params)) return 2;
  if (!calib_path.empty()) {
    Result<Calibration> c = read_calibration(calib_path);
    if (!c) return cl.usage_error("--calib " + c.error());
    out.calib = std::move(*c);
  }
  cv::setNumThreads(threads);
  Detector det(std::move(*dicts), params);
  AcquisitionSettings acquisition{.fps_cap = 0};
  apply_resize_option(resize, acquisition);
  det.set_acquisition(acquisition);

  for (const std::string& path : paths) {
    switch (classify_path(path)) {
      case PathKind::image: run_image(out, path, det, threads); break;
      case PathKind::video: run_video(out, path, det, threads); break;
      case PathKind::folder: {
        std::vector<std::string> skipped;
        std::string folder_error;
        const auto images = list_images(path, &skipped, &folder_error);
        if (!folder_error.empty()) print_problem("%s\n", folder_error.c_str());
        for (const auto& s : skipped) print_problem("%s\n", s.c_str());
        if (images.empty() && folder_error.empty()) print_problem("%s: folder has no images\n", path.c_str());
        for (const auto& image : images) run_image(out, image, det, threads);
        break;
      }
      case PathKind::missing: print_problem("%s: no such file or folder\n", path.c_str()); break;
      case PathKind::other: {
        // load_image names the reason (empty, unknown signature, unsupported format ...).
        run_image(out, path, det, threads);
        break;
      }
    }
  }
  return out.frames > 0 ? 0 : 1;
}

}  // namespace arwb
