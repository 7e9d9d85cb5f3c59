// The live view's overlays in the real window (xvfb-run): marker labels on a crowded image that neither overlap
// nor cover a marker's corner, in normal and presentation mode; labels and rejected candidates hidden per kind by
// --actions labels=...; and projected media drawn over the labels and outlines they cover.
#include "detect/dictionary.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"
#include "support/samples.hpp"
#include "support/window.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <string>
#include <vector>

namespace arwb {
namespace {

using test::RunResult;
using test::TempDir;

using test::kLiveView;
using test::kSample;
using test::stats;

// A 640x480 image of 12 ARUCO_ORIGINAL markers 62 px wide, 90 px apart, each turned a little more: labels as
// wide as "11 ARUCO_ORIGINAL" cannot all sit next to their marker.
std::string crowded_image(const TempDir& tmp) {
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar::all(170));
  const Dictionary d = make_aruco_original();
  int id = 0;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      while (!unambiguous(d, id)) ++id;
      draw_marker(img, d, id++, project_square({185.0 + 90 * c, 150.0 + 90 * r}, 62, 4 * (r * 4 + c), 10, 0, 800),
                  1.0, 4, 0, 255);
    }
  }
  const std::string path = tmp.str("crowded.png");
  cv::imwrite(path, img);
  return path;
}

using test::window_args;

bool overlay_green(const cv::Vec3b& bgr) { return bgr[1] > 200 && bgr[2] < 110 && bgr[0] < 130; }
bool magenta(const cv::Vec3b& p) { return p[0] > 200 && p[2] > 200 && p[1] < 60; }

cv::Rect box_rect(const nlohmann::json& b) {
  return {b[0].get<int>(), b[1].get<int>(), b[2].get<int>() - b[0].get<int>(), b[3].get<int>() - b[1].get<int>()};
}

// The live view's region as the --stats layout reports it (it differs between the normal and the presentation
// arrangement); kLiveView when the report has none.
cv::Rect live_view_region(const nlohmann::json& s) {
  if (s.contains("layout") && s["layout"].contains("regions")) {
    for (const auto& r : s["layout"]["regions"]) {
      for (const auto& p : r["panels"]) {
        if (p == "live_view") return {r["rect"][0].get<int>(), r["rect"][1].get<int>(), r["rect"][2].get<int>(), r["rect"][3].get<int>()};
      }
    }
  }
  ADD_FAILURE() << "no live_view region in the layout";
  return kLiveView;
}

// The labels' boxes from --stats, each checked against the screenshot: a dark box with green text in it, inside
// the live view's region `view`, overlapping no other box.
std::vector<cv::Rect> checked_label_boxes(const nlohmann::json& labels, const cv::Mat& shot, cv::Rect view) {
  std::vector<cv::Rect> boxes;
  for (const auto& b : labels["boxes"]) boxes.push_back(box_rect(b));
  for (size_t i = 0; i < boxes.size(); ++i) {
    const cv::Rect r = boxes[i];
    EXPECT_EQ(r & view, r) << "label " << i << " outside the live view";
    for (size_t j = i + 1; j < boxes.size(); ++j) {
      // The reported boxes are rounded outwards by up to a pixel: a pixel of contact is not an overlap.
      const cv::Rect both = boxes[i] & boxes[j];
      EXPECT_TRUE(both.width <= 1 || both.height <= 1) << "labels " << i << " and " << j << " overlap";
    }
    int green = 0, dark = 0;
    const cv::Rect inner(r.x + 1, r.y + 1, r.width - 2, r.height - 2);
    for (int y = inner.y; y < inner.br().y; ++y) {
      for (int x = inner.x; x < inner.br().x; ++x) {
        const cv::Vec3b p = shot.at<cv::Vec3b>(y, x);
        green += overlay_green(p);
        dark += p[0] < 70 && p[1] < 70 && p[2] < 70;
      }
    }
    EXPECT_GT(green, 10) << "no text in label " << i;
    EXPECT_GT(dark, inner.area() / 2) << "label " << i << " is not on its dark box";
  }
  return boxes;
}

