#include "calibration/board.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace arwb {

namespace {
std::string num(double v, int decimals = 1) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}
}  // namespace

namespace {

// A chessboard grid found in a grey frame, probed around its corners: whether a grid position is a chessboard
// corner (four squares meeting, bright and dark crosswise), judged from the grey levels at the centres of the
// four squares around it, placed by a homography of the known corners near it (local, so that lens distortion
// does not throw the prediction off as one fit over the whole board would).
class GridProbe {
 public:
  GridProbe(const cv::Mat& grey, const BoardSpec& board, const std::vector<cv::Point2f>& corners) : grey_(grey) {
    for (int r = 0; r < board.rows; ++r)
      for (int c = 0; c < board.cols; ++c) known_[{c, r}] = corners[size_t(r * board.cols + c)];
  }
  // The contrast across the diagonals at (c, r) when it is a chessboard corner (each diagonal alike, the two
  // different); 0 when it is not, or the squares around it leave the image. *at gets its predicted place.
  double crossing(int c, int r, cv::Point2f* at = nullptr) const {
    std::vector<cv::Point2f> from, to;
    for (const auto& [pos, p] : known_)
      if (std::abs(pos.first - c) <= 2 && std::abs(pos.second - r) <= 2) {
        from.emplace_back(float(pos.first), float(pos.second));
        to.push_back(p);
      }
    if (from.size() < 6) return 0;
    const cv::Mat H = cv::findHomography(from, to);
    if (H.empty()) return 0;
    std::vector<cv::Point2d> in{{c + 0.5, r + 0.5}, {c - 0.5, r - 0.5}, {c + 0.5, r - 0.5}, {c - 0.5, r + 0.5}, {double(c), double(r)}}, out;
    cv::perspectiveTransform(in, out, H);
    double v[4];
    for (int i = 0; i < 4; ++i) {
      const int x = int(std::lround(out[size_t(i)].x)), y = int(std::lround(out[size_t(i)].y));
      if (x < 0 || y < 0 || x >= grey_.cols || y >= grey_.rows) return 0;
      v[i] = grey_.at<uchar>(y, x);
    }
    if (at) *at = cv::Point2f(out[4]);
    const double across = std::abs(v[0] + v[1] - v[2] - v[3]) / 2, alike = std::abs(v[0] - v[1]) + std::abs(v[2] - v[3]);
    return alike < 0.5 * across ? across : 0;
  }
  void add(int c, int r, cv::Point2f p) { known_[{c, r}] = p; }

 private:
  const cv::Mat& grey_;
  std::map<std::pair<int, int>, cv::Point2f> known_;
};

cv::Mat grey_of(const cv::Mat& frame) {
  if (frame.channels() == 1) return frame;
  cv::Mat grey;
  cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

// The contrast of a typical corner of the grid, and whether nearly all of its corners are chessboard corners:
// findChessboardCornersSB, asked for fewer corners than the board has, can return a grid that runs along the
// board's outer edge (where squares meet the white paper), which would poison a calibration.
bool all_corners_cross(const cv::Mat& grey, const BoardSpec& board, const std::vector<cv::Point2f>& corners,
                       double* typical) {
  const GridProbe probe(grey, board, corners);
  std::vector<double> x;
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.cols; ++c) x.push_back(probe.crossing(c, r));
  std::vector<double> sorted = x;
  std::sort(sorted.begin(), sorted.end());
  *typical = sorted[sorted.size() / 2];
  const size_t crossing = size_t(std::count_if(x.begin(), x.end(), [&](double v) { return v > 0.3 * *typical; }));
  return *typical > 0 && crossing * 10 >= x.size() * 9;
}

}  // namespace

BoardDetection detect_chessboard(const cv::Mat& frame, const BoardSpec& board) {
  BoardDetection d;
  const cv::Mat grey = grey_of(frame);
  const cv::Size pattern(board.cols, board.rows);
  try {
    d.found = cv::findChessboardCornersSB(grey, pattern, d.corners,
                                          cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_ACCURACY);
    if (d.found) d.edge_width_px = cv::estimateChessboardSharpness(grey, pattern, d.corners)[0];
  } catch (const cv::Exception&) {   // a frame OpenCV cannot work on is a frame without a board
    d = {};
  }
  double typical = 0;
  if (d.found && (d.corners.size() != size_t(board.cols) * size_t(board.rows) ||
                  !all_corners_cross(grey, board, d.corners, &typical)))
    d = {};
  return d;
}

BoardDetection detect_board(const cv::Mat& frame, const BoardSpec& board) {
  if (board.kind == BoardKind::chessboard) return detect_chessboard(frame, board);
  return {};   // ChArUco: not read yet
}

std::optional<cv::Size> find_any_chessboard(const cv::Mat& frame, std::initializer_list<cv::Size> sizes) {
  const cv::Mat grey = grey_of(frame);
  for (const cv::Size s : sizes) {
    std::vector<cv::Point2f> corners;
    bool found = false;
    try {
      found = cv::findChessboardCorners(grey, s, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE |
                                                              cv::CALIB_CB_FAST_CHECK);
    } catch (const cv::Exception&) {
    }
    double typical = 0;
    if (found && all_corners_cross(grey, BoardSpec{.cols = s.width, .rows = s.height, .square_mm = 1}, corners, &typical)) return s;
  }
  return std::nullopt;
}

std::optional<cv::Size> larger_board(const cv::Mat& frame, const BoardSpec& board,
                                     const std::vector<cv::Point2f>& corners) {
  const cv::Mat grey = grey_of(frame);
  double reference = 0;
  if (!all_corners_cross(grey, board, corners, &reference)) return std::nullopt;
  GridProbe probe(grey, board, corners);
  int c0 = 0, c1 = board.cols - 1, r0 = 0, r1 = board.rows - 1;   // the grid's extent
  // The line beyond the grid at column (or row) `at_index` is board when most of its points cross; its corners
  // are then known too, and the next line beyond is judged from them.
  const auto grow = [&](bool column, int at_index) {
    std::vector<std::pair<std::pair<int, int>, cv::Point2f>> found;
    const int from = column ? r0 : c0, to = column ? r1 : c1;
    for (int i = from; i <= to; ++i) {
      const int c = column ? at_index : i, r = column ? i : at_index;
      cv::Point2f p;
      if (probe.crossing(c, r, &p) > 0.5 * reference) found.push_back({{c, r}, p});
    }
    if (2 * found.size() <= size_t(to - from + 1)) return false;
    for (const auto& [pos, p] : found) probe.add(pos.first, pos.second, p);
    return true;
  };
  for (bool again = true; again && c1 - c0 < 39 && r1 - r0 < 39;) {
    again = false;
    if (grow(true, c1 + 1)) ++c1, again = true;
    if (grow(true, c0 - 1)) --c0, again = true;
    if (grow(false, r1 + 1)) ++r1, again = true;
    if (grow(false, r0 - 1)) --r0, again = true;
  }
  const cv::Size size(c1 - c0 + 1, r1 - r0 + 1);
  if (size == cv::Size(board.cols, board.rows)) return std::nullopt;
  return size;
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
