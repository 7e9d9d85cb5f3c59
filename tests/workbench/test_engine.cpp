// The workbench's worker (src/workbench/engine.hpp) without a window: it publishes frames, holds still when frozen,
// re-detects a frozen frame when the parameters change, and falls back to the synthetic source when its source
// goes away while running.
#include "workbench/engine.hpp"
#include "synth/synth.hpp"
#include "support/numbered_video.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <mutex>
#include <thread>

namespace arwb {
namespace {

namespace fs = std::filesystem;

// The frame a freeze holds: the newest once none has come for 400 ms. A frame in flight when the freeze came
// lands after it, late on a loaded machine under the sanitizers (200 ms was not always enough).
std::shared_ptr<const Frame> frozen_frame(const Engine& e) {
  auto held = e.latest();
  for (int i = 0; i < 25; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(400));
    auto now = e.latest();
    if (now->index == held->index) break;
    held = std::move(now);
  }
  return held;
}

struct Logged {
  std::mutex m;
  std::vector<std::pair<int, std::string>> lines;
  Engine::LogFn fn() {
    return [this](int level, const std::string& s) {
      std::lock_guard lock(m);
      lines.emplace_back(level, s);
    };
  }
  bool has(int level, const std::string& part) {
    std::lock_guard lock(m);
    for (const auto& [l, s] : lines)
      if (l == level && s.find(part) != std::string::npos) return true;
    return false;
  }
};

EngineConfig synthetic_config() {
  EngineConfig c;
  c.acquisition.fps_cap = 50;
  return c;
}

// The same on a file source.
EngineConfig file_config(SourceKind kind, const std::string& path) {
  EngineConfig c = synthetic_config();
  c.source.kind = kind;
  c.source.path = path;
  return c;
}

TEST(Engine, PublishesDetectedFramesOfTheSyntheticScene) {
  Logged log;
  Engine e(synthetic_config(), log.fn());
  e.start();
  auto f = e.wait_newer(0, 5.0);
  ASSERT_TRUE(f);
  f = e.wait_newer(f->index, 5.0);   // a second, newer frame arrives
  ASSERT_TRUE(f);
  EXPECT_GE(f->index, 2u);
  EXPECT_EQ(f->image.size(), cv::Size(640, 480));
  EXPECT_EQ(f->trace.level, TraceLevel::full);
  EXPECT_FALSE(f->views[static_cast<size_t>(Stage::contours)].empty());
  EXPECT_FALSE(f->truth.empty());
  EXPECT_EQ(f->trace.markers.size(), f->truth.size());
}

TEST(Engine, FrozenHoldsTheFrameUntilNextFrameIsAsked) {
  Logged log;
  Engine e(synthetic_config(), log.fn());
  e.start();
  ASSERT_TRUE(e.wait_newer(0, 5.0));
  e.set_frozen(true);
  const uint64_t held = frozen_frame(e)->index;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(e.latest()->index, held);
  e.next_frame();
  const auto next = e.wait_newer(held, 5.0);
  ASSERT_TRUE(next);
  EXPECT_EQ(next->index, held + 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(e.latest()->index, held + 1);
}

TEST(Engine, NewParametersRedetectTheFrozenFrame) {
  Logged log;
  Engine e(synthetic_config(), log.fn());
  e.start();
  ASSERT_TRUE(e.wait_newer(0, 5.0));
  e.set_frozen(true);
  const auto before = frozen_frame(e);
  ASSERT_FALSE(before->trace.markers.empty());
  DetectorParams p;
  p.min_perimeter_px = 5000;   // longer than any marker's border here
  e.set_params(p);
  const auto after = e.wait_newer(before->index, 5.0);
  ASSERT_TRUE(after);
  EXPECT_TRUE(after->trace.markers.empty());
  EXPECT_EQ(cv::norm(before->image, after->image, cv::NORM_INF), 0.0);   // the same frame, read again
}

// The stream is a video: most frames are searched around the last one's markers, the whole frame every
// full_search_interval frames. A frozen frame read again is searched as it was when it came, its regions following
// the sliders.
TEST(Engine, TheStreamIsSearchedAsVideoAndAFrozenFrameAsItCame) {
  Logged log;
  Engine e(synthetic_config(), log.fn());
  e.start();
  int regions = 0, whole = 0;
  uint64_t last = 0;
  for (int k = 0; k < 15; ++k) {
    const auto f = e.wait_newer(last, 5.0);
    ASSERT_TRUE(f);
    last = f->index;
    ASSERT_NE(f->trace.stage(Stage::search_regions), nullptr);
    (f->trace.search.whole ? whole : regions)++;
  }
  EXPECT_GE(regions, 6);
  EXPECT_GE(whole, 2);
  e.set_frozen(true);
  const auto before = frozen_frame(e);
  DetectorParams p;
  p.region_margin_rate = 2;
  e.set_params(p);
  const auto after = e.wait_newer(before->index, 5.0);
  ASSERT_TRUE(after);
  EXPECT_EQ(after->trace.search.whole, before->trace.search.whole);
  EXPECT_EQ(after->trace.search.known, before->trace.search.known);
  EXPECT_EQ(after->trace.markers.size(), before->trace.markers.size());
  auto area = [](const SearchRecord& s) {
    double a = 0;
    for (const cv::Rect& r : s.regions) a += r.area();
    return a;
  };
  if (!before->trace.search.whole) {
    EXPECT_GE(area(after->trace.search), area(before->trace.search));
  }
}

TEST(Engine, FramesRecordTheParametersTheyWereDetectedWith) {
  Logged log;
  Engine e(synthetic_config(), log.fn());
  e.start();
  ASSERT_TRUE(e.wait_newer(0, 5.0));
  e.set_frozen(true);
  const auto before = frozen_frame(e);
  EXPECT_EQ(before->params, DetectorParams());
  EXPECT_EQ(before->dictionaries, std::vector<std::string>({"ARUCO_ORIGINAL"}));
  DetectorParams p;
  p.error_correction_rate = 0.25;
  e.set_params(p);
  // A frame already being detected when the change arrived (a loaded machine) is published with the old
  // parameters; the one after it must carry the new ones.
  auto after = e.wait_newer(before->index, 5.0);
  for (int i = 0; after && after->params.error_correction_rate != 0.25 && i < 3; ++i) after = e.wait_newer(after->index, 5.0);
  ASSERT_TRUE(after);
  EXPECT_DOUBLE_EQ(after->params.error_correction_rate, 0.25);
  EXPECT_EQ(before->params, DetectorParams());   // a published frame keeps its own
}

TEST(Engine, PeersAreMatchedToArwbOnTheWorker) {
  Logged log;
  Engine e(synthetic_config(), log.fn());
  e.set_peers(true, true);
  e.start();
  std::shared_ptr<const Frame> f;
  for (uint64_t after = 0; !f || f->peers.size() < 2 || f->trace.markers.empty();) {
    f = e.wait_newer(after, 5.0);
    ASSERT_TRUE(f);
    after = f->index;
    ASSERT_LT(after, 50u) << "no frame with markers and both peers";
  }
  const PeerDetections& ocv = f->peers[0];
  ASSERT_EQ(ocv.name, "opencv_aruco");
  ASSERT_TRUE(ocv.error.empty()) << ocv.error;
  // Every arwb marker is either matched or listed as arwb's alone; every peer marker likewise.
  EXPECT_EQ(ocv.matching.pairs.size() + ocv.matching.only_reference.size(), f->trace.markers.size());
  EXPECT_EQ(ocv.matching.pairs.size() + ocv.matching.only_found.size(), ocv.markers.size());
  EXPECT_FALSE(ocv.matching.pairs.empty());
  for (const MatchedPair& m : ocv.matching.pairs) {
    ASSERT_LT(m.reference, f->trace.markers.size());
    ASSERT_LT(m.found, ocv.markers.size());
    EXPECT_EQ(f->trace.markers[m.reference].id, ocv.markers[m.found].id);
    EXPECT_LE(m.corner_px, match_tolerance_px(f->trace.markers[m.reference].corners));
  }
  EXPECT_EQ(ocv.other_dicts, 0);
  // AprilTag cannot read ARUCO_ORIGINAL: it says so and matches nothing.
  EXPECT_EQ(f->peers[1].name, "apriltag");
  EXPECT_FALSE(f->peers[1].error.empty());
  EXPECT_TRUE(f->peers[1].matching.pairs.empty());
}

TEST(Engine, SceneSettingsSurviveASwitchToAnotherSourceAndBack) {
  test::TempDir tmp;
  cv::imwrite(tmp.str("still.png"), cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(128)));
  Logged log;
  Engine e(synthetic_config(), log.fn());
  SyntheticControls one;
  one.markers = 1;
  e.set_synthetic(one);
  e.start();
  auto f = e.wait_newer(0, 5.0);
  ASSERT_TRUE(f);
  SourceSpec still;
  still.kind = SourceKind::image;
  still.path = tmp.str("still.png");
  e.open_source(still);
  for (int i = 0; i < 100 && (!f || f->source.kind != SourceKind::image); ++i) f = e.wait_newer(f->index, 0.1);
  ASSERT_EQ(f->source.kind, SourceKind::image);
  e.open_source(SourceSpec{});
  for (int i = 0; i < 100 && f->source.kind != SourceKind::synthetic; ++i) f = e.wait_newer(f->index, 0.1);
  ASSERT_EQ(f->source.kind, SourceKind::synthetic);
  EXPECT_EQ(f->truth.size(), 1u) << "the new synthetic source got the scene's sliders";
}

TEST(Engine, FallsBackToTheSyntheticSceneWhenTheFolderGoes) {
  test::TempDir tmp;
  const std::string folder = tmp.str("shots");
  fs::create_directories(folder);
  const Dictionary d = make_aruco_original();
  for (int i = 0; i < 3; ++i) {
    cv::Mat img(480, 640, CV_8UC3, cv::Scalar::all(170));
    draw_marker(img, d, 10 + i, project_square({320, 240}, 140, 10.0 * i, 0, 0, 800));
    cv::imwrite(folder + "/" + std::to_string(i) + ".png", img);
  }
  Logged log;
  const EngineConfig c = file_config(SourceKind::folder, folder);
  Engine e(c, log.fn());
  e.set_playback({true, true, 8.0});   // eight images a second
  e.start();
  auto f = e.wait_newer(0, 5.0);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->source.kind, SourceKind::folder);
  fs::remove_all(folder);
  for (int i = 0; i < 100 && e.source().kind != SourceKind::synthetic; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(e.source().kind, SourceKind::synthetic);
  EXPECT_TRUE(log.has(2, "shots")) << "the error names the folder";
  f = e.wait_newer(e.latest()->index, 5.0);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->source.kind, SourceKind::synthetic);
}

