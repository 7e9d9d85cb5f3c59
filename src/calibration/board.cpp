#include "calibration/board.hpp"

#include "base/decimals.hpp"
#include "detect/dictionary.hpp"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>

namespace arwb {

namespace {
std::string figure(double v, int decimals = 1) { return fixed_text(v, decimals); }
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

// Each corner refined by cornerSubPix with a window of a `divisor`-th of the distance to its nearest neighbour
// on the grid (2 px to `max_win`), so that the window holds one corner and no other feature. ids: each corner's
// place on a grid `grid_width` wide, row by row (empty: the corners are the whole grid in order).
void refine_corners(const cv::Mat& grey, std::vector<cv::Point2f>& corners, const std::vector<int>& ids,
                    int grid_width, int divisor, int max_win) {
  const auto id_of = [&](size_t i) { return ids.empty() ? int(i) : ids[i]; };
  std::map<int, size_t> at;
  for (size_t i = 0; i < corners.size(); ++i) at[id_of(i)] = i;
  const std::vector<cv::Point2f> found = corners;   // the neighbours' distances before any is moved
  for (size_t i = 0; i < found.size(); ++i) {
    const int id = id_of(i), c = id % grid_width;
    double nearest = 1e9;
    for (const int n : {c > 0 ? id - 1 : -1, c + 1 < grid_width ? id + 1 : -1, id - grid_width, id + grid_width})
      if (const auto it = at.find(n); n >= 0 && it != at.end())
        nearest = std::min(nearest, double(cv::norm(found[it->second] - found[i])));
    if (nearest > 1e8) continue;
    const int win = std::clamp(int(nearest / divisor), 2, max_win);
    std::vector<cv::Point2f> one{found[i]};
    cv::cornerSubPix(grey, one, cv::Size(win, win), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 0.001));
    corners[i] = one[0];
  }
}

}  // namespace