TEST(Overlays, CrowdedLabelsNeitherOverlapNorCoverMarkersInBothModes) {
  TempDir tmp;
  const std::string image = crowded_image(tmp);
  std::vector<int> heights[2];
  double scale[2] = {0, 0};
  for (int mode = 0; mode < 2; ++mode) {
    SCOPED_TRACE(mode ? "presentation" : "normal");
    const std::string shot_path = tmp.str(mode ? "presentation.png" : "normal.png");
    const RunResult r = test::run_arwb_window(
        window_args(tmp, "--source '" + image + "' --frames 40 --stats --screenshot '" + shot_path + "'" +
                             (mode ? " --presentation" : "")));
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json s = stats(r);
    ASSERT_EQ(s.value("markers", 0), 12) << r.out;
    ASSERT_TRUE(s.contains("labels")) << r.out;
    const nlohmann::json& labels = s["labels"];
    const int drawn = labels["drawn"], hidden = labels["hidden"];
    EXPECT_EQ(drawn + hidden, 12) << labels;
    EXPECT_GE(drawn, mode ? 6 : 10) << labels;
    EXPECT_EQ(labels["overlaps"], 0) << labels;
    EXPECT_EQ(labels["on_corners"], 0) << labels;
    const cv::Mat shot = cv::imread(shot_path);
    ASSERT_FALSE(shot.empty());
    for (const cv::Rect& b : checked_label_boxes(labels, shot, live_view_region(s))) heights[mode].push_back(b.height);
    scale[mode] = s["layout"].value("scale", 0.0);
    ASSERT_EQ(static_cast<int>(heights[mode].size()), drawn);
  }
  // Presentation mode scales the labels' text with the rest (25 px text for 15 at 900 lines: x1.67).
  ASSERT_FALSE(heights[0].empty());
  ASSERT_FALSE(heights[1].empty());
  ASSERT_GT(scale[1], 1.5);
  const double ratio = static_cast<double>(heights[1][0]) / heights[0][0];
  EXPECT_GT(ratio, scale[1] * 0.85);
  EXPECT_LT(ratio, scale[1] * 1.15);
}

TEST(Overlays, LabelsAndRejectedCandidatesAreHiddenPerKind) {
  TempDir tmp;
  const std::string image = crowded_image(tmp);
  auto run = [&](const std::string& labels, const std::string& shot) {
    const RunResult r = test::run_arwb_window(
        window_args(tmp, "--source '" + image + "' --frames 30 --stats --screenshot '" + tmp.str(shot) +
                             "' --actions '0:labels=" + labels + "'"));
    EXPECT_EQ(r.status, 0) << r.err;
    return stats(r);
  };
  auto widest = [](const nlohmann::json& labels) {
    int w = 0;
    for (const auto& b : labels["boxes"]) w = std::max(w, box_rect(b).width);
    return w;
  };
  // Ids alone: short labels, all of them next to their marker.
  const nlohmann::json ids = run("ids,rejected", "ids.png");
  EXPECT_EQ(ids["labels"]["drawn"], 12) << ids;
  EXPECT_LT(widest(ids["labels"]), 30) << ids;
  // The dictionaries' names alone: wide.
  const nlohmann::json dict = run("dict", "dict.png");
  EXPECT_GT(widest(dict["labels"]), 80) << dict;
  // None: no label, and neither the rejected candidates' outlines (quad_fit's in its colour) nor label text.
  const nlohmann::json none = run("none", "none.png");
  EXPECT_EQ(none["labels"]["drawn"], 0) << none;
  EXPECT_EQ(none["labels"]["hidden"], 0) << none;
  const cv::Mat with = cv::imread(tmp.str("ids.png")), without = cv::imread(tmp.str("none.png"));
  ASSERT_FALSE(with.empty());
  ASSERT_FALSE(without.empty());
  // The rejected candidates here are two quad_fit outlines (cyan-green, stage_colour), around the whole grid.
  auto cyan = [](const cv::Mat& shot) {
    int n = 0;
    for (int y = kLiveView.y; y < kLiveView.br().y; ++y) {
      for (int x = kLiveView.x; x < kLiveView.br().x; ++x) {
        const cv::Vec3b p = shot.at<cv::Vec3b>(y, x);
        n += p[0] > 150 && p[1] > 150 && p[2] < 120 && std::abs(p[0] - p[1]) < 60;
      }
    }
    return n;
  };
  EXPECT_GT(cyan(with), 100);
  EXPECT_LT(cyan(without), 10);
  // An unknown kind is refused by name and changes nothing.
  const RunResult bad = test::run_arwb_window(
      window_args(tmp, "--source '" + image + "' --frames 20 --stats --actions '0:labels=ids,colour'"));
  EXPECT_EQ(bad.status, 0) << bad.err;
  EXPECT_NE((bad.out + bad.err).find("no kind 'colour'"), std::string::npos) << bad.out << bad.err;
  EXPECT_EQ(stats(bad)["labels"]["drawn"], 12);
}