// Next frame on a frozen, playing video shows the frame after the one shown, whatever its clock has reached
// meanwhile, and the frame's source position is the picture's number; it plays on from there when unfrozen.
class FrozenVideo : public ::testing::TestWithParam<const char*> {};

TEST_P(FrozenVideo, NextFrameIsTheFrameAfterTheOneShown) {
  test::TempDir tmp;
  const std::string ext = GetParam(), path = tmp.str("clip." + ext);
  if (!test::write_numbered_video(path, ext == "avi" ? "MJPG" : "mp4v", 60, {128, 96}, 25))
    GTEST_SKIP() << "no writer for " << ext << " in this OpenCV";
  const EngineConfig c = file_config(SourceKind::video, path);
  Logged log;
  Engine e(c, log.fn());
  e.start();
  auto f = e.wait_newer(0, 5.0);
  ASSERT_TRUE(f);
  for (int i = 0; i < 100 && f->source.position < 3; ++i) f = e.wait_newer(f->index, 1.0);   // playing
  e.set_frozen(true);
  f = frozen_frame(e);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));   // the clock would pass 12 frames
  for (int k = 0; k < 3; ++k) {
    const int shown = f->source.position;
    EXPECT_EQ(test::numbered_frame(f->image), shown);
    const uint64_t ticket = e.next_frame();
    for (int i = 0; i < 500 && e.served() < ticket; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    f = e.latest();
    EXPECT_EQ(f->source.position, shown + 1);
    EXPECT_EQ(test::numbered_frame(f->image), shown + 1) << "the picture is the frame its position says";
    EXPECT_EQ(frame_label(*f), "frame " + std::to_string(shown + 1));
  }
  const int held = f->source.position;
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));   // frozen longer than the gap a clock skips
  e.set_frozen(false);
  f = e.wait_newer(f->index, 5.0);
  ASSERT_TRUE(f);
  EXPECT_GT(f->source.position, held) << "it plays on";
  EXPECT_LT(f->source.position, held + 15) << "from where it was, not from where its clock ran to";
}

