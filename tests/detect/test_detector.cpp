// The detector end to end on synthetic frames with exact truth: many poses, negatives, bit errors, corner
// accuracy, thread-count independence, multiple dictionaries and the trace.
#include "detect/detector.hpp"
#include "detect/pipeline.hpp"
#include "inspect/trace_view.hpp"
#include "synth/synth_set.hpp"
#include "synth/synth.hpp"
#include "detector_test_util.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

using namespace arwb;

using arwb::test::mean_corner_error;
using arwb::test::with_id;

TEST(Detector, FindsEveryMarkerAtManyPosesWithItsCornerOrder) {
  const Dictionary d = make_aruco_original();
  const Detector det({d});
  int cases = 0;
  for (double tilt_x : {-50.0, -25.0, 0.0, 25.0, 50.0})
    for (double tilt_y : {-45.0, 0.0, 45.0})
      for (double roll : {0.0, 33.0, 90.0, 200.0})
        for (double side : {40.0, 120.0}) {
          cv::Mat img(240, 320, CV_8UC3, cv::Scalar(180, 190, 200));
          const Quad q = project_square({160, 120}, side, roll, tilt_x, tilt_y, 350);
          const int id = (cases * 37) % 1000;  // ids 1000+ include 1023, which reads the same upside down
          draw_marker(img, d, id, q);
          const auto found = det.detect(img);
          ASSERT_EQ(found.size(), 1u) << "tilt " << tilt_x << "," << tilt_y << " roll " << roll << " side " << side;
          EXPECT_EQ(found[0].id, id);
          EXPECT_LT(mean_corner_error(found[0], {id, d.name(), q}), 0.3)
              << "tilt " << tilt_x << "," << tilt_y << " roll " << roll << " side " << side;
          ++cases;
        }
  EXPECT_EQ(cases, 120);
}

TEST(Detector, CornerErrorUnderAThirdOfAPixelOnCleanRenders) {
  const Dictionary d = make_aruco_original();
  const Detector det({d});
  SynthOptions opt;
  opt.dictionaries = {d};
  opt.effects = false;
  opt.empty_fraction = 0;
  double err = 0;
  int n = 0;
  for (int i = 0; i < 20; ++i) {
    const SynthImage s = synth_photo(opt, 5, i);
    const auto found = det.detect(s.image);
    EXPECT_EQ(found.size(), s.markers.size()) << "image " << i;
    for (const auto& m : found)
      for (const auto& t : s.markers)
        if (t.id == m.id) err += mean_corner_error(m, t), ++n;
  }
  ASSERT_GT(n, 30);
  EXPECT_LT(err / n, 0.3);
}

// corner_refinement's three parameters each change the corners: off keeps the polygon's corners (worse), more
// passes stay as precise as one, and the corners move between one pass and several.
TEST(Detector, CornerRefinementParametersTakeEffect) {
  const Dictionary d = make_aruco_original();
  SynthOptions opt;
  opt.dictionaries = {d};
  opt.effects = false;
  opt.empty_fraction = 0;
  DetectorParams off, one, many;
  off.corner_refinement = 0;
  many.subpix_max_iterations = 10;
  double err_off = 0, err_one = 0, err_many = 0, moved = 0;
  int n = 0;
  for (int i = 0; i < 12; ++i) {
    const SynthImage s = synth_photo(opt, 9, i);
    const auto a = Detector({d}, off).detect(s.image), b = Detector({d}, one).detect(s.image),
               c = Detector({d}, many).detect(s.image);
    ASSERT_EQ(a.size(), b.size());
    ASSERT_EQ(b.size(), c.size());
    for (size_t k = 0; k < b.size(); ++k)
      for (const auto& t : s.markers)
        if (t.id == b[k].id) {
          err_off += mean_corner_error(a[k], t);
          err_one += mean_corner_error(b[k], t);
          err_many += mean_corner_error(c[k], t);
          moved += mean_corner_error(c[k], {t.id, t.dict, b[k].corners});
          ++n;
        }
  }
  ASSERT_GT(n, 20);
  EXPECT_GT(err_off / n, 1.5 * err_one / n) << "refinement off should keep the rougher polygon corners";
  // One pass already places clean corners within 0.05 px; more passes re-profile square to the sides found and
  // move them by hundredths of a pixel either way (0.042 px after one pass, 0.047 px after ten).
  EXPECT_LE(err_many / n, err_one / n * 1.2);
  EXPECT_LT(err_many / n, 0.06);
  EXPECT_GT(moved / n, 0.005);
}

