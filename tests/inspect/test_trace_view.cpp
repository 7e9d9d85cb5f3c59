// The per-stage pictures of a full trace (trace_view.hpp): which stages get one, their sizes, what they show,
// the empty cases, and how long they take at the workbench's frame size.
#include "detect/detector.hpp"
#include "detect/dictionary.hpp"
#include "synth/synth.hpp"
#include "inspect/trace_view.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

using namespace arwb;

namespace {

using Views = std::array<cv::Mat, kStageCount>;

// A light page with `cols` x `rows` markers of side `side` on a regular grid, slightly turned and tilted.
cv::Mat page_with_markers(const Dictionary& d, int cols, int rows, double side, std::vector<int>* ids,
                          cv::Size size = {640, 480}) {
  cv::Mat img(size, CV_8UC3, cv::Scalar(235, 235, 235));
  const double cw = double(size.width) / cols, ch = double(size.height) / rows;
  int id = 3;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      while (!unambiguous(d, id)) ++id;
      const cv::Point2d centre((c + 0.5) * cw, (r + 0.5) * ch);
      const double roll = 7.0 * (r * cols + c) - 20.0;
      draw_marker(img, d, id, project_square(centre, side, roll, 10.0 * (c % 3 - 1), 8.0 * (r % 2), 900.0));
      if (ids) ids->push_back(id);
      id += 5;
    }
  return img;
}

// A busy frame: markers, and between them blobs and specks (many contours), dark diamonds (quads that fail at
// otsu) and patterned squares (quads that reach the bit grid).
cv::Mat busy_page(const Dictionary& d) {
  cv::Mat img = page_with_markers(d, 5, 4, 52, nullptr);
  cv::RNG rng(7);
  auto near_marker = [](cv::Point p) {  // the markers are centred in 128 x 120 cells
    return std::abs((p.x % 128) - 64) < 44 && std::abs((p.y % 120) - 60) < 44;
  };
  for (int i = 0; i < 900; ++i) {
    // One draw per statement: the order of a call's arguments differs between compilers.
    const int y = rng.uniform(0, 480), x = rng.uniform(0, 640);
    const cv::Point p(x, y);
    if (near_marker(p)) continue;
    if (i % 2) {
      const int grey = rng.uniform(20, 90), angle = rng.uniform(0, 180);
      const int a = rng.uniform(5, 10), b = rng.uniform(4, 8);
      cv::ellipse(img, p, {a, b}, angle, 0, 360, cv::Scalar::all(grey), cv::FILLED);
    } else
      cv::circle(img, p, rng.uniform(1, 3), cv::Scalar::all(40), cv::FILLED);
  }
  for (int r = 0; r <= 4; ++r)
    for (int c = 0; c <= 5; ++c) {
      const cv::Point2f p(float(std::clamp(c * 128, 14, 626)), float(std::clamp(r * 120, 14, 466)));
      const float s = float(rng.uniform(16, 24));
      cv::circle(img, p, 20, cv::Scalar::all(235), cv::FILLED);  // a quiet zone
      cv::Point2f v[4];
      cv::RotatedRect(p, {s, s}, float(rng.uniform(0, 90))).points(v);
      std::vector<cv::Point> pts;
      for (const auto& q : v) pts.emplace_back(cvRound(q.x), cvRound(q.y));
      cv::fillConvexPoly(img, pts, cv::Scalar::all(rng.uniform(10, 60)));
    }
  for (int r = 0; r <= 4; ++r)
    for (int c = 0; c < 5; ++c) {
      const cv::Point p(64 + 128 * c, std::clamp(120 * r, 14, 466));
      cv::rectangle(img, cv::Rect(p.x - 17, p.y - 17, 34, 34), cv::Scalar::all(235), cv::FILLED);
      cv::rectangle(img, cv::Rect(p.x - 11, p.y - 11, 22, 22), cv::Scalar::all(15), cv::FILLED);
      const int h = rng.uniform(3, 8), w = rng.uniform(3, 8);
      cv::rectangle(img, cv::Rect(p.x - 5, p.y - 5, w, h), cv::Scalar::all(230), cv::FILLED);
    }
  return img;
}