INSTANTIATE_TEST_SUITE_P(Containers, FrozenVideo, ::testing::Values("mp4", "avi"));

// Acquisition's default resize keeps the source's aspect: a 799x533 photograph is worked at 640x427, not
// squashed into 640x480, and its markers are those the detector finds in the whole picture.
TEST(Engine, TheDefaultResizeKeepsTheSourcesAspect) {
  test::TempDir tmp;
  const Dictionary d = make_aruco_original();
  cv::Mat photo(533, 799, CV_8UC3, cv::Scalar::all(225));
  for (int i = 0; i < 12; ++i)
    draw_marker(photo, d, 100 + i, project_square({70.0 + 130 * (i % 6), 150.0 + 230 * (i / 6)}, 70, 8.0 * i, 0, 0, 800));
  cv::imwrite(tmp.str("photo.png"), photo);
  const EngineConfig c = file_config(SourceKind::image, tmp.str("photo.png"));
  Logged log;
  Engine e(c, log.fn());
  e.start();
  const auto f = e.wait_newer(0, 5.0);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->image.size(), cv::Size(640, 427));
  const Detector whole({d}, DetectorParams{});
  EXPECT_EQ(whole.detect(photo, nullptr, TraceLevel::off, 1).size(), 12u);
  EXPECT_EQ(f->trace.markers.size(), 12u);
}

