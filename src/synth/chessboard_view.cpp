#include "synth/chessboard_view.hpp"

#include "detect/dictionary.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

namespace arwb {

SynthCamera SynthCamera::resized(cv::Size to) const {
  SynthCamera c = *this;
  const double s = double(to.width) / size.width;
  const cv::Matx33d& K = camera_matrix;
  c.size = to;
  c.camera_matrix = cv::Matx33d(K(0, 0) * s, 0, to.width / 2.0 + (K(0, 2) - size.width / 2.0) * s,  //
                                0, K(1, 1) * s, to.height / 2.0 + (K(1, 2) - size.height / 2.0) * s,  //
                                0, 0, 1);
  return c;
}

SynthChessboard SynthChessboard::of(const BoardSpec& spec, double margin_squares) {
  SynthChessboard b;
  const cv::Size inner = spec.inner_corners();
  b.cols = inner.width;
  b.rows = inner.height;
  b.square_m = spec.square_mm / 1000;
  b.margin_squares = margin_squares;
  b.kind = spec.kind;
  b.marker_m = spec.marker_mm / 1000;
  b.dictionary = spec.dictionary;
  return b;
}

cv::Mat sample_rays(const SynthCamera& camera) {
  // Undistorted at every pixel centre (and a ring of one pixel around the image), then interpolated to the 4x4
  // samples: the lens model is smooth at the scale of a pixel, and this is 16 times fewer points to undistort.
  const int w = camera.size.width, h = camera.size.height;
  std::vector<cv::Point2f> pts;
  pts.reserve(size_t(w + 2) * size_t(h + 2));
  for (int y = -1; y <= h; ++y)
    for (int x = -1; x <= w; ++x) pts.emplace_back(float(x), float(y));
  std::vector<cv::Point2f> out;
  // Iterated to convergence rather than OpenCV's default 5 steps, which leave strong barrel distortion
  // under-corrected at the corners of the image.
  cv::undistortPoints(pts, out, cv::Mat(camera.camera_matrix), camera.distortion, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-10));
  const cv::Mat grid = cv::Mat(out, true).reshape(2, h + 2);
  // Sample (i, j) of pixel (x, y) sits at x + (i + 0.5)/4 - 0.5: pixel centres at integers, as OpenCV's
  // projectPoints and corner detectors place them.
  cv::Mat rays;
  rays.create(h * kRaySamples, w * kRaySamples, CV_32FC2);
  for (int sy = 0; sy < rays.rows; ++sy) {
    const double gy = (sy + 0.5) / kRaySamples - 0.5 + 1;
    const int iy = int(std::floor(gy));
    const float fy = float(gy - iy);
    auto* row = rays.ptr<cv::Vec2f>(sy);
    for (int sx = 0; sx < rays.cols; ++sx) {
      const double gx = (sx + 0.5) / kRaySamples - 0.5 + 1;
      const int ix = int(std::floor(gx));
      const float fx = float(gx - ix);
      const cv::Vec2f a = grid.at<cv::Vec2f>(iy, ix), b = grid.at<cv::Vec2f>(iy, ix + 1);
      const cv::Vec2f c = grid.at<cv::Vec2f>(iy + 1, ix), d = grid.at<cv::Vec2f>(iy + 1, ix + 1);
      row[sx] = (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy;
    }
  }
  return rays;
}

ChessboardRenderer::ChessboardRenderer(SynthCamera camera, SynthChessboard board)
    : camera_(std::move(camera)), board_(board), rays_(sample_rays(camera_)) {
  if (board_.kind != BoardKind::charuco) return;
  // OpenCV 4.6's layout: squares row by row, the top-left one black, a marker in each white square, ids in order.
  const std::optional<Dictionary> dict = dictionary_by_name(board_.dictionary);
  const int sx = board_.cols + 1, sy = board_.rows + 1;
  marker_cells_.assign(size_t(sx) * size_t(sy), cv::Mat());
  int id = 0;
  for (int j = 0; j < sy; ++j)
    for (int i = 0; i < sx; ++i) {
      if ((i + j) % 2 == 0) continue;
      const int this_id = id++;
      if (!dict || this_id >= dict->size()) continue;   // past the dictionary's end: a white square
      const int n = dict->marker_size();
      cv::Mat cells = cv::Mat::zeros(n + 2, n + 2, CV_8U);
      dict->bits(this_id).copyTo(cells(cv::Rect(1, 1, n, n)));
      marker_cells_[size_t(j * sx + i)] = cells;
    }
}

ChessboardView ChessboardRenderer::render(const cv::Vec3d& rvec, const cv::Vec3d& tvec, double blur_px,
                                          double noise, unsigned seed, int samples) const {
  cv::Mat1f acc(camera_.size, 0.f);
  render_rows(rvec, tvec, acc, 0, camera_.size.height, samples);
  return finish(acc, rvec, tvec, blur_px, noise, seed);
}

void ChessboardRenderer::render_rows(const cv::Vec3d& rvec, const cv::Vec3d& tvec, cv::Mat1f& acc, int row0,
                                     int row1, int samples) const {
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  // The plane z = 0 of the board maps to normalised image coordinates by H = [r1 r2 t]; its inverse takes a
  // sample's ray back to board coordinates.
  const cv::Matx33d H(R(0, 0), R(0, 1), tvec[0], R(1, 0), R(1, 1), tvec[1], R(2, 0), R(2, 1), tvec[2]);
  const cv::Matx33d Hi = H.inv();
  const double sq = board_.square_m;
  const double x0 = -sq * (1 + board_.margin_squares), x1 = sq * (board_.cols + board_.margin_squares);
  const double y0 = -sq * (1 + board_.margin_squares), y1 = sq * (board_.rows + board_.margin_squares);
  row0 = std::clamp(row0, 0, camera_.size.height);
  row1 = std::clamp(row1, row0, camera_.size.height);
  if (acc.size() != camera_.size) acc = cv::Mat1f(camera_.size, 0.f);
  if (row0 == row1) return;
  acc.rowRange(row0, row1).setTo(0);
  const bool charuco = board_.kind == BoardKind::charuco;
  const int squares_x = board_.cols + 1;
  const double marker = board_.marker_m, inset = (sq - marker) / 2;
  // Which of the four samples a side are taken: all; the outer two (offsets -3/8 and +3/8 px, whose mean is the
  // pixel's centre); or one (+1/8 px: a moving board, which nobody measures).
  const std::vector<int> taken = samples >= 4 ? std::vector<int>{0, 1, 2, 3}
                                 : samples == 2 ? std::vector<int>{0, 3}
                                                : std::vector<int>{2};
  const int n_taken = int(taken.size());
  for (int sy = row0 * kRaySamples; sy < row1 * kRaySamples; ++sy) {
    if (std::find(taken.begin(), taken.end(), sy % kRaySamples) == taken.end()) continue;
    const auto* ray = rays_.ptr<cv::Vec2f>(sy);
    float* row = acc.ptr<float>(sy / kRaySamples);
    for (int sx0 = 0; sx0 < rays_.cols; sx0 += kRaySamples)
    for (int k = 0; k < n_taken; ++k) {
      const int sx = sx0 + taken[size_t(k)];
      const double px = ray[sx][0], py = ray[sx][1];
      const double bw = Hi(2, 0) * px + Hi(2, 1) * py + Hi(2, 2);
      float value;
      const double bx = (Hi(0, 0) * px + Hi(0, 1) * py + Hi(0, 2)) / bw;
      const double by = (Hi(1, 0) * px + Hi(1, 1) * py + Hi(1, 2)) / bw;
      // bw <= 0: the ray meets the plane behind the camera.
      if (bw <= 0 || bx < x0 || bx >= x1 || by < y0 || by >= y1) {
        value = float(90 + 60.0 * sx / rays_.cols);   // background
      } else if (bx < -sq || bx >= sq * board_.cols || by < -sq || by >= sq * board_.rows) {
        value = 220;   // paper margin
      } else {
        const long i = long(std::floor(bx / sq)), j = long(std::floor(by / sq));
        value = ((i + j) & 1) ? 220.f : 30.f;
        if (charuco && ((i + j) & 1)) {
          // The square's marker, if any: (i + 1, j + 1) in OpenCV's squares, which start at the outer corner.
          const cv::Mat& cells = marker_cells_[size_t((j + 1) * squares_x + (i + 1))];
          const double across = bx - double(i) * sq - inset, down = by - double(j) * sq - inset;
          if (!cells.empty() && across >= 0 && down >= 0 && across < marker && down < marker) {
            const int n = cells.rows;
            const int cu = std::min(n - 1, int(across / marker * n)), cr = std::min(n - 1, int(down / marker * n));
            value = cells.at<uchar>(cr, cu) ? 220.f : 30.f;
          }
        }
      }
      row[sx / kRaySamples] += value;
    }
  }
  acc.rowRange(row0, row1) *= 1.0 / (n_taken * n_taken);
}

ChessboardView ChessboardRenderer::finish(cv::Mat1f acc, const cv::Vec3d& rvec, const cv::Vec3d& tvec,
                                          double blur_px, double noise, unsigned seed) const {
  ChessboardView v;
  const int w = camera_.size.width, h = camera_.size.height;
  const double sq = board_.square_m;
  if (blur_px > 0) cv::GaussianBlur(acc, acc, cv::Size(), blur_px);
  if (noise > 0) {
    cv::Mat1f n(acc.size());
    cv::theRNG().state = seed;
    cv::randn(n, 0, noise);
    acc += n;
  }
  acc.convertTo(v.image, CV_8U);

  std::vector<cv::Point3f> obj;
  for (int r = 0; r < board_.rows; ++r)
    for (int c = 0; c < board_.cols; ++c) obj.emplace_back(float(c * sq), float(r * sq), 0.f);
  cv::projectPoints(obj, rvec, tvec, cv::Mat(camera_.camera_matrix), camera_.distortion, v.corners);
  v.all_inside = true;
  for (const cv::Point2f& p : v.corners)
    if (p.x < 2 || p.y < 2 || p.x > float(w - 3) || p.y > float(h - 3)) v.all_inside = false;
  return v;
}

std::vector<std::pair<cv::Vec3d, cv::Vec3d>> chessboard_poses(const SynthCamera& camera, const SynthChessboard& board,
                                                              int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const double bw = board.square_m * (board.cols + 1 + 2 * board.margin_squares);
  const double bh = board.square_m * (board.rows + 1 + 2 * board.margin_squares);
  const double f = camera.camera_matrix(0, 0);
  std::vector<std::pair<cv::Vec3d, cv::Vec3d>> poses;
  for (int tries = 0; int(poses.size()) < count && tries < count * 200; ++tries) {
    // Tilt about x and y, a little roll; the board's centre aimed at a point spread over the frame.
    // One draw per statement: the order of a call's arguments is unspecified, and GCC and Clang differ, so the
    // drawn poses (and every test built on them) would differ between the two compilers' builds.
    const double roll = u(rng), tilt_y = u(rng), tilt_x = u(rng);
    const cv::Vec3d rvec(tilt_x * 0.7, tilt_y * 0.7, roll * 0.3);
    const double fill = 0.45 + 0.35 * (u(rng) + 1) / 2;   // the board's width over the image's
    const double z = f * bw / (fill * camera.size.width);
    const double cx = u(rng) * 0.35 * camera.size.width / f * z, cy = u(rng) * 0.35 * camera.size.height / f * z;
    cv::Matx33d R;
    cv::Rodrigues(rvec, R);
    // t places the board's centre (not its first inner corner) at (cx, cy, z).
    const cv::Vec3d centre(bw / 2 - board.square_m * (1 + board.margin_squares),
                           bh / 2 - board.square_m * (1 + board.margin_squares), 0);
    const cv::Vec3d t = cv::Vec3d(cx, cy, z) - R * centre;
    std::vector<cv::Point3f> outline{{float(-board.square_m), float(-board.square_m), 0},
                                     {float(board.square_m * board.cols), float(-board.square_m), 0},
                                     {float(board.square_m * board.cols), float(board.square_m * board.rows), 0},
                                     {float(-board.square_m), float(board.square_m * board.rows), 0}};
    std::vector<cv::Point2f> img;
    cv::projectPoints(outline, rvec, t, cv::Mat(camera.camera_matrix), camera.distortion, img);
    bool inside = true;
    // Squares and a little white at least 12 px inside the image: a detector needs the board's border.
    for (const cv::Point2f& p : img)
      if (p.x < 12 || p.y < 12 || p.x > float(camera.size.width - 13) || p.y > float(camera.size.height - 13)) inside = false;
    if (inside) poses.emplace_back(rvec, t);
  }
  return poses;
}

std::vector<std::pair<cv::Vec3d, cv::Vec3d>> partial_board_poses(const SynthCamera& camera,
                                                                 const SynthChessboard& board, int count,
                                                                 unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const double bw = board.square_m * (board.cols + 1), bh = board.square_m * (board.rows + 1);
  const double f = camera.camera_matrix(0, 0);
  std::vector<cv::Point3f> inner;
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.cols; ++c)
      inner.emplace_back(float(c * board.square_m), float(r * board.square_m), 0.f);
  std::vector<std::pair<cv::Vec3d, cv::Vec3d>> poses;
  for (int tries = 0; int(poses.size()) < count && tries < count * 400; ++tries) {
    const double roll = u(rng), tilt_y = u(rng), tilt_x = u(rng);   // in this order: see chessboard_poses
    const cv::Vec3d rvec(tilt_x * 0.6, tilt_y * 0.6, roll * 0.3);
    const double fill = 0.8 + 0.5 * (u(rng) + 1) / 2;   // the board wider than most of the image
    const double z = f * bw / (fill * camera.size.width);
    const double cx = u(rng) * 0.45 * camera.size.width / f * z, cy = u(rng) * 0.45 * camera.size.height / f * z;
    cv::Matx33d R;
    cv::Rodrigues(rvec, R);
    const cv::Vec3d centre(bw / 2 - board.square_m, bh / 2 - board.square_m, 0);
    const cv::Vec3d t = cv::Vec3d(cx, cy, z) - R * centre;
    std::vector<cv::Point2f> img;
    cv::projectPoints(inner, rvec, t, cv::Mat(camera.camera_matrix), camera.distortion, img);
    // A board held close, not one that fills the room: its corners stay within a third of the image of it.
    const int n = int(std::count_if(img.begin(), img.end(), [&](const cv::Point2f& p) {
      return p.x >= 12 && p.y >= 12 && p.x <= float(camera.size.width - 13) && p.y <= float(camera.size.height - 13);
    }));
    const bool near = std::all_of(img.begin(), img.end(), [&](const cv::Point2f& p) {
      return p.x > -0.3f * float(camera.size.width) && p.x < 1.3f * float(camera.size.width) &&
             p.y > -0.3f * float(camera.size.height) && p.y < 1.3f * float(camera.size.height);
    });
    if (near && 3 * n >= int(img.size()) && 5 * n <= 4 * int(img.size())) poses.emplace_back(rvec, t);
  }
  return poses;
}

}  // namespace arwb