void dump(const Views& views, const std::string& prefix) {
  const char* dir = std::getenv("ARWB_TRACE_VIEW_DUMP");  // set to a folder to look at the pictures
  if (!dir) return;
  for (int s = 0; s < kStageCount; ++s)
    if (!views[size_t(s)].empty())
      cv::imwrite(std::string(dir) + "/" + prefix + "_" + std::string(stage_name(Stage(s))) + ".png",
                  views[size_t(s)]);
}

bool is_green(const cv::Vec3b& p) { return p[1] > 170 && p[0] < 120 && p[2] < 120; }

// Green pixels within `r` of p.
int green_near(const cv::Mat& img, cv::Point p, int r) {
  int n = 0;
  for (int y = std::max(0, p.y - r); y <= std::min(img.rows - 1, p.y + r); ++y)
    for (int x = std::max(0, p.x - r); x <= std::min(img.cols - 1, p.x + r); ++x)
      n += is_green(img.at<cv::Vec3b>(y, x));
  return n;
}

// Tiles of a mosaic: blobs of non-background pixels at least a tile's size (labels touching a tile merge into it).
int count_tiles(const cv::Mat& mosaic) {
  const cv::Vec3b bg = mosaic.at<cv::Vec3b>(0, 0);
  cv::Mat diff;
  cv::absdiff(mosaic, cv::Scalar(bg[0], bg[1], bg[2]), diff);
  cv::Mat grey, mask;
  cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, mask, 0, 255, cv::THRESH_BINARY);
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
  int tiles = 0;
  for (int i = 1; i < n; ++i)
    if (stats.at<int>(i, cv::CC_STAT_WIDTH) >= 60 && stats.at<int>(i, cv::CC_STAT_HEIGHT) >= 60) ++tiles;
  return tiles;
}

// Six markers on a page, detected with the full trace.
struct SixMarkers {
  std::vector<int> ids;
  cv::Mat img = page_with_markers(make_aruco_original(), 3, 2, 90, &ids);
  FrameTrace t;
  std::vector<Marker> markers = Detector({make_aruco_original()}).detect(img, &t, TraceLevel::full);
};

int with_warp(const FrameTrace& t) {
  return int(std::count_if(t.candidates.begin(), t.candidates.end(), [](const auto& c) { return !c.warp.empty(); }));
}

cv::Point work_point(const cv::Point2f& p, const FrameTrace& t) {
  return {cvRound((p.x + 0.5) / t.scale_x - 0.5), cvRound((p.y + 0.5) / t.scale_y - 0.5)};
}

}  // namespace

// A thumbnail fits 192x144 by whole blocks: each pixel the mean of its k x k block of the picture.
TEST(Thumbnail, EachPixelIsTheMeanOfItsBlock) {
  cv::Mat in(480, 642, CV_8UC3);
  cv::randu(in, 0, 256);
  cv::Mat out;
  thumbnail(in, out);
  ASSERT_EQ(out.size(), cv::Size(160, 120)) << "k = 4: 642 / 4 leaves two columns out";
  for (const cv::Point p : {cv::Point(0, 0), cv::Point(159, 119), cv::Point(77, 31)}) {
    const cv::Scalar mean = cv::mean(in(cv::Rect(p.x * 4, p.y * 4, 4, 4)));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out.at<cv::Vec3b>(p)[c], mean[c], 0.5) << p;
  }
  thumbnail(cv::Mat(720, 1280, CV_8UC1, cv::Scalar(9)), out);
  EXPECT_EQ(out.size(), cv::Size(182, 102));
  EXPECT_EQ(out.at<uchar>(101, 181), 9);
  thumbnail(cv::Mat(100, 150, CV_8UC1, cv::Scalar(3)), out);
  EXPECT_EQ(out.size(), cv::Size(150, 100)) << "a small picture is kept as it is";
  thumbnail(cv::Mat(2000, 3, CV_8UC1, cv::Scalar(5)), out);
  EXPECT_EQ(out.size(), cv::Size(1, 142)) << "thinner than a block";
  thumbnail(cv::Mat(), out);
  EXPECT_TRUE(out.empty());
}