TEST(Detector, NegativesGiveNoMarkers) {
  const Detector det({make_aruco_original(), *dictionary_by_name("4X4_50"), *dictionary_by_name("APRILTAG_36h11")});
  cv::Mat blank(480, 640, CV_8UC1, cv::Scalar(128));
  cv::Mat noise(480, 640, CV_8UC1);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat checker(480, 640, CV_8UC1, cv::Scalar(255));
  for (int y = 0; y < 480; y += 40)
    for (int x = 0; x < 640; x += 40)
      if ((x / 40 + y / 40) % 2) checker(cv::Rect(x, y, 40, 40)).setTo(0);
  cv::Mat text(480, 640, CV_8UC1, cv::Scalar(240));
  for (int line = 0; line < 12; ++line)
    cv::putText(text, "The quick brown fox 0123456789 [#] ArUco", {10, 35 + line * 38}, cv::FONT_HERSHEY_DUPLEX,
                0.9, cv::Scalar(10), 2);
  for (const cv::Mat* img : {&blank, &noise, &checker, &text}) EXPECT_TRUE(det.detect(*img).empty());
}

TEST(Detector, ThinOutlinedFrameIsNoMarker) {
  // Image 57 of the bench's ARUCO_ORIGINAL set (seed 1) holds a thin red frame, 124x21 px, that stretched to a
  // square reads as id 1023 (01110 in every row). min_side_rate 0.1 drops such slivers; 0.05 lets it through to
  // identification.
  const Dictionary d = make_aruco_original();
  const SetItem item = make_set_item({d}, mixed_sizes(), 1, 57);
  auto has_1023 = [](const std::vector<Marker>& ms) {
    return std::any_of(ms.begin(), ms.end(), [](const Marker& m) { return m.id == 1023; });
  };
  for (const auto& t : item.truth) ASSERT_NE(t.id, 1023);
  EXPECT_FALSE(has_1023(Detector({d}).detect(item.image)));
  // identification's bar check drops it too: its inside reads as stripes along its length.
  DetectorParams loose;
  loose.min_side_rate = 0.05;
  EXPECT_FALSE(has_1023(Detector({d}, loose).detect(item.image)));
  loose.bar_min_aspect_rate = 0;
  EXPECT_TRUE(has_1023(Detector({d}, loose).detect(item.image)));
}

TEST(Detector, APieceOfALargerDarkShapeIsNoMarker) {
  // Image 67 of the bench's ARUCO_ORIGINAL set (seed 1): inside a decoy's black pattern, a white hole and the black
  // around it make a quad that reads as id 1023 with no bit wrong. To its right the decoy stays black: no quiet zone.
  const Dictionary d = make_aruco_original();
  const SetItem item = make_set_item({d}, mixed_sizes(), 1, 67);
  auto ids = [](const std::vector<Marker>& ms) {
    std::vector<int> out;
    for (const auto& m : ms) out.push_back(m.id);
    std::sort(out.begin(), out.end());
    return out;
  };
  std::vector<int> truth;
  for (const auto& t : item.truth) truth.push_back(t.id);
  std::sort(truth.begin(), truth.end());
  ASSERT_EQ(std::count(truth.begin(), truth.end(), 1023), 0);
  EXPECT_EQ(ids(Detector({d}).detect(item.image)), truth);
  DetectorParams off;
  off.quiet_zone_max_dark_rate = 1;
  const std::vector<int> without = ids(Detector({d}, off).detect(item.image));
  EXPECT_EQ(std::count(without.begin(), without.end(), 1023), 1);
  // Its fate names the parameter and the side.
  FrameTrace t;
  Detector({d}).detect(item.image, &t, TraceLevel::full);
  const auto it = std::find_if(t.candidates.begin(), t.candidates.end(), [](const CandidateRecord& c) {
    return c.fate.param == "quiet_zone_max_dark_rate";
  });
  ASSERT_NE(it, t.candidates.end());
  EXPECT_EQ(it->fate.stage, Stage::border_check);
  EXPECT_NE(it->fate.message.find("its right side"), std::string::npos) << it->fate.message;
}