// Acquisition's resize is the detector's first stage: a 1280x960 image becomes the 640x480 working frame, the
// trace's acquisition stage times the resize, and the markers are drawn in the working frame's pixels.
TEST(Engine, AcquisitionResizeIsTheDetectorsFirstStage) {
  test::TempDir tmp;
  const Dictionary d = make_aruco_original();
  cv::Mat big(960, 1280, CV_8UC3, cv::Scalar::all(230));
  draw_marker(big, d, 12, Quad{cv::Point2f(400, 300), {800, 300}, {800, 700}, {400, 700}});
  cv::imwrite(tmp.str("big.png"), big);
  const EngineConfig c = file_config(SourceKind::image, tmp.str("big.png"));
  Logged log;
  Engine e(c, log.fn());
  e.start();
  auto f = e.wait_newer(0, 5.0);
  ASSERT_TRUE(f);
  ASSERT_EQ(f->source.kind, SourceKind::image);
  EXPECT_EQ(f->source.size, cv::Size(1280, 960));
  EXPECT_EQ(f->image.size(), cv::Size(640, 480));
  EXPECT_EQ(f->trace.work_width, 640);
  EXPECT_EQ(f->trace.width, 640);
  ASSERT_NE(f->trace.stage(Stage::acquisition), nullptr);
  EXPECT_GT(f->trace.stage(Stage::acquisition)->ms, 0);
  ASSERT_EQ(f->trace.markers.size(), 1u);
  EXPECT_NEAR(f->trace.markers[0].corners[0].x, 200 - 0.25, 1.0);   // (400 + 0.5) / 2 - 0.5
  EXPECT_NEAR(f->trace.markers[0].corners[2].y, 350 - 0.25, 1.0);

  // Resize off: the frame is worked at its own size.
  AcquisitionSettings off = c.acquisition;
  off.resize = false;
  e.set_acquisition(off);
  for (int i = 0; i < 100 && f->image.cols != 1280; ++i) f = e.wait_newer(f->index, 0.1);
  EXPECT_EQ(f->image.size(), cv::Size(1280, 960));
  EXPECT_EQ(f->trace.work_width, 1280);
  ASSERT_EQ(f->trace.markers.size(), 1u);
  EXPECT_NEAR(f->trace.markers[0].corners[0].x, 400, 1.0);
}

}  // namespace
}  // namespace arwb