BoardDetection detect_chessboard(const cv::Mat& frame, const BoardSpec& board) {
  BoardDetection d;
  const cv::Mat grey = grey_of(frame);
  const cv::Size pattern(board.cols, board.rows);
  try {
    d.found = cv::findChessboardCornersSB(grey, pattern, d.corners,
                                          cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_ACCURACY);
    // findChessboardCornersSB's corners are pulled toward the image's centre on tilted views (0.01 to 0.03 px,
    // which biased fx by 0.2 %, four of its own deviations); refined by cornerSubPix with a window of a quarter
    // of a square they are not, and the solve's 95 % intervals hold the true camera (tested over seeds).
    if (d.found) refine_corners(grey, d.corners, {}, board.cols, 4, 8);
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

cv::Ptr<cv::aruco::CharucoBoard> opencv_charuco_board(const BoardSpec& board) {
  using namespace cv::aruco;
  static const std::map<std::string, PREDEFINED_DICTIONARY_NAME> table = {
      {"4X4_50", DICT_4X4_50},       {"4X4_100", DICT_4X4_100},       {"4X4_250", DICT_4X4_250},
      {"4X4_1000", DICT_4X4_1000},   {"5X5_50", DICT_5X5_50},         {"5X5_100", DICT_5X5_100},
      {"5X5_250", DICT_5X5_250},     {"5X5_1000", DICT_5X5_1000},     {"6X6_50", DICT_6X6_50},
      {"6X6_100", DICT_6X6_100},     {"6X6_250", DICT_6X6_250},       {"6X6_1000", DICT_6X6_1000},
      {"7X7_50", DICT_7X7_50},       {"7X7_100", DICT_7X7_100},       {"7X7_250", DICT_7X7_250},
      {"7X7_1000", DICT_7X7_1000},   {"ARUCO_ORIGINAL", DICT_ARUCO_ORIGINAL},
      {"APRILTAG_16h5", DICT_APRILTAG_16h5}, {"APRILTAG_25h9", DICT_APRILTAG_25h9},
      {"APRILTAG_36h10", DICT_APRILTAG_36h10}, {"APRILTAG_36h11", DICT_APRILTAG_36h11}};
  // detect's name for the dictionary (case and the DICT_ prefix as the user gave them) is the key.
  const std::optional<Dictionary> d = dictionary_by_name(board.dictionary);
  if (!d || board.kind != BoardKind::charuco || !board.problem().empty()) return {};
  const auto it = table.find(d->name());
  if (it == table.end()) return {};
  // One board per thread, made again only when the board changes: detection runs on every frame.
  thread_local std::string key;
  thread_local cv::Ptr<CharucoBoard> made;
  const std::string wanted = board.describe();
  if (!made || key != wanted) {
    made = CharucoBoard::create(board.cols, board.rows, float(board.square_mm / 1000), float(board.marker_mm / 1000),
                                getPredefinedDictionary(it->second));
    key = wanted;
  }
  return made;
}

// How wide the black-white edges of a ChArUco view are, px: OpenCV's chessboard measure reads the markers in the
// white squares as edges, so this one looks only across the square edges between neighbouring corners, within the
// white margin a white square keeps around its marker. Per edge: the contrast over the steepest step of a profile
// across it (a step blurred by a Gaussian of sigma s gives about 2.5 s, as its 10-90 % rise does); the median of
// all. 0 when no two neighbouring corners were found.
double charuco_edge_width(const cv::Mat& grey, const BoardSpec& board, const std::vector<cv::Point2f>& corners,
                          const std::vector<int>& ids) {
  const int width = board.inner_corners().width;
  const double margin_share = 0.9 * (board.square_mm - board.marker_mm) / (2 * board.square_mm);
  std::map<int, cv::Point2f> by_id;
  for (size_t i = 0; i < ids.size(); ++i) by_id[ids[i]] = corners[i];
  std::vector<double> widths;
  constexpr double kStep = 0.25;
  for (const auto& [id, p] : by_id)
    for (const int next : {id % width + 1 < width ? id + 1 : -1, id + width}) {
      const auto it = by_id.find(next);
      if (next < 0 || it == by_id.end()) continue;
      const cv::Point2d a(p), b(it->second), mid = (a + b) * 0.5;
      const double len = cv::norm(b - a), reach = margin_share * len;
      if (len < 4 || reach < 1.5) continue;
      const cv::Point2d normal(-(b - a).y / len, (b - a).x / len);
      std::vector<double> profile;
      for (double t = -reach; t <= reach; t += kStep) {
        const cv::Point2d q = mid + normal * t;
        if (q.x < 0 || q.y < 0 || q.x > grey.cols - 2 || q.y > grey.rows - 2) break;
        const int x = int(q.x), y = int(q.y);
        const double fx = q.x - x, fy = q.y - y;
        profile.push_back((1 - fy) * ((1 - fx) * grey.at<uchar>(y, x) + fx * grey.at<uchar>(y, x + 1)) +
                          fy * ((1 - fx) * grey.at<uchar>(y + 1, x) + fx * grey.at<uchar>(y + 1, x + 1)));
      }
      if (profile.size() < 5) continue;
      const auto [lo, hi] = std::minmax_element(profile.begin(), profile.end());
      double steepest = 0;
      for (size_t k = 1; k < profile.size(); ++k) steepest = std::max(steepest, std::abs(profile[k] - profile[k - 1]) / kStep);
      if (steepest > 0 && *hi - *lo > 20) widths.push_back((*hi - *lo) / steepest);
    }
  if (widths.empty()) return 0;
  std::nth_element(widths.begin(), widths.begin() + std::ptrdiff_t(widths.size() / 2), widths.end());
  return widths[widths.size() / 2];
}

BoardDetection detect_charuco(const cv::Mat& frame, const BoardSpec& board) {
  BoardDetection d;
  const cv::Ptr<cv::aruco::CharucoBoard> cb = opencv_charuco_board(board);
  if (!cb) return d;
  const cv::Mat grey = grey_of(frame);
  const cv::Size grid = board.inner_corners();
  try {
    std::vector<std::vector<cv::Point2f>> markers, rejected;
    std::vector<int> marker_ids;
    const cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
    cv::aruco::detectMarkers(grey, cb->dictionary, markers, marker_ids, params, rejected);
    if (marker_ids.empty()) return d;
    // Markers missed at first are looked for again where the board says they should be.
    cv::aruco::refineDetectedMarkers(grey, cb, markers, marker_ids, rejected);
    std::vector<cv::Point2f> corners;
    std::vector<int> ids;
    cv::aruco::interpolateCornersCharuco(markers, marker_ids, grey, cb, corners, ids);
    std::vector<size_t> order(ids.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return ids[a] < ids[b]; });
    for (size_t i : order) {
      if (ids[i] < 0 || ids[i] >= grid.area()) continue;
      d.corners.push_back(corners[i]);
      d.ids.push_back(ids[i]);
    }
    // OpenCV 4.6's interpolation leaves its corners about half a pixel down and right of where they are (measured
    // on synthetic views: (+0.5, +0.5) px), and further off on tilted views; refined again, each with a window that
    // stays clear of the markers' corners (a fourteenth of its nearest neighbour's distance), they come within a
    // tenth of a pixel.
    refine_corners(grey, d.corners, d.ids, grid.width, 14, 4);
  } catch (const cv::Exception&) {   // a frame OpenCV cannot work on is a frame without a board
    return {};
  }
  if (int(d.ids.size()) < kMinCharucoCorners) return {};
  // All on one line (a row, a column, a diagonal), the corners cannot place the board's plane.
  const std::vector<cv::Point3f> obj = board.object_points();
  const cv::Point3f p0 = obj[size_t(d.ids[0])], p1 = obj[size_t(d.ids[1])];
  bool spread = false;
  for (int id : d.ids) {
    const cv::Point3f p = obj[size_t(id)];
    spread = spread || std::abs((p1.x - p0.x) * (p.y - p0.y) - (p1.y - p0.y) * (p.x - p0.x)) > 1e-6;
  }
  if (!spread) return {};
  d.found = true;
  d.edge_width_px = charuco_edge_width(grey, board, d.corners, d.ids);
  return d;
}

BoardDetection detect_board(const cv::Mat& frame, const BoardSpec& board) {
  if (board.kind == BoardKind::chessboard) return detect_chessboard(frame, board);
  return detect_charuco(frame, board);
}

std::optional<cv::Size> find_any_chessboard(const cv::Mat& frame, std::vector<cv::Size> sizes) {
  const cv::Mat grey = grey_of(frame);
  std::stable_sort(sizes.begin(), sizes.end(), [](cv::Size a, cv::Size b) { return a.area() > b.area(); });
  for (const cv::Size s : sizes) {
    if (s.width < 2 || s.height < 2) continue;
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
  return view_pose(corners, {}, board, image);
}

namespace {

// The ROS terms from what both kinds of view give: the corners seen, the area they cover, and three of the board's
// outer corners a, b, c in its own order (the skew is the angle at b; a right angle is no skew).
ViewPose pose_terms(const std::vector<cv::Point2f>& corners, double area, cv::Point2d a, cv::Point2d b, cv::Point2d c,
                    cv::Size image) {
  const double border = std::sqrt(area);
  cv::Point2d mean(0, 0);
  for (const cv::Point2f& pt : corners) mean += cv::Point2d(pt);
  mean *= 1.0 / double(corners.size());
  const auto span = [&](double m, double extent) {
    const double room = extent - border;
    return room <= 0 ? 0.5 : std::clamp((m - border / 2) / room, 0.0, 1.0);
  };
  ViewPose v;
  v.x = span(mean.x, image.width);
  v.y = span(mean.y, image.height);
  v.size = std::sqrt(area / (double(image.width) * image.height));
  const cv::Point2d u = a - b, w = c - b;
  const double angle = std::acos(std::clamp(u.dot(w) / (cv::norm(u) * cv::norm(w) + 1e-12), -1.0, 1.0));
  v.skew = std::min(1.0, 2 * std::abs(CV_PI / 2 - angle));
  return v;
}

}  // namespace

ViewPose view_pose(const std::vector<cv::Point2f>& corners, const std::vector<int>& ids, const BoardSpec& board,
                   cv::Size image) {
  const cv::Size grid = board.inner_corners();
  if (corners.size() < 4) return {};
  if (!ids.empty() || board.kind == BoardKind::charuco) {
    // Part of the board, or a ChArUco board: its outline placed by the homography of the corners seen.
    std::vector<int> all(corners.size());
    std::iota(all.begin(), all.end(), 0);
    const std::vector<int>& which = ids.empty() ? all : ids;
    const std::vector<cv::Point3f> obj = board.object_points();
    std::vector<cv::Point2f> plane;
    for (int id : which) plane.emplace_back(obj[size_t(id)].x, obj[size_t(id)].y);
    std::vector<cv::Point2f> hull;
    cv::convexHull(corners, hull);
    const double area = cv::contourArea(hull);
    const cv::Mat H = cv::findHomography(plane, corners);
    if (H.empty()) {   // no outline to measure the skew on: none is counted
      const cv::Point2d m(corners[0]);
      return pose_terms(corners, area, m + cv::Point2d(1, 0), m, m + cv::Point2d(0, 1), image);
    }
    const float w = float(board.square_mm * (grid.width - 1)), h = float(board.square_mm * (grid.height - 1));
    const std::vector<cv::Point2f> outline{{0, 0}, {w, 0}, {w, h}};
    std::vector<cv::Point2f> o;
    cv::perspectiveTransform(outline, o, H);
    return pose_terms(corners, area, o[0], o[1], o[2], image);
  }
  // The board's four outer inner corners, in its own row-by-row order; the area of a b c d from its diagonals.
  const cv::Point2d a = corners[0], b = corners[size_t(grid.width) - 1], c = corners.back(),
                    d = corners[corners.size() - size_t(grid.width)];
  const cv::Point2d p = c - a, q = d - b;
  return pose_terms(corners, std::abs(p.x * q.y - p.y * q.x) / 2, a, b, c, image);
}

Verdict ViewSelector::consider(const BoardDetection& det, cv::Size image) {
  const std::vector<cv::Point2f> previous = std::move(previous_);
  const std::vector<int> previous_ids = std::move(previous_ids_);
  previous_ = det.found ? det.corners : std::vector<cv::Point2f>{};
  previous_ids_ = det.found ? det.ids : std::vector<int>{};
  if (!det.found) return {false, "no board", "no board"};
  if (int(kept_.size()) >= opt_.max_views)
    return {false, "enough views (" + std::to_string(opt_.max_views) + ", --max-views)", "enough"};
  const size_t all = size_t(board_.inner_corners().area());
  // A view of part of the board says how much of it.
  const std::string part = det.ids.empty() || det.ids.size() == all ? std::string()
                           : " (" + std::to_string(det.ids.size()) + " of " + std::to_string(all) + " corners seen)";
  double margin = 1e9;
  for (const cv::Point2f& p : det.corners)
    margin = std::min({margin, double(p.x), double(p.y), image.width - 1.0 - p.x, image.height - 1.0 - p.y});
  if (margin < opt_.min_edge_margin_px)
    return {false,
            "near the edge (a corner " + figure(margin) + " px from it, need " + figure(opt_.min_edge_margin_px) + ")",
            "edge"};
  if (opt_.video) {
    if (previous.empty()) return {false, "moving (no board in the previous frame to compare with)", "moving"};
    // Motion over the corners both frames hold: all of them for a chessboard, those with the same id for ChArUco.
    double motion = 0;
    size_t common = 0;
    if (det.ids.empty() && previous_ids.empty() && previous.size() == det.corners.size()) {
      for (size_t i = 0; i < previous.size(); ++i) motion += cv::norm(det.corners[i] - previous[i]);
      common = previous.size();
    } else {
      for (size_t i = 0, j = 0; i < det.ids.size() && j < previous_ids.size();) {
        if (det.ids[i] < previous_ids[j]) ++i;
        else if (previous_ids[j] < det.ids[i]) ++j;
        else motion += cv::norm(det.corners[i++] - previous[j++]), ++common;
      }
    }
    if (common == 0) return {false, "moving (no corner seen in the previous frame too)", "moving"};
    motion /= double(common);
    if (motion > opt_.max_motion_px)
      return {false, "moving (corners moved " + figure(motion) + " px since the previous frame, limit " +
                         figure(opt_.max_motion_px) + ")", "moving"};
  }
  if (det.edge_width_px > opt_.max_edge_width_px)
    return {false,
            "blurred (edges " + figure(det.edge_width_px) + " px wide, limit " + figure(opt_.max_edge_width_px) + ")",
            "blurred"};
  const ViewPose pose = view_pose(det.corners, det.ids, board_, image);
  for (size_t i = 0; i < kept_.size(); ++i) {
    const ViewPose& k = kept_[i];
    const double dist = std::abs(k.x - pose.x) + std::abs(k.y - pose.y) + std::abs(k.size - pose.size) +
                        std::abs(k.skew - pose.skew);
    if (dist < opt_.min_pose_distance)
      return {false, "like view " + std::to_string(i + 1) + " (pose difference " + figure(dist, 2) + " < " +
                         figure(opt_.min_pose_distance, 2) + ")" + part, "similar"};
  }
  kept_.push_back(pose);
  return {true, "kept" + part, "kept"};
}

}  // namespace arwb