TEST(Detector, TheFineSearchFindsASmallBlurredMarkerTheDecimatedSearchCouldNotClose) {
  // Image 22 of the bench's standard ARUCO_ORIGINAL set (seed 1), 1280x720: id 199 is 22 px, blurred, beside a
  // shadow. Searched at half size its outline is 11 px and does not close into a quad; at full size it does.
  const Dictionary d = *dictionary_by_name("ARUCO_ORIGINAL");
  const SetItem item = make_set_item({d}, mixed_sizes(), 1, 22, SetKind::standard);
  ASSERT_EQ(item.image.size(), cv::Size(1280, 720));
  DetectorParams p;
  p.decimation_factor = 2;
  DetectorParams off = p;
  off.fine_max_side_px = 0;
  auto has_199 = [](const std::vector<Marker>& ms) {
    return std::any_of(ms.begin(), ms.end(), [](const Marker& m) { return m.id == 199; });
  };
  FrameTrace t_off;
  EXPECT_FALSE(has_199(Detector({d}, off).detect(item.image, &t_off, TraceLevel::summary)));
  EXPECT_EQ(t_off.stage(Stage::fine_search)->in, 0) << "off: nothing searched again";
  FrameTrace t;
  const std::vector<Marker> found = Detector({d}, p).detect(item.image, &t, TraceLevel::full);
  ASSERT_TRUE(has_199(found));
  EXPECT_EQ(found.size(), item.truth.size());
  const StageRecord* fine = t.stage(Stage::fine_search);
  ASSERT_TRUE(fine);
  EXPECT_GT(fine->in, 0);
  EXPECT_GT(fine->out, 0);
  // Its picture: the full-resolution binary inside the regions searched again, black elsewhere; the marker's
  // region is one of them.
  ASSERT_EQ(fine->image.size(), item.image.size());
  const Marker& m = *with_id(found, 199);
  const cv::Rect box = cv::boundingRect(std::vector<cv::Point2f>(m.corners.begin(), m.corners.end()));
  EXPECT_GT(cv::countNonZero(fine->image(box & cv::Rect({}, fine->image.size()))), 0);
  EXPECT_LT(cv::countNonZero(fine->image), int(fine->image.total() / 4)) << "only small regions";
  // Without the full trace the shapes cut by a region's edge are not traced, only counted: the same counts and
  // markers.
  FrameTrace t_summary;
  const std::vector<Marker> found_summary = Detector({d}, p).detect(item.image, &t_summary, TraceLevel::summary);
  ASSERT_EQ(found_summary.size(), found.size());
  for (size_t i = 0; i < found.size(); ++i) {
    EXPECT_EQ(found_summary[i].id, found[i].id);
    EXPECT_EQ(found_summary[i].corners, found[i].corners);
  }
  EXPECT_EQ(t_summary.stage(Stage::fine_search)->in, fine->in);
  EXPECT_EQ(t_summary.stage(Stage::fine_search)->out, fine->out);
  const auto cut_in_fine = std::count_if(t.candidates.begin(), t.candidates.end(), [](const CandidateRecord& c) {
    return c.fate.stage == Stage::fine_search && c.fate.param == "region_margin_rate";
  });
  EXPECT_GT(cut_in_fine, 0) << "the image has shapes cut by a fine region's edge";
  // At full resolution from the start (decimation_factor 1; the default decimates a frame this size) there is
  // nothing to search again.
  DetectorParams every_pixel;
  every_pixel.decimation_factor = 1;
  FrameTrace t_full;
  EXPECT_TRUE(has_199(Detector({d}, every_pixel).detect(item.image, &t_full, TraceLevel::summary)));
  EXPECT_EQ(t_full.stage(Stage::fine_search)->in, 0);
}

