// The frame's camera and calibration (engine_state.hpp): the loaded calibration fitted to the frame's size, the
// Calibrate workspace's session fed with new frames, the synthetic camera's truth and the undistorted image.
#include "workbench/engine_state.hpp"

#include "capture/opencv_error.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>

namespace arwb {

void Engine::State::camera(Worker& w, Frame& f) {
  if (w.loaded_raw && f.image.size() != w.loaded_for) {
    w.loaded_for = f.image.size();
    if (Result<Calibration> c = calibration_for_size(*w.loaded_raw, f.image.size())) {
      w.loaded = std::make_shared<const Calibration>(std::move(*c));
    } else {
      w.loaded.reset();
      log_(2, c.error());
    }
  }
  if (!w.loaded_raw) w.loaded.reset();
  f.loaded_calibration = w.loaded;
  const bool sized = w.marker_size > 0 && std::isfinite(w.marker_size);
  f.pose_marker_side = sized ? w.marker_size : 1.0;
  f.pose_unit = sized ? "mm" : "marker sides";
}

// The board is searched in the source's own frame (w.raw), not the working image: photographs of 1920x1080 are
// calibrated at 1920x1080 as `arwb calibrate` calibrates them, and the solve is fitted to the working size where
// it is used (the undistorted view).
void Engine::State::calibrate(Worker& w, Frame& f, bool fresh) {
  if (w.calibrating) {
    CalibrationSession& session = w.calibration();
    if (fresh) {
      const bool stills = w.info.kind == SourceKind::folder || w.info.kind == SourceKind::image;
      session.set_stills(stills);
      const std::string name = w.info.kind == SourceKind::folder && !w.info.item.empty() ? w.info.item
                               : w.info.kind == SourceKind::video ? "frame " + std::to_string(w.info.position)
                                                                  : "frame " + std::to_string(f.index);
      // Offered to the search on the session's own thread: a frame without a board can take OpenCV a second, which
      // must not stop the live view (nor quitting). A folder's image that comes while it is busy is skipped; a
      // looping folder shows it again.
      // A synthetic world stepped per frame waits for the search instead: a frame skipped would put the next
      // frame judged a step further on, and a slow machine would see the board move between every two.
      const auto* syn = dynamic_cast<const SyntheticSource*>(w.source.get());
      if (syn && syn->frame_step() > 0) {
        session.feed(w.raw, name);
        w.calibration_searched = true;
      } else {
        w.calibration_searched = session.offer(w.raw, name);
      }
      w.calibration_name = name;
    } else if (!w.calibration_searched) {
      // The frame shown was skipped while the search was busy: searched once the search is free, so that a frozen
      // or ended source shows its board (the finished search's poll brings the worker back here).
      w.calibration_searched = session.offer(w.raw, w.calibration_name);
    }
    f.calibration_name = w.calibration_name;
    f.calibration = session.snapshot();
  }
  if (const auto* syn = dynamic_cast<const SyntheticSource*>(w.source.get())) {
    if (const SynthCamera* cam = syn->board_camera()) {
      Calibration t;
      t.camera_matrix = cam->camera_matrix;   // the source's own pixels, where the board is searched
      t.distortion = cam->distortion;
      t.image_size = cam->size;
      t.source = "the synthetic camera";
      f.calibration_truth = std::move(t);
    }
  }
  if (!w.undistort) return;
  // The newest solve, else the loaded file.
  const Calibration* use = nullptr;
  std::shared_ptr<const void> owner;
  std::string by;
  std::shared_ptr<const CalibrationSnapshot> snap = w.session ? w.session->snapshot() : nullptr;
  if (snap && snap->solution && (w.fitted_of != snap->solution || w.fitted_for != f.image.size())) {
    w.fitted_of = snap->solution;
    w.fitted_for = f.image.size();
    Result<Calibration> c = calibration_for_size(snap->solution->calibration, f.image.size());
    w.fitted = c ? std::make_shared<const Calibration>(std::move(*c)) : nullptr;
  }
  if (snap && snap->solution && w.fitted) {
    use = w.fitted.get();
    owner = w.fitted;
    by = "the solve of " + std::to_string(snap->solution->view_names.size()) + " views";
  } else if (w.loaded) {
    use = w.loaded.get();
    owner = w.loaded;
    by = w.loaded->source;
  }
  if (!use) return;
  if (owner != w.maps_of || f.image.size() != w.maps_size) {
    try {
      cv::initUndistortRectifyMap(cv::Mat(use->camera_matrix), use->distortion, cv::noArray(),
                                  cv::Mat(use->camera_matrix), f.image.size(), CV_16SC2, w.map1, w.map2);
    } catch (const cv::Exception& e) {
      log_(2, "undistort: " + one_line_reason(e));
      w.undistort = false;
      return;
    }
    w.maps_of = owner;
    w.maps_size = f.image.size();
  }
  cv::remap(f.image, f.undistorted, w.map1, w.map2, cv::INTER_LINEAR);
  f.undistorted_by = by;
}

}  // namespace arwb