TEST(Overlays, ProjectedMediaCoverTheLabelsAndOutlines) {
  TempDir tmp;
  // Both markers of the sample covered by an opaque magenta picture, stretched over the marker.
  cv::imwrite(tmp.str("magenta.png"), cv::Mat(64, 64, CV_8UC3, cv::Scalar(255, 0, 255)));
  test::write_file(tmp.str("scene.lua"),
                   "marker({from = 843, to = 950}, { media = image \"magenta.png\", place = on_marker { fit = \"stretch\" } })\n");
  const RunResult r = test::run_arwb_window(
      window_args(tmp, "--source '" + kSample + "' --scene '" + tmp.str("scene.lua") +
                           "' --frames 40 --stats --screenshot '" + tmp.str("shot.png") + "'"));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json s = stats(r);
  EXPECT_EQ(s.value("overlays", 0), 2) << r.out;
  ASSERT_TRUE(s.contains("labels")) << r.out;
  EXPECT_EQ(s["labels"]["drawn"], 2) << r.out;
  const cv::Mat shot = cv::imread(tmp.str("shot.png"));
  ASSERT_FALSE(shot.empty());
  // Each media on screen: the convex hull of a group of magenta pixels (a label drawn across a picture would cut
  // it in two: pieces within 12 px are one group). Inside it (less two pixels of anti-aliased edge) every pixel
  // is the picture's: no label box, no text, no outline on it.
  cv::Mat mask(shot.size(), CV_8U, cv::Scalar(0));
  for (int y = kLiveView.y; y < kLiveView.br().y; ++y)
    for (int x = kLiveView.x; x < kLiveView.br().x; ++x)
      mask.at<uint8_t>(y, x) = magenta(shot.at<cv::Vec3b>(y, x)) ? 255 : 0;
  cv::Mat near_mask, groups;
  cv::dilate(mask, near_mask, cv::getStructuringElement(cv::MORPH_RECT, {25, 25}));
  const int n_groups = cv::connectedComponents(near_mask, groups);
  cv::Mat media(shot.size(), CV_8U, cv::Scalar(0));
  int big = 0;
  for (int g = 1; g < n_groups; ++g) {
    std::vector<cv::Point> points;
    for (int y = 0; y < mask.rows; ++y)
      for (int x = 0; x < mask.cols; ++x)
        if (mask.at<uint8_t>(y, x) && groups.at<int>(y, x) == g) points.push_back({x, y});
    if (points.size() < 200) continue;
    ++big;
    std::vector<cv::Point> hull;
    cv::convexHull(points, hull);
    cv::fillConvexPoly(media, hull, 255);
  }
  cv::erode(media, media, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
  int inside = 0, foreign = 0;
  for (int y = 0; y < shot.rows; ++y) {
    for (int x = 0; x < shot.cols; ++x) {
      if (!media.at<uint8_t>(y, x)) continue;
      ++inside;
      foreign += !magenta(shot.at<cv::Vec3b>(y, x));
    }
  }
  EXPECT_GT(inside, 1500);
  EXPECT_EQ(foreign, 0) << "pixels drawn over the media";
  // And the labels were placed beside the pictures, not under them.
  for (const auto& b : s["labels"]["boxes"]) {
    const cv::Rect box = box_rect(b) & cv::Rect(0, 0, shot.cols, shot.rows);
    EXPECT_EQ(cv::countNonZero(media(box)), 0) << "a label under a media: " << b;
  }
}

}  // namespace
}  // namespace arwb