// Each quad is read as found first and refined and read again only when that read could be a marker
// (unrefined_miss_rate). On photographs of the bench's standard sets it finds exactly the markers, corners and all,
// of refining every quad; the quads it stops are named so in the trace, and none of them is a marker.
TEST(Detector, QuadsReadAsFoundAreRefinedOnlyWhenTheyCouldBeMarkers) {
  int stopped_total = 0, stopped_at_id = 0;
  for (const char* name : {"ARUCO_ORIGINAL", "APRILTAG_36h11"}) {
    const Dictionary d = *dictionary_by_name(name);
    DetectorParams every;
    every.unrefined_miss_rate = 1;
    // At unrefined_miss_rate 0 images 49 and 85 (ARUCO_ORIGINAL) and at 0.1 image 43 (APRILTAG_36h11) read a
    // marker from another of its quads, with other corners: those frames sit nearest the default's edge.
    for (int i : {0, 1, 2, 43, 49, 85}) {
      const SetItem item = make_set_item({d}, mixed_sizes(), 1, i, SetKind::standard);
      FrameTrace t;
      const std::vector<Marker> found = Detector({d}).detect(item.image, &t, TraceLevel::full);
      FrameTrace t_every;
      const std::vector<Marker> found_every = Detector({d}, every).detect(item.image, &t_every, TraceLevel::full);
      ASSERT_EQ(found.size(), found_every.size()) << name << " image " << i;
      for (size_t m = 0; m < found.size(); ++m) {
        EXPECT_EQ(found[m].id, found_every[m].id) << name << " image " << i;
        EXPECT_EQ(found[m].corners, found_every[m].corners) << name << " image " << i;
      }
      EXPECT_EQ(t.candidates.size(), t_every.candidates.size()) << "the same quads reach the reader";
      for (const CandidateRecord& c : t_every.candidates) {
        EXPECT_EQ(c.fate.message.find("as found"), std::string::npos) << "at 1 every quad is refined first";
        EXPECT_FALSE(c.read_as_found);
      }
      for (const CandidateRecord& c : t.candidates) {
        EXPECT_EQ(c.read_as_found, c.fate.message.find("before corner_refinement") != std::string::npos)
            << c.fate.message;
        if (c.fate.message.find("before corner_refinement") == std::string::npos) continue;
        ++stopped_total;
        ASSERT_TRUE(c.has_quad);
        EXPECT_TRUE(c.fate.stage == Stage::otsu || c.fate.stage == Stage::border_check ||
                    c.fate.stage == Stage::identification)
            << c.fate.message;
        if (c.fate.stage == Stage::identification) {
          ++stopped_at_id;
          EXPECT_EQ(c.fate.param, "unrefined_miss_rate");
          EXPECT_GT(c.fate.value, c.fate.limit);
        }
        EXPECT_FALSE(c.warp.empty()) << "the full trace keeps the frontal view it read as found";
        // No marker of the truth has this quad (the trace's quads are in working pixels: scale them).
        for (const TruthMarker& tm : item.truth) {
          double far = 0;
          for (int j = 0; j < 4; ++j) {
            double nearest = 1e9;
            for (int k = 0; k < 4; ++k) {
              const cv::Point2f q(float((c.quad[size_t(k)].x + 0.5) * t.scale_x - 0.5),
                                  float((c.quad[size_t(k)].y + 0.5) * t.scale_y - 0.5));
              nearest = std::min(nearest, cv::norm(q - tm.corners[size_t(j)]));
            }
            far = std::max(far, nearest);
          }
          EXPECT_GT(far, 4.0) << name << " image " << i << ": marker " << tm.id << " was stopped: "
                              << c.fate.message;
        }
      }
    }
  }
  EXPECT_GT(stopped_total, 40) << "clutter is stopped before refinement";
  EXPECT_GT(stopped_at_id, 5) << "some of it by its nearest id";
}

TEST(Detector, MoreBitErrorsThanTheBudgetGiveNoMarker) {
  // 4X4_50 corrects 1 bit at the default rate (max 1 x 0.6 rounds down to 0 ... so use rate 1).
  const Dictionary d = *dictionary_by_name("4X4_50");
  DetectorParams p;
  p.error_correction_rate = 1.0;
  const Detector det({d}, p);
  const int budget = d.max_correction_bits();
  ASSERT_GE(budget, 1);
  for (int flips = 0; flips <= budget + 1; ++flips) {
    uint64_t code = d.code(9);
    for (int b = 0; b < flips; ++b) code ^= uint64_t(1) << (b * 5);
    const Dictionary one("4X4_50", 4, {code}, 0);  // draws the corrupted pattern
    cv::Mat img(200, 200, CV_8UC1, cv::Scalar(255));
    draw_marker(img, one, 0, Quad{cv::Point2f(50, 50), {150, 50}, {150, 150}, {50, 150}});
    const auto found = det.detect(img);
    if (d.nearest(code).hamming <= budget) {
      ASSERT_EQ(found.size(), 1u) << flips << " flipped";
      EXPECT_EQ(found[0].id, d.nearest(code).id);
      EXPECT_EQ(found[0].hamming, flips);
    } else {
      EXPECT_TRUE(found.empty()) << flips << " flipped";
    }
  }
}

