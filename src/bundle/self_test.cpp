// The export's self-test (export_parts.hpp): each id the scene maps drawn alone on a synthetic frame, detected
// with the scene's dictionary and run through the scene as the workbench runs it; the web cards it shows are
// kept as pictures for the bundle.
#include "bundle/export_parts.hpp"

#include "detect/detector.hpp"
#include "inspect/trace_view.hpp"
#include "script/self_test_verdict.hpp"
#include "synth/synth.hpp"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace arwb::bundle {

namespace {

// The self-test's frame: one marker, upright and frontal, well inside a small frame, one second apart so each
// id enters alone (the tracker holds a missed marker for a quarter second). With a calibration that names its
// image size the frame takes that size's aspect (see test_frame), since a calibration fits only frames of its
// own shape.
const cv::Size kTestFrame{320, 240};
constexpr int kCalibratedTestWidth = 640;
constexpr double kTestMarkerPx = 120;

// The self-test's frame for a calibration: its own image size scaled to a 640-pixel width (a 16:9 camera's
// 1280x720 gives 640x360), or the size itself when rounding the height would change the aspect more than
// calibration_for_size allows (a very wide strip); the small default frame when it names no size. A shape whose
// frame would be over 4096x4096 pixels (a 1x65536 strip: 640x41943040) is refused with the sizes.
Result<cv::Size> test_frame(const Calibration& c) {
  const cv::Size own = c.image_size;
  if (own.width <= 0 || own.height <= 0) return kTestFrame;
  const int height = std::max(1, int(std::lround(double(kCalibratedTestWidth) * own.height / own.width)));
  const cv::Size scaled{kCalibratedTestWidth, height};
  const double a = double(own.width) * scaled.height, b = double(scaled.width) * own.height;
  const bool same_aspect = std::abs(a - b) <= 0.004 * std::max(a, b);
  // In doubles: cv::Size::area() is an int, which 640x41943040 overflows.
  const auto small_enough = [](cv::Size s) { return double(s.width) * double(s.height) <= 4096.0 * 4096.0; };
  // The marker (kTestMarkerPx) must fit well inside the frame either way.
  if (same_aspect && height >= 2 * kTestMarkerPx && small_enough(scaled)) return scaled;
  if (own.width >= 2 * kTestMarkerPx && own.height >= 2 * kTestMarkerPx && small_enough(own)) return own;
  if (small_enough(scaled)) return scaled;
  return fail("made for " + std::to_string(own.width) + "x" + std::to_string(own.height) +
              ", a shape the self-test cannot render (640 pixels wide, a frame of it would be " +
              std::to_string(scaled.width) + "x" + std::to_string(scaled.height) + ")");
}

}  // namespace

Result<TestResult> self_test(SceneStage& stage, const Dictionary& dict, const std::optional<Calibration>& calib,
                             const ExportOptions& options) {
  const std::map<int, std::vector<size_t>> by_id = script::mapped_ids(stage.runtime());
  Detector detector({dict});
  std::shared_ptr<const Calibration> camera;
  cv::Size frame_size = kTestFrame;
  if (calib) {
    const Result<cv::Size> size = test_frame(*calib);
    if (!size) return fail("calibration: " + size.error());
    frame_size = *size;
    Result<Calibration> fitted = calibration_for_size(*calib, frame_size);
    if (!fitted) return fail("calibration: " + fitted.error());
    camera = std::make_shared<const Calibration>(std::move(*fitted));
  }
  TestResult out;
  std::set<std::pair<std::string, std::string>> cards_seen;
  double t = 0;
  size_t done = 0;
  for (const auto& [id, mappings] : by_id) {
    if (++done % 100 == 0) say(options, "self-test: " + std::to_string(done) + " of " + std::to_string(by_id.size()) + " ids");
    cv::Mat raw(frame_size, CV_8UC3, cv::Scalar(200, 200, 200));
    const Quad corners = project_square({frame_size.width / 2.0, frame_size.height / 2.0}, kTestMarkerPx, 0, 0, 0, 500);
    draw_marker(raw, dict, id, corners, 1.5);
    Frame f;
    f.index = done;
    f.time_s = t;
    detector.detect(raw, &f.trace, TraceLevel::full, 1, &f.image);
    render_stage_views(f.image, f.trace, f.views);
    f.loaded_calibration = camera;
    f.pose_marker_side = 1;
    stage.run(f, t, 1e9);
    t += 1.0;
    const std::vector<std::string> errors = stage.take_errors();
    bool detected = false;
    for (const Marker& m : f.trace.markers) detected = detected || m.id == id;
    for (const size_t mi : mappings) {
      const script::MappingVerdict v = script::judge_mapping(id, mi, detected, f.scene, f.overlays, errors);
      SelfTestRow row;
      row.id = id;
      row.mapping_line = v.line;
      row.media = v.media;
      row.detected = detected;
      row.fired = v.fired;
      row.detail = v.detail;
      if (!detected && !unambiguous(dict, id))
        row.detail += " (it reads the same as a marker turned: it cannot be told apart)";
      const Overlay* shown = v.shown;
      if (shown && shown->media.kind == MediaKind::web &&
          cards_seen.insert({shown->media.url, shown->media.title}).second) {
        uint64_t version = 0;
        const std::shared_ptr<const cv::Mat> picture = shown->content ? shown->content->current(&version) : nullptr;
        std::vector<unsigned char> png;
        if (picture && !picture->empty() && cv::imencode(".png", *picture, png)) {
          out.cards.push_back({shown->media.url, shown->media.title, ""});
          out.card_png.emplace_back(png.begin(), png.end());
        }
      }
      out.passed = out.passed && row.fired;
      out.rows.push_back(std::move(row));
    }
  }
  return out;
}

}  // namespace arwb::bundle