TEST(TraceView, MosaicStagesAreThePerCandidateOnes) {
  for (int s = 0; s < kStageCount; ++s) {
    const Stage st = Stage(s);
    const bool expect = st == Stage::perspective_removal || st == Stage::otsu || st == Stage::bit_grid ||
                        st == Stage::border_check || st == Stage::identification;
    EXPECT_EQ(stage_view_is_mosaic(st), expect) << stage_name(st);
  }
}

TEST(TraceView, EveryTracedStageHasAViewAtTheRightSize) {
  const Dictionary d = make_aruco_original();
  std::vector<int> ids;
  const cv::Mat img = page_with_markers(d, 3, 2, 90, &ids);
  const Detector det({d});
  FrameTrace t;
  const auto markers = det.detect(img, &t, TraceLevel::full);
  ASSERT_EQ(markers.size(), ids.size());
  ASSERT_EQ(int(t.stages.size()), kStageCount);
  Views views;
  render_stage_views(img, t, views);
  dump(views, "page");
  for (const StageRecord& r : t.stages) {
    const cv::Mat& v = views[size_t(r.stage)];
    SCOPED_TRACE(std::string(stage_name(r.stage)));
    ASSERT_FALSE(v.empty());
    EXPECT_EQ(v.type(), CV_8UC3);
    if (!stage_view_is_mosaic(r.stage)) {
      EXPECT_EQ(v.size(), cv::Size(t.work_width, t.work_height));
      EXPECT_EQ(v.size(), img.size());
    }
    double lo = 0, hi = 0;
    cv::minMaxLoc(v.reshape(1), &lo, &hi);
    EXPECT_LT(lo, hi) << "a uniform picture";
  }
  // acquisition is the grey frame; adaptive_threshold the binary one, foreground white.
  cv::Mat grey;
  cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
  cv::Mat acq_grey;
  cv::cvtColor(views[size_t(Stage::acquisition)], acq_grey, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(acq_grey, grey, cv::NORM_INF), 0);
  cv::Mat bin;
  cv::cvtColor(views[size_t(Stage::adaptive_threshold)], bin, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(bin, t.stage(Stage::adaptive_threshold)->image, cv::NORM_INF), 0);
  // contours: light strokes on black where the contours run.
  const cv::Mat& cv_contours = views[size_t(Stage::contours)];
  EXPECT_EQ(cv_contours.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  for (const auto& c : t.contours) {
    const cv::Vec3b p = cv_contours.at<cv::Vec3b>(c[0]);
    EXPECT_GT(p[0], 200);
  }
}

TEST(TraceView, DuplicatesViewOutlinesEachMarkerInGreen) {
  const SixMarkers page;
  ASSERT_EQ(page.markers.size(), page.ids.size());
  const cv::Mat& img = page.img;
  const FrameTrace& t = page.t;
  const auto& markers = page.markers;
  Views views;
  render_stage_views(img, t, views);
  const cv::Mat& dup = views[size_t(Stage::duplicates)];
  const cv::Mat& refine = views[size_t(Stage::corner_refinement)];
  for (const Marker& m : markers)
    for (const auto& c : m.corners) {
      EXPECT_GT(green_near(dup, work_point(c, t), 4), 0) << "marker " << m.id;
      EXPECT_GT(green_near(refine, work_point(c, t), 4), 0) << "marker " << m.id;
    }
  // Away from the markers the frame is only dimmed: no green.
  EXPECT_EQ(green_near(dup, {4, 4}, 4), 0);
  // The identification mosaic frames the identified grids green.
  const cv::Mat& ident = views[size_t(Stage::identification)];
  int green = 0;
  for (int y = 0; y < ident.rows; ++y)
    for (int x = 0; x < ident.cols; ++x) green += is_green(ident.at<cv::Vec3b>(y, x));
  EXPECT_GE(green, int(markers.size()) * 4 * 60);  // a 2 px frame of a 64 px tile per marker, at least
}

TEST(TraceView, DetectionAtAReducedSizeDrawsAtTheWorkingSize) {
  const Dictionary d = make_aruco_original();
  std::vector<int> ids;
  const cv::Mat img = page_with_markers(d, 2, 2, 140, &ids);
  Detector det({d});
  AcquisitionSettings a;
  a.size = {320, 0};
  det.set_acquisition(a);
  FrameTrace t;
  const auto markers = det.detect(img, &t, TraceLevel::full);
  ASSERT_EQ(markers.size(), ids.size());
  ASSERT_EQ(t.work_width, 320);
  Views views;
  render_stage_views(img, t, views);
  for (const StageRecord& r : t.stages) {
    if (!stage_view_is_mosaic(r.stage)) {
      EXPECT_EQ(views[size_t(r.stage)].size(), cv::Size(320, 240));
    }
  }
  for (const Marker& m : markers)
    for (const auto& c : m.corners)
      EXPECT_GT(green_near(views[size_t(Stage::duplicates)], work_point(c, t), 3), 0) << "marker " << m.id;
}

TEST(TraceView, PerspectiveMosaicHasATilePerWarp) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = busy_page(d);
  FrameTrace t;
  Detector({d}).detect(img, &t, TraceLevel::full);
  const int warps = with_warp(t);
  Views views;
  render_stage_views(img, t, views);
  dump(views, "busy");
  ASSERT_GT(warps, 20);
  const cv::Mat& persp = views[size_t(Stage::perspective_removal)];
  EXPECT_EQ(count_tiles(persp), warps);
  EXPECT_EQ(count_tiles(views[size_t(Stage::otsu)]), warps);
  // Roughly 4:3.
  EXPECT_GT(persp.cols, persp.rows * 0.9);
  EXPECT_LT(persp.cols, persp.rows * 2.0);

  // Fewer warps, a smaller mosaic.
  FrameTrace fewer = t;
  int kept = 0;
  for (auto& c : fewer.candidates) {
    if (!c.warp.empty() && ++kept > warps / 3) c.warp.release();
  }
  Views small;
  render_stage_views(img, fewer, small);
  EXPECT_EQ(count_tiles(small[size_t(Stage::perspective_removal)]), warps / 3);
  EXPECT_LT(small[size_t(Stage::perspective_removal)].total(), persp.total());
}