// An AprilTag family corrects its share of half its minimum distance (36h11: 0.6 x 5 = 3 bits), as AprilTag 3
// corrects bits, though OpenCV gives these families no correction at all.
TEST(Detector, AnAprilTagWithThreeWrongBitsIsReadAndWithFourIsNot) {
  const Dictionary d = *dictionary_by_name("APRILTAG_36h11");
  const Detector det({d});
  ASSERT_EQ(stages::correction_budget(d, det.params()), 3);
  for (int flips = 0; flips <= 4; ++flips) {
    uint64_t code = d.code(101);
    for (int b = 0; b < flips; ++b) code ^= uint64_t(1) << (b * 7 + 3);
    const Dictionary one("APRILTAG_36h11", 6, {code}, 0);   // draws the corrupted pattern
    cv::Mat img(240, 240, CV_8UC1, cv::Scalar(255));
    draw_marker(img, one, 0, Quad{cv::Point2f(40, 40), {200, 40}, {200, 200}, {40, 200}});
    const auto found = det.detect(img);
    ASSERT_EQ(d.nearest(code).hamming, flips);
    if (flips <= 3) {
      ASSERT_EQ(found.size(), 1u) << flips << " flipped";
      EXPECT_EQ(found[0].id, 101);
      EXPECT_EQ(found[0].hamming, flips);
    } else {
      EXPECT_TRUE(found.empty()) << flips << " flipped";
    }
  }
}

TEST(Detector, SameResultsForAnyThreadCount) {
  const Dictionary d = make_aruco_original();
  const Detector det({d});
  SynthOptions opt;
  opt.dictionaries = {d};
  opt.size = {1280, 720};
  for (int i = 0; i < 6; ++i) {
    const SynthImage s = synth_photo(opt, 11, i);
    const auto one = det.detect(s.image, nullptr, TraceLevel::off, 1);
    for (int threads : {2, 3, 8}) {
      const auto many = det.detect(s.image, nullptr, TraceLevel::off, threads);
      ASSERT_EQ(one.size(), many.size());
      for (size_t k = 0; k < one.size(); ++k) {
        EXPECT_EQ(one[k].id, many[k].id);
        for (int c = 0; c < 4; ++c) EXPECT_EQ(one[k].corners[size_t(c)], many[k].corners[size_t(c)]);
      }
    }
  }
}

TEST(Detector, SeveralDictionariesInOnePass) {
  const Dictionary a = make_aruco_original(), b = *dictionary_by_name("APRILTAG_36h11"),
                   c = *dictionary_by_name("4X4_50");
  cv::Mat img(300, 600, CV_8UC1, cv::Scalar(220));
  draw_marker(img, a, 700, Quad{cv::Point2f(30, 80), {170, 80}, {170, 220}, {30, 220}});
  draw_marker(img, b, 400, Quad{cv::Point2f(230, 80), {370, 80}, {370, 220}, {230, 220}});
  draw_marker(img, c, 42, Quad{cv::Point2f(430, 80), {570, 80}, {570, 220}, {430, 220}});
  const auto found = Detector({a, b, c}).detect(img);
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].dict, "ARUCO_ORIGINAL");
  EXPECT_EQ(found[0].id, 700);
  EXPECT_EQ(found[1].dict, "APRILTAG_36h11");
  EXPECT_EQ(found[1].id, 400);
  EXPECT_EQ(found[2].dict, "4X4_50");
  EXPECT_EQ(found[2].id, 42);
}

