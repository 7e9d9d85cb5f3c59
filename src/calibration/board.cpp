#include "calibration/board.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace arwb {

namespace {
std::string num(double v, int decimals = 1) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}
}  // namespace

std::string BoardSpec::describe() const {
  return "chessboard " + std::to_string(cols) + "x" + std::to_string(rows) + " inner corners (" +
         std::to_string(cols + 1) + "x" + std::to_string(rows + 1) + " squares), " + num(square_mm, 2) +
         " mm squares";
}

std::vector<cv::Point3f> BoardSpec::object_points() const {
  std::vector<cv::Point3f> pts;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) pts.emplace_back(float(c * square_mm), float(r * square_mm), 0.f);
  return pts;
}

BoardDetection detect_chessboard(const cv::Mat& frame, const BoardSpec& board) {
  BoardDetection d;
  cv::Mat grey;
  if (frame.channels() == 3) cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  else grey = frame;
  const cv::Size pattern(board.cols, board.rows);
  try {
    d.found = cv::findChessboardCornersSB(grey, pattern, d.corners,
                                          cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_ACCURACY);
    if (d.found) d.edge_width_px = cv::estimateChessboardSharpness(grey, pattern, d.corners)[0];
  } catch (const cv::Exception&) {   // a frame OpenCV cannot work on is a frame without a board
    d = {};
  }
  if (d.found && d.corners.size() != size_t(board.cols) * size_t(board.rows)) d = {};
  return d;
}

ViewPose view_pose(const std::vector<cv::Point2f>& corners, const BoardSpec& board, cv::Size image) {
  // The board's four outer inner corners, in its own row-by-row order.
  const cv::Point2d a = corners[0], b = corners[size_t(board.cols) - 1], c = corners.back(),
                    d = corners[corners.size() - size_t(board.cols)];
  // Area of the quadrilateral a b c d from its diagonals.
  const cv::Point2d p = c - a, q = d - b;
  const double area = std::abs(p.x * q.y - p.y * q.x) / 2;
  const double border = std::sqrt(area);
  cv::Point2d mean(0, 0);
  for (const cv::Point2f& pt : corners) mean += cv::Point2d(pt);
  mean *= 1.0 / double(corners.size());
  ViewPose v;
  const auto span = [&](double m, double extent) {
    const double room = extent - border;
    return room <= 0 ? 0.5 : std::clamp((m - border / 2) / room, 0.0, 1.0);
  };
  v.x = span(mean.x, image.width);
  v.y = span(mean.y, image.height);
  v.size = std::sqrt(area / (double(image.width) * image.height));
  // Skew: the angle at corner b between its sides to a and to c; a right angle is no skew.
  const cv::Point2d u = a - b, w = c - b;
  const double angle = std::acos(std::clamp(u.dot(w) / (cv::norm(u) * cv::norm(w) + 1e-12), -1.0, 1.0));
  v.skew = std::min(1.0, 2 * std::abs(CV_PI / 2 - angle));
  return v;
}

Verdict ViewSelector::consider(const BoardDetection& det, cv::Size image) {
  const std::vector<cv::Point2f> previous = std::move(previous_);
  previous_ = det.found ? det.corners : std::vector<cv::Point2f>{};
  if (!det.found) return {false, "no board", "no board"};
  if (int(kept_.size()) >= opt_.max_views)
    return {false, "enough views (" + std::to_string(opt_.max_views) + ", --max-views)", "enough"};
  double margin = 1e9;
  for (const cv::Point2f& p : det.corners)
    margin = std::min({margin, double(p.x), double(p.y), image.width - 1.0 - p.x, image.height - 1.0 - p.y});
  if (margin < opt_.min_edge_margin_px)
    return {false, "near the edge (a corner " + num(margin) + " px from it, need " + num(opt_.min_edge_margin_px) + ")",
            "edge"};
  if (opt_.video) {
    if (previous.empty()) return {false, "moving (no board in the previous frame to compare with)", "moving"};
    double motion = 0;
    for (size_t i = 0; i < previous.size(); ++i) motion += cv::norm(det.corners[i] - previous[i]);
    motion /= double(previous.size());
    if (motion > opt_.max_motion_px)
      return {false, "moving (corners moved " + num(motion) + " px since the previous frame, limit " +
                         num(opt_.max_motion_px) + ")", "moving"};
  }
  if (det.edge_width_px > opt_.max_edge_width_px)
    return {false, "blurred (edges " + num(det.edge_width_px) + " px wide, limit " + num(opt_.max_edge_width_px) + ")",
            "blurred"};
  const ViewPose pose = view_pose(det.corners, board_, image);
  for (size_t i = 0; i < kept_.size(); ++i) {
    const ViewPose& k = kept_[i];
    const double dist = std::abs(k.x - pose.x) + std::abs(k.y - pose.y) + std::abs(k.size - pose.size) +
                        std::abs(k.skew - pose.skew);
    if (dist < opt_.min_pose_distance)
      return {false, "like view " + std::to_string(i + 1) + " (pose difference " + num(dist, 2) + " < " +
                         num(opt_.min_pose_distance, 2) + ")", "similar"};
  }
  kept_.push_back(pose);
  return {true, "kept", "kept"};
}

}  // namespace arwb