TEST(TraceView, SummaryTraceGivesNoViews) {
  const Dictionary d = make_aruco_original();
  const cv::Mat img = page_with_markers(d, 2, 2, 90, nullptr);
  FrameTrace t;
  Detector({d}).detect(img, &t, TraceLevel::summary);
  ASSERT_FALSE(t.stages.empty());
  Views views;
  views[0] = cv::Mat(4, 4, CV_8UC3);  // stale pictures are cleared
  render_stage_views(img, t, views);
  for (const auto& v : views) EXPECT_TRUE(v.empty());
  FrameTrace none;
  render_stage_views(img, none, views);
  for (const auto& v : views) EXPECT_TRUE(v.empty());
}

TEST(TraceView, NoCandidatesGivesNoneMosaics) {
  const cv::Mat img(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
  FrameTrace t;
  const auto markers = Detector({make_aruco_original()}).detect(img, &t, TraceLevel::full);
  EXPECT_TRUE(markers.empty());
  EXPECT_TRUE(t.candidates.empty());
  Views views;
  render_stage_views(img, t, views);
  for (const StageRecord& r : t.stages) {
    const cv::Mat& v = views[size_t(r.stage)];
    SCOPED_TRACE(std::string(stage_name(r.stage)));
    ASSERT_FALSE(v.empty());
    if (stage_view_is_mosaic(r.stage)) {
      // A small dark picture saying "none".
      EXPECT_LT(v.cols, 200);
      EXPECT_LT(v.rows, 100);
      EXPECT_LT(cv::mean(v)[0], 80);
      double lo = 0, hi = 0;
      cv::minMaxLoc(v.reshape(1), &lo, &hi);
      EXPECT_GT(hi, 150);  // the text
    } else {
      EXPECT_EQ(v.size(), img.size());
    }
  }
}

TEST(TraceView, ViewsStillHeldAreNeverDrawnOver) {
  const Dictionary d = make_aruco_original();
  const cv::Mat a = page_with_markers(d, 3, 2, 90, nullptr);
  const cv::Mat b = busy_page(d);
  const Detector det({d});
  FrameTrace ta, tb;
  det.detect(a, &ta, TraceLevel::full);
  det.detect(b, &tb, TraceLevel::full);
  Views va, vb, scratch;
  render_stage_views(a, ta, va);
  Views copies;
  for (int s = 0; s < kStageCount; ++s) copies[size_t(s)] = va[size_t(s)].clone();
  for (int i = 0; i < 3; ++i) render_stage_views(b, tb, i == 0 ? vb : scratch);
  for (int s = 0; s < kStageCount; ++s) {
    SCOPED_TRACE(std::string(stage_name(Stage(s))));
    ASSERT_EQ(va[size_t(s)].size(), copies[size_t(s)].size());
    EXPECT_EQ(cv::norm(va[size_t(s)], copies[size_t(s)], cv::NORM_INF), 0);
    if (!va[size_t(s)].empty()) {
      EXPECT_NE(va[size_t(s)].data, vb[size_t(s)].data);
      EXPECT_NE(scratch[size_t(s)].data, vb[size_t(s)].data);
    }
  }
  // Rendering again into the same array reuses nothing it still holds, and gives the same pictures.
  render_stage_views(a, ta, va);
  for (int s = 0; s < kStageCount; ++s) EXPECT_EQ(cv::norm(va[size_t(s)], copies[size_t(s)], cv::NORM_INF), 0);
}


// The decimation step shows what the tour says at every resolution: at 640x480 the default factor is 1 and the
// caption says the search ran on the grey image itself; at 1280x720 it is 2, and the picture is the half-size
// copy stretched over the frame, its 2x2 blocks visible, as the caption says.
TEST(TraceView, TheDecimationPictureAndItsCaptionSayTheFactorAtEveryResolution) {
  const Dictionary d = make_aruco_original();
  const auto blocky = [](const cv::Mat& v) {   // every pixel equal to its neighbour in its 2x2 block
    for (int y = 0; y + 1 < v.rows; y += 2)
      for (int x = 0; x + 1 < v.cols; x += 2)
        if (v.at<cv::Vec3b>(y, x) != v.at<cv::Vec3b>(y, x + 1) || v.at<cv::Vec3b>(y, x) != v.at<cv::Vec3b>(y + 1, x))
          return false;
    return true;
  };
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(1280, 720)}) {
    const cv::Mat img = page_with_markers(d, 3, 2, size.height / 5.0, nullptr, size);
    Detector det({d});
    AcquisitionSettings a;
    a.resize = false;
    det.set_acquisition(a);
    FrameTrace t;
    ASSERT_EQ(det.detect(img, &t, TraceLevel::full).size(), 6u) << size;
    Views views;
    render_stage_views(img, t, views);
    const cv::Mat& v = views[size_t(Stage::decimation)];
    ASSERT_EQ(v.size(), size);
    const std::string caption = stage_view_caption(t, Stage::decimation);
    std::printf("%dx%d: %s\n", size.width, size.height, caption.c_str());
    if (size.height < 720) {
      EXPECT_EQ(caption, "decimation factor 1: the search ran on the grey image itself (640x480)");
      EXPECT_FALSE(blocky(v));
    } else {
      EXPECT_EQ(caption, "searched at 1/2 (640x360), each pixel the mean of a 2x2 block, stretched over the frame");
      EXPECT_TRUE(blocky(v));
    }
    EXPECT_EQ(stage_view_caption(t, Stage::adaptive_threshold), caption);
    EXPECT_EQ(stage_view_caption(t, Stage::quad_fit), "");
  }
}