TEST(Trace, RecordsEveryStageAndEachCandidatesFate) {
  const Dictionary d = make_aruco_original();
  cv::Mat img(240, 320, CV_8UC1, cv::Scalar(230));
  draw_marker(img, d, 77, Quad{cv::Point2f(40, 40), {140, 40}, {140, 140}, {40, 140}});
  cv::rectangle(img, cv::Rect(200, 60, 80, 80), cv::Scalar(20), -1);  // a black square: a quad, no marker
  const Detector det({d});
  FrameTrace t;
  const auto found = det.detect(img, &t, TraceLevel::full);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(t.stages.size(), size_t(kStageCount));
  for (int s = 0; s < kStageCount; ++s) EXPECT_EQ(t.stages[size_t(s)].stage, static_cast<Stage>(s));
  EXPECT_FALSE(t.stage(Stage::adaptive_threshold)->image.empty());
  EXPECT_FALSE(t.contours.empty());
  int accepted = 0, uniform = 0;
  for (const auto& c : t.candidates) {
    if (c.fate.stage == Stage::accepted) {
      ++accepted;
      EXPECT_EQ(c.marker, 0);
      EXPECT_EQ(c.warp.size(), cv::Size(56, 56));   // 14 px a cell: viewed at twice warp_cell_px
      EXPECT_EQ(c.bits.size(), cv::Size(7, 7));
      EXPECT_EQ(c.histogram.size(), 256u);
      EXPECT_EQ(c.border_errors, 0);
      EXPECT_EQ(c.per_rotation[size_t(found[0].rotation)].id, 77);
    }
    if (c.fate.stage == Stage::otsu) {
      uniform += c.bbox == cv::Rect(200, 60, 80, 80);   // (a speck between the marker's cells may be uniform too)
      EXPECT_EQ(c.fate.param, "otsu_min_stddev");
    }
    if (c.fate.stage != Stage::accepted) {
      EXPECT_FALSE(c.fate.message.empty());
    }
  }
  EXPECT_EQ(accepted, 1);
  EXPECT_EQ(uniform, 1);  // the black square's inside is one grey level

  FrameTrace off;
  det.detect(img, &off, TraceLevel::off);
  EXPECT_TRUE(off.stages.empty());
  EXPECT_TRUE(off.candidates.empty());
  EXPECT_EQ(off.markers.size(), 1u);
}

// decimation_factor 2: the search runs on the half-size image, yet every marker of 40 px and more on clean renders
// is found with its corners placed on the full image, as precisely as a full search places them; the same markers
// for any thread count.
TEST(Detector, DecimatedSearchFindsTheMarkersAndPlacesCornersOnTheFullImage) {
  const Dictionary d = make_aruco_original();
  DetectorParams half;
  half.decimation_factor = 2;
  const Detector full_search({d}), decimated({d}, half);
  SynthOptions opt;
  opt.dictionaries = {d};
  opt.effects = false;
  opt.empty_fraction = 0;
  opt.min_side_px = 40;
  double err_full = 0, err_half = 0;
  int n = 0;
  for (int i = 0; i < 16; ++i) {
    const SynthImage s = synth_photo(opt, 21, i);
    const auto a = full_search.detect(s.image), b = decimated.detect(s.image);
    ASSERT_EQ(b.size(), s.markers.size()) << "image " << i;
    for (const auto& m : b)
      for (const auto& t : s.markers)
        if (t.id == m.id) err_half += mean_corner_error(m, t), ++n;
    for (const auto& m : a)
      for (const auto& t : s.markers)
        if (t.id == m.id) err_full += mean_corner_error(m, t);
    for (int threads : {2, 5}) {
      const auto many = decimated.detect(s.image, nullptr, TraceLevel::off, threads);
      ASSERT_EQ(many.size(), b.size());
      for (size_t k = 0; k < b.size(); ++k)
        for (size_t c = 0; c < 4; ++c) EXPECT_EQ(many[k].corners[c], b[k].corners[c]);
    }
  }
  ASSERT_GT(n, 25);
  EXPECT_LT(err_half / n, 0.3);
  EXPECT_LT(err_half / n, 1.25 * err_full / n);
}