// Pixels of `img` where `pred` holds.
template <class Pred>
int count_where(const cv::Mat& img, Pred pred) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) n += pred(img.at<cv::Vec3b>(y, x));
  return n;
}

// A projector's pictures (issue 45): outlines as wide as asked, corner marks grown with them, and the text left
// out of the pictures and given as data for the window to draw in its own type: the same labels as the pictures
// for a snapshot have drawn in, in strips twice as tall.
TEST(TraceView, AProjectorsPicturesHaveWideOutlinesAndTheirTextAsData) {
  const SixMarkers page;
  ASSERT_EQ(page.markers.size(), page.ids.size());
  const cv::Mat& img = page.img;
  const FrameTrace& t = page.t;
  const auto& markers = page.markers;
  Views plain, wide;
  StageLabels plain_labels, wide_labels;
  render_stage_views(img, t, plain, {}, &plain_labels);
  StageViewStyle projector;
  projector.line = 3;
  projector.text = false;
  render_stage_views(img, t, wide, projector, &wide_labels);
  dump(wide, "projector");

  // The same text either way: a "#N" over each tile and "id dH" under each identification tile, each marker's id.
  const auto texts = [](const std::vector<StageLabel>& ls) {
    std::vector<std::string> out;
    for (const auto& l : ls) out.push_back(l.text);
    return out;
  };
  const size_t ident = size_t(Stage::identification), dup = size_t(Stage::duplicates);
  const int tiles = count_tiles(plain[ident]);
  ASSERT_GT(tiles, 0);
  EXPECT_EQ(int(plain_labels[ident].size()), 2 * tiles);
  EXPECT_EQ(texts(wide_labels[ident]), texts(plain_labels[ident]));
  std::vector<std::string> id_texts;
  for (const Marker& m : markers) id_texts.push_back(std::to_string(m.id));
  EXPECT_EQ(texts(wide_labels[dup]), id_texts);
  for (size_t i = 0; i < wide_labels[ident].size(); ++i)
    EXPECT_EQ(wide_labels[ident][i].height, 2 * plain_labels[ident][i].height);

  // The strips: text drawn in for a snapshot, empty (the mosaic's background) for the projector.
  const auto strip_ink = [](const cv::Mat& mosaic, const StageLabel& l) {
    const cv::Vec3b bg = mosaic.at<cv::Vec3b>(0, 0);
    const int h = int(l.height);
    const cv::Rect box(cvRound(l.centre.x - 31.5f), cvRound(l.centre.y + 0.5f - l.height / 2.0f), 64, h);
    return count_where(mosaic(box & cv::Rect(0, 0, mosaic.cols, mosaic.rows)),
                       [&](const cv::Vec3b& p) { return p != bg; });
  };
  for (size_t i = 0; i < plain_labels[ident].size(); ++i) {
    EXPECT_GT(strip_ink(plain[ident], plain_labels[ident][i]), 5) << plain_labels[ident][i].text;
    EXPECT_EQ(strip_ink(wide[ident], wide_labels[ident][i]), 0) << wide_labels[ident][i].text;
  }
  // The ids: drawn over each marker's middle for a snapshot, not for the projector.
  for (const StageLabel& l : wide_labels[dup]) {
    EXPECT_GT(green_near(plain[dup], l.centre, 5), 0) << l.text;
    EXPECT_EQ(green_near(wide[dup], l.centre, 5), 0) << l.text;
  }

  // Outlines and marks at least twice the pixels at 3 px wide (all of them, text left out).
  const auto cyan = [](const cv::Vec3b& p) { return p[0] > 200 && p[1] > 200 && p[2] < 60; };
  EXPECT_GT(count_where(wide[size_t(Stage::quad_fit)], cyan), 2 * count_where(plain[size_t(Stage::quad_fit)], cyan));
  const size_t refine = size_t(Stage::corner_refinement);
  EXPECT_GT(count_where(wide[refine], is_green), 2 * count_where(plain[refine], is_green));
  EXPECT_GT(count_where(wide[dup], is_green), 2 * count_where(plain[dup], is_green));
  for (const Marker& m : markers)
    for (const auto& c : m.corners)
      EXPECT_GT(green_near(wide[refine], work_point(c, t), 9), 2 * green_near(plain[refine], work_point(c, t), 9));
}