// At defaults a frame with a shorter side of 720 px or more is searched at half size. Image 20 of the bench's
// standard ARUCO_ORIGINAL set (seed 1), 1920x1080: id 263 is 24 px, blurred, its thin quiet zone beside a dark
// shape. At half size that quiet zone closes: the marker is part of a larger dark region, which no quad fits and
// which is too large for fine_search, but its inside is still a quad-shaped hole, and fine_search finds the marker
// around it at full resolution.
TEST(Detector, HalfSizeSearchFindsASmallMarkerMergedIntoADarkShapeByItsInside) {
  const Dictionary d = *dictionary_by_name("ARUCO_ORIGINAL");
  const SetItem item = make_set_item({d}, mixed_sizes(), 1, 20, SetKind::standard);
  ASSERT_EQ(item.image.size(), cv::Size(1920, 1080));
  const auto truth = with_id(item.truth, 263);
  ASSERT_NE(truth, item.truth.end());
  FrameTrace t;
  const std::vector<Marker> found = Detector({d}).detect(item.image, &t, TraceLevel::full);
  EXPECT_EQ(t.search.factor, 2);
  const auto m = with_id(found, 263);
  ASSERT_NE(m, found.end());
  // Placed as the search of every pixel places it at fine_search's threshold (it is blurred and in shadow: half a
  // pixel off either way, and where it lies depends on the threshold the quad was found at).
  DetectorParams every_pixel;
  every_pixel.decimation_factor = 1;
  every_pixel.threshold_offset = every_pixel.fine_threshold_offset;
  const std::vector<Marker> full = Detector({d}, every_pixel).detect(item.image);
  const auto f = with_id(full, 263);
  ASSERT_NE(f, full.end());
  EXPECT_NEAR(mean_corner_error(*m, *truth), mean_corner_error(*f, *truth), 0.05);
  EXPECT_EQ(found.size(), item.truth.size());
  // The half-size search saw the marker only inside a region larger than fine_max_side_px.
  const cv::Rect marker_box = cv::boundingRect(std::vector<cv::Point2f>(truth->corners.begin(), truth->corners.end()));
  bool merged = false;
  for (const auto& c : t.candidates)
    if (c.contour >= 0 && (c.bbox & marker_box) == marker_box && c.bbox.width > 80 && c.bbox.height > 80) merged = true;
  EXPECT_TRUE(merged);
  EXPECT_GE(t.stage(Stage::fine_search)->out, 1);
  DetectorParams no_fine;
  no_fine.fine_max_side_px = 0;
  const std::vector<Marker> without = Detector({d}, no_fine).detect(item.image);
  EXPECT_TRUE(std::none_of(without.begin(), without.end(), [](const Marker& k) { return k.id == 263; }));
}

// A colour video frame searched around its known markers converts its grey image only in those regions, around the
// candidates and in fine_search's regions; the full trace converts all of it (the acquisition stage's picture).
// Both read every marker the same, to the last bit of each corner: what the readings look at was converted.
// Standard and hard frames, 1280x720 up; the whole frame searched at half size is converted whole.
TEST(Detector, AColourFrameReadsTheSameWithItsGreyConvertedWhereLooked) {
  const Dictionary d = *dictionary_by_name("ARUCO_ORIGINAL");
  const Detector det({d});
  int frames = 0, markers = 0;
  for (const SetKind kind : {SetKind::standard, SetKind::hard})
    for (int index = 0; index < 12; ++index) {
      const SetItem item =
          make_set_item({d}, kind == SetKind::hard ? hard_sizes() : mixed_sizes(), 1, index, kind);
      if (std::min(item.image.cols, item.image.rows) < 720 || item.image.cols > 1920) continue;
      ASSERT_EQ(item.image.type(), CV_8UC3);
      FrameTrace t;
      const std::vector<Marker> all = det.detect(item.image, &t, TraceLevel::full);
      ASSERT_EQ(t.search.factor, 2);
      const std::vector<Marker> looked = det.detect(item.image);
      ASSERT_EQ(looked.size(), all.size()) << "image " << index;
      for (size_t i = 0; i < all.size(); ++i) {
        EXPECT_EQ(looked[i].id, all[i].id);
        for (size_t j = 0; j < 4; ++j) EXPECT_EQ(looked[i].corners[j], all[i].corners[j]) << "image " << index;
      }
      // The next frame, searched around these markers.
      SearchHint hint;
      for (const Marker& m : all) hint.known.push_back(m.corners);
      if (hint.known.empty()) continue;
      FrameTrace regions;
      const std::vector<Marker> around = det.detect(item.image, &regions, TraceLevel::full, 1, nullptr, &hint);
      ASSERT_FALSE(regions.search.whole) << "image " << index;
      FrameTrace summary;
      const std::vector<Marker> lazily = det.detect(item.image, &summary, TraceLevel::summary, 1, nullptr, &hint);
      ASSERT_EQ(lazily.size(), around.size()) << "image " << index;
      for (size_t i = 0; i < around.size(); ++i) {
        EXPECT_EQ(lazily[i].id, around[i].id);
        for (size_t j = 0; j < 4; ++j) EXPECT_EQ(lazily[i].corners[j], around[i].corners[j]) << "image " << index;
      }
      ++frames;
      markers += int(all.size());
    }
  EXPECT_GE(frames, 8);
  EXPECT_GE(markers, 20);
}

// The decimation stage is in the trace with its time, and at full level its picture (and the threshold's) is the
// search image; the views stretch both back to the working size, so they line up with the frame. Contours and
// quads are in the frame's pixels.
TEST(Trace, DecimationIsAStageWhosePicturesLineUpWithTheFrame) {
  const Dictionary d = make_aruco_original();
  cv::Mat img(240, 320, CV_8UC1, cv::Scalar(230));
  draw_marker(img, d, 77, Quad{cv::Point2f(40, 40), {140, 40}, {140, 140}, {40, 140}});
  DetectorParams p;
  p.decimation_factor = 2;
  FrameTrace t;
  const auto found = Detector({d}, p).detect(img, &t, TraceLevel::full);
  ASSERT_EQ(found.size(), 1u);
  const StageRecord* dec = t.stage(Stage::decimation);
  ASSERT_NE(dec, nullptr);
  EXPECT_GE(dec->ms, 0.0);
  EXPECT_EQ(dec->image.size(), img.size() / 2);
  const StageRecord* thr = t.stage(Stage::adaptive_threshold);
  ASSERT_NE(thr, nullptr);
  EXPECT_EQ(thr->image.size(), img.size() / 2);
  std::array<cv::Mat, kStageCount> views;
  render_stage_views(cv::Mat(), t, views);
  const cv::Mat& shown = views[size_t(Stage::decimation)];
  ASSERT_EQ(shown.size(), img.size());
  EXPECT_EQ(shown.at<cv::Vec3b>(90, 20), cv::Vec3b(230, 230, 230));
  EXPECT_LT(shown.at<cv::Vec3b>(46, 50)[0], 60);  // in the marker's black frame
  EXPECT_EQ(views[size_t(Stage::adaptive_threshold)].size(), img.size());
  const auto accepted = std::find_if(t.candidates.begin(), t.candidates.end(),
                                     [](const CandidateRecord& c) { return c.fate.stage == Stage::accepted; });
  ASSERT_NE(accepted, t.candidates.end());
  EXPECT_NEAR(accepted->bbox.x, 40, 2);
  EXPECT_NEAR(accepted->bbox.width, 100, 3);
  EXPECT_NEAR(accepted->perimeter, 400, 16);
  // Off: the same markers.
  const auto quiet = Detector({d}, p).detect(img);
  ASSERT_EQ(quiet.size(), 1u);
  EXPECT_EQ(quiet[0].corners, found[0].corners);
}

// `arwb synth --size 1280x720 --seed 3`, image 2: id 414 is 21 px, and a thin dark line crosses its quiet zone. At
// half size the two merge into one shape, longer than fine_max_side_px, that no quad fits and whose inside is no
// quad-shaped hole (the marker's cells break it up). quad_fit cuts the line's stub (cut_thin_lines).
TEST(Detector, HalfSizeSearchFindsASmallMarkerJoinedToAThinLine) {
  const Dictionary d = *dictionary_by_name("ARUCO_ORIGINAL");
  const SetItem item = make_set_item({d}, {cv::Size(1280, 720)}, 3, 2, SetKind::standard);
  const auto truth = with_id(item.truth, 414);
  ASSERT_NE(truth, item.truth.end());
  FrameTrace t;
  const std::vector<Marker> found = Detector({d}).detect(item.image, &t, TraceLevel::full);
  EXPECT_EQ(t.search.factor, 2);
  const auto m = with_id(found, 414);
  ASSERT_NE(m, found.end());
  EXPECT_LT(mean_corner_error(*m, *truth), 0.5);
  // The half-size search saw it in a shape longer than fine_max_side_px that quad_fit turned down.
  const cv::Rect marker_box = cv::boundingRect(std::vector<cv::Point2f>(truth->corners.begin(), truth->corners.end()));
  bool merged = false;
  for (const auto& c : t.candidates)
    if (c.contour >= 0 && c.fate.stage == Stage::quad_fit && (c.bbox & marker_box) == marker_box &&
        std::max(c.bbox.width, c.bbox.height) > 80)
      merged = true;
  EXPECT_TRUE(merged);
  DetectorParams uncut;
  uncut.cut_thin_lines = 0;
  const std::vector<Marker> without = Detector({d}, uncut).detect(item.image);
  EXPECT_TRUE(std::none_of(without.begin(), without.end(), [](const Marker& k) { return k.id == 414; }));
}
