// MediaStore: images (conversion, cache), video players (offline: exact frames; live: advancing and pausing),
// text and web cards (size, straight alpha, cache and its limits).
#include "capture/source.hpp"
#include "media/media_store.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;
using arwb::MediaContent;
using arwb::MediaSpec;
using arwb::media::MediaStore;
using arwb::media::StoreMode;
using arwb::media::VideoContent;
using arwb::test::TempDir;
using arwb::test::write_file;

namespace {

// Waits until `done` holds or a generous deadline passes (a loaded machine may be slow; no speed is asserted).
bool eventually(const std::function<bool()>& done, std::chrono::seconds deadline = std::chrono::seconds(20)) {
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

uint64_t version_of(const MediaContent& content) {
  uint64_t version = 0;
  (void)content.current(&version);
  return version;
}

// ---- Videos whose frames show their own index, so a test can read which frame it got ---------------------------

constexpr int kBits = 8, kStripe = 20, kVideoW = kBits * kStripe, kVideoH = 120;

// Frame i: 8 vertical stripes, stripe b white when bit b of i is set. Survives lossy compression intact.
cv::Mat index_frame(int i) {
  cv::Mat m(kVideoH, kVideoW, CV_8UC3, cv::Scalar::all(0));
  for (int b = 0; b < kBits; ++b)
    if (i >> b & 1) m(cv::Rect(b * kStripe, 0, kStripe, kVideoH)).setTo(cv::Scalar::all(255));
  return m;
}

int frame_index(const cv::Mat& m) {
  int i = 0;
  for (int b = 0; b < kBits; ++b) {
    const cv::Scalar mean = cv::mean(m(cv::Rect(b * kStripe + 5, 20, kStripe - 10, kVideoH - 40)));
    if (mean[0] > 128) i |= 1 << b;
  }
  return i;
}

int shown_index(const VideoContent& v) {
  uint64_t version = 0;
  const auto frame = v.current(&version);
  return frame ? frame_index(*frame) : -1;
}

struct VideoFormat {
  const char* name;
  int fourcc;
};
void PrintTo(const VideoFormat& f, std::ostream* os) { *os << f.name; }

void write_index_video(const std::string& path, int fourcc, int frames, double fps) {
  cv::VideoWriter w(path, cv::CAP_FFMPEG, fourcc, fps, cv::Size(kVideoW, kVideoH));
  ASSERT_TRUE(w.isOpened()) << path;
  for (int i = 0; i < frames; ++i) w.write(index_frame(i));
}

constexpr int kFrames = 30;
constexpr double kFps = 10;

class Video : public ::testing::TestWithParam<VideoFormat> {
 protected:
  void SetUp() override { write_index_video(path, GetParam().fourcc, kFrames, kFps); }
  std::shared_ptr<VideoContent> open(MediaStore& store, bool loop) {
    std::string error = "unchanged";
    auto v = store.video(path, loop, &error);
    EXPECT_TRUE(v) << error;
    EXPECT_EQ(error, "");
    return v;
  }
  TempDir tmp;
  std::string path = tmp.str(std::string("clip.") + GetParam().name);
};

INSTANTIATE_TEST_SUITE_P(Formats, Video,
                         ::testing::Values(VideoFormat{"avi", cv::VideoWriter::fourcc('M', 'J', 'P', 'G')},
                                           VideoFormat{"mp4", cv::VideoWriter::fourcc('m', 'p', '4', 'v')}),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace

// ---- Images --------------------------------------------------------------------------------------------------

TEST(Image, DecodedOnceAsBgrAndSharedWhileHeld) {
  TempDir tmp;
  cv::Mat bgr(30, 40, CV_8UC3, cv::Scalar(10, 20, 30));
  bgr.at<cv::Vec3b>(5, 7) = cv::Vec3b(200, 100, 50);
  ASSERT_TRUE(cv::imwrite(tmp.str("a.png"), bgr));
  MediaStore store(StoreMode::offline);
  std::string error = "unchanged";
  auto a = store.image(tmp.str("a.png"), &error);
  ASSERT_TRUE(a) << error;
  EXPECT_EQ(error, "");
  EXPECT_EQ(a->size(), cv::Size(40, 30));
  uint64_t version = 0;
  auto pixels = a->current(&version);
  ASSERT_TRUE(pixels);
  EXPECT_GT(version, 0u);
  EXPECT_EQ(pixels->type(), CV_8UC3);
  EXPECT_EQ(cv::norm(*pixels, bgr, cv::NORM_INF), 0);
  EXPECT_EQ(store.image(tmp.str("a.png"), &error), a);  // the same object while someone holds it
}

TEST(Image, GreyAndSixteenBitBecomeEightBitBgr) {
  TempDir tmp;
  ASSERT_TRUE(cv::imwrite(tmp.str("grey.png"), cv::Mat(8, 8, CV_8UC1, cv::Scalar(77))));
  ASSERT_TRUE(cv::imwrite(tmp.str("deep.png"), cv::Mat(8, 8, CV_16UC3, cv::Scalar(257 * 10, 257 * 100, 65535))));
  ASSERT_TRUE(cv::imwrite(tmp.str("deep_grey.png"), cv::Mat(8, 8, CV_16UC1, cv::Scalar(257 * 200))));
  MediaStore store(StoreMode::live);
  std::string error;
  const auto pixel = [&](const std::string& name) {
    auto content = store.image(tmp.str(name), &error);
    EXPECT_TRUE(content) << error;
    if (!content) return cv::Vec3b();
    auto m = content->current(nullptr);
    EXPECT_EQ(m->type(), CV_8UC3) << name;
    return m->at<cv::Vec3b>(3, 3);
  };
  EXPECT_EQ(pixel("grey.png"), cv::Vec3b(77, 77, 77));
  EXPECT_EQ(pixel("deep.png"), cv::Vec3b(10, 100, 255));
  EXPECT_EQ(pixel("deep_grey.png"), cv::Vec3b(200, 200, 200));
}

TEST(Image, AlphaIsKeptAsBgra) {
  TempDir tmp;
  ASSERT_TRUE(cv::imwrite(tmp.str("alpha.png"), cv::Mat(8, 8, CV_8UC4, cv::Scalar(1, 2, 3, 128))));
  MediaStore store(StoreMode::offline);
  std::string error;
  auto content = store.image(tmp.str("alpha.png"), &error);
  ASSERT_TRUE(content) << error;
  auto m = content->current(nullptr);
  EXPECT_EQ(m->type(), CV_8UC4);
  EXPECT_EQ(m->at<cv::Vec4b>(4, 4), cv::Vec4b(1, 2, 3, 128));
}

TEST(Image, FailuresNameThePathAndReturnNull) {
  TempDir tmp;
  ASSERT_TRUE(cv::imwrite(tmp.str("whole.png"), cv::Mat(64, 64, CV_8UC3, cv::Scalar(9, 9, 9))));
  const std::string bytes = arwb::test::read_file(tmp.str("whole.png"));
  write_file(tmp.str("cut.png"), bytes.substr(0, bytes.size() / 2));
  write_file(tmp.str("text.png"), "hello\n");
  MediaStore store(StoreMode::offline);
  for (const char* name : {"cut.png", "text.png", "missing.png"}) {
    std::string error;
    EXPECT_FALSE(store.image(tmp.str(name), &error)) << name;
    EXPECT_EQ(error.rfind(tmp.str(name) + ": ", 0), 0u) << error;
  }
}

TEST(Image, ReleasedImagesAreDecodedAgain) {
  TempDir tmp;
  ASSERT_TRUE(cv::imwrite(tmp.str("a.png"), cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3))));
  MediaStore store(StoreMode::offline);
  std::string error;
  auto a = store.image(tmp.str("a.png"), &error);
  const uint64_t first = version_of(*a);
  a.reset();
  store.trim();
  a = store.image(tmp.str("a.png"), &error);
  ASSERT_TRUE(a) << error;
  EXPECT_NE(version_of(*a), first);  // a new decoding, so a new version for the texture
}

// ---- Videos: offline -----------------------------------------------------------------------------------------

TEST_P(Video, ReportsSizeRateAndDuration) {
  MediaStore store(StoreMode::offline);
  auto v = open(store, false);
  ASSERT_TRUE(v);
  EXPECT_EQ(v->size(), cv::Size(kVideoW, kVideoH));
  EXPECT_DOUBLE_EQ(v->fps(), kFps);
  EXPECT_NEAR(v->duration_s(), kFrames / kFps, 1e-9);
  // The first frame is there from the start.
  uint64_t version = 0;
  auto first = v->current(&version);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->type(), CV_8UC3);
  EXPECT_EQ(first->size(), v->size());
  EXPECT_EQ(frame_index(*first), 0);
  EXPECT_GT(version, 0u);
  EXPECT_EQ(v->frames_decoded(), 1u);
  EXPECT_EQ(v->error(), "");
  // Another player of the same file: the same first picture, but a version of its own.
  auto other = open(store, false);
  ASSERT_TRUE(other);
  EXPECT_NE(version_of(*other), version);
}

TEST_P(Video, OfflineShowsTheFrameAtTheClockForwardsAndBackwards) {
  MediaStore store(StoreMode::offline);
  auto v = open(store, false);
  ASSERT_TRUE(v);
  uint64_t last_version = version_of(*v);
  for (const int k : {1, 2, 5, 12, 29, 3, 0, 17, 16, 28, 9}) {
    v->set_clock(k / kFps, true);  // offline: `playing` does not make the picture move on by itself
    uint64_t version = 0;
    auto frame = v->current(&version);
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame_index(*frame), k) << "set_clock(" << k / kFps << ")";
    EXPECT_GT(version, last_version) << "a new picture has a new version";
    last_version = version;
  }
  // Asking again for the frame shown decodes nothing.
  const uint64_t decoded = v->frames_decoded();
  v->set_clock(9 / kFps + 0.04, false);
  EXPECT_EQ(v->frames_decoded(), decoded);
  EXPECT_EQ(version_of(*v), last_version);
  EXPECT_EQ(v->error(), "");
}

TEST_P(Video, OfflineWithoutLoopHoldsTheLastFrame) {
  MediaStore store(StoreMode::offline);
  auto v = open(store, false);
  ASSERT_TRUE(v);
  for (const double t : {2.95, 3.0, 3.5, 100.0, 1e12}) {
    v->set_clock(t, true);
    EXPECT_EQ(shown_index(*v), kFrames - 1) << t;
  }
  v->set_clock(-1, false);  // before the start: the first frame
  EXPECT_EQ(shown_index(*v), 0);
}

TEST_P(Video, OfflineLoopWrapsAround) {
  MediaStore store(StoreMode::offline);
  auto v = open(store, true);
  ASSERT_TRUE(v);
  v->set_clock(2.9, false);
  EXPECT_EQ(shown_index(*v), 29);
  v->set_clock(3.0, false);
  EXPECT_EQ(shown_index(*v), 0);
  v->set_clock(3.5, false);
  EXPECT_EQ(shown_index(*v), 5);
  v->set_clock(6.2, false);
  EXPECT_EQ(shown_index(*v), 2);
  v->set_clock(10 * 3.0 + 1.7, false);
  EXPECT_EQ(shown_index(*v), 17);
}

TEST_P(Video, OfflineIsTheSameEveryTime) {
  MediaStore store(StoreMode::offline);
  auto a = open(store, true), b = open(store, true);
  ASSERT_TRUE(a && b);
  for (const double t : {0.0, 0.7, 2.2, 0.4, 4.1}) {
    a->set_clock(t, true);
    b->set_clock(t, true);
    auto fa = a->current(nullptr), fb = b->current(nullptr);
    EXPECT_EQ(cv::norm(*fa, *fb, cv::NORM_INF), 0) << t;
  }
}

// ---- Videos: live --------------------------------------------------------------------------------------------

TEST_P(Video, LiveAdvancesWhilePlayingAndStopsWhenPaused) {
  MediaStore store(StoreMode::live);
  auto v = open(store, true);
  ASSERT_TRUE(v);
  const uint64_t start = version_of(*v);
  v->set_clock(0, true);
  EXPECT_TRUE(eventually([&] { return version_of(*v) >= start + 3; })) << "the picture does not advance";

  v->set_clock(1.2, false);
  EXPECT_TRUE(eventually([&] { return shown_index(*v) == 12; })) << "paused at 1.2 s shows frame 12";
  // Paused: once any decode in flight is done, nothing more is decoded.
  uint64_t settled = 0;
  EXPECT_TRUE(eventually([&] {
    const uint64_t before = v->frames_decoded();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    settled = v->frames_decoded();
    return settled == before;
  }));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(v->frames_decoded(), settled);
  EXPECT_EQ(shown_index(*v), 12);

  v->set_clock(0.3, false);  // backwards
  EXPECT_TRUE(eventually([&] { return shown_index(*v) == 3; }));
  EXPECT_EQ(v->error(), "");
}

TEST_P(Video, LiveWaitsForAClockSlightlyBehindInsteadOfSeekingBack) {
  MediaStore store(StoreMode::live);
  auto v = open(store, false);
  ASSERT_TRUE(v);
  v->set_clock(1.0, false);
  ASSERT_TRUE(eventually([&] { return shown_index(*v) == 10; }));
  ASSERT_TRUE(eventually([&] {
    const uint64_t before = v->frames_decoded();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    return v->frames_decoded() == before;
  }));
  const uint64_t decoded = v->frames_decoded();
  // The scene's clock comes back half a frame behind the picture, playing: frame 10 stays until 11 is due.
  v->set_clock(0.95, true);
  int index = -1;
  uint64_t spent = 0;
  ASSERT_TRUE(eventually([&] {
    index = shown_index(*v);   // read first: the count below already includes this frame
    spent = v->frames_decoded() - decoded;
    EXPECT_NE(index, 9) << "sought back to frame 9";
    return index >= 12;
  }));
  // Frames 11..index were decoded, plus at most one in flight; a seek back would have cost 9 and 10 again.
  EXPECT_LE(spent, static_cast<uint64_t>(index - 10 + 1));
}

TEST_P(Video, LiveLoopWrapsAndNonLoopHoldsTheLastFrame) {
  MediaStore store(StoreMode::live);
  auto looping = open(store, true), once = open(store, false);
  ASSERT_TRUE(looping && once);
  looping->set_clock(2.8, true);
  once->set_clock(2.8, true);
  EXPECT_TRUE(eventually([&] { return shown_index(*looping) >= 27; }));
  EXPECT_TRUE(eventually([&] {
    const int i = shown_index(*looping);
    return i >= 0 && i < 20;
  })) << "the looping video starts again";
  EXPECT_TRUE(eventually([&] { return shown_index(*once) == kFrames - 1; }));
  // Past the end it holds: no more decoding although the clock runs on.
  uint64_t settled = 0;
  EXPECT_TRUE(eventually([&] {
    const uint64_t before = once->frames_decoded();
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    settled = once->frames_decoded();
    return settled == before;
  }));
  EXPECT_EQ(shown_index(*once), kFrames - 1);
  EXPECT_EQ(once->error(), "");
}

TEST_P(Video, LivePlayersStopWhenReleasedWhilePlaying) {
  // Would hang (and time out) if the player's thread did not stop.
  MediaStore store(StoreMode::live);
  for (int i = 0; i < 5; ++i) {
    auto v = open(store, true);
    ASSERT_TRUE(v);
    v->set_clock(0.1 * i, true);
    std::this_thread::sleep_for(std::chrono::milliseconds(20 * i));
  }
}

// ---- Videos: faults ------------------------------------------------------------------------------------------

TEST(VideoFaults, RefusesWhatIsNotAVideo) {
  TempDir tmp;
  write_file(tmp.str("text.mp4"), "not a video at all\n");
  ASSERT_TRUE(cv::imwrite(tmp.str("still.png"), cv::Mat(8, 8, CV_8UC3, cv::Scalar::all(0))));
  MediaStore store(StoreMode::offline);
  for (const char* name : {"text.mp4", "missing.mp4"}) {
    std::string error;
    EXPECT_FALSE(store.video(tmp.str(name), false, &error)) << name;
    EXPECT_EQ(error.rfind(tmp.str(name) + ": ", 0), 0u) << error;
  }
}

TEST(VideoFaults, TruncatedVideoHoldsItsLastGoodFrameAndSaysWhy) {
  TempDir tmp;
  write_index_video(tmp.str("whole.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 40, 10);
  const std::string bytes = arwb::test::read_file(tmp.str("whole.avi"));
  write_file(tmp.str("cut.avi"), bytes.substr(0, bytes.size() / 2));
  MediaStore store(StoreMode::offline);
  std::string error;
  auto v = store.video(tmp.str("cut.avi"), false, &error);
  ASSERT_TRUE(v) << error;
  v->set_clock(3.9, false);
  const int held = shown_index(*v);
  EXPECT_GT(held, 5);
  EXPECT_LT(held, 39);
  // The container promised 40 frames: the shortfall is reported, and the duration is what could be decoded.
  EXPECT_NE(v->error().find(tmp.str("cut.avi") + ": cannot decode frame "), std::string::npos) << v->error();
  EXPECT_NE(v->error().find("damaged or truncated"), std::string::npos) << v->error();
  EXPECT_LT(v->duration_s(), 3.9);
  EXPECT_GE(v->duration_s() * 10, held);
  // Asking again holds the same picture; going back still works.
  const uint64_t version = version_of(*v);
  v->set_clock(3.9, false);
  EXPECT_EQ(version_of(*v), version);
  v->set_clock(0.2, false);
  EXPECT_EQ(shown_index(*v), 2);
}

TEST(VideoFaults, TruncatedVideoEndsWhereTheVideoSourceEnds) {
  // The store's players and the workbench's video source read through capture's one VideoReader: a cut file
  // ends at the same frame in both, with the same message.
  TempDir tmp;
  write_index_video(tmp.str("whole.avi"), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 40, 10);
  const std::string bytes = arwb::test::read_file(tmp.str("whole.avi"));
  const std::string cut = tmp.str("cut.avi");
  write_file(cut, bytes.substr(0, bytes.size() / 2));

  MediaStore store(StoreMode::offline);
  std::string error;
  auto v = store.video(cut, false, &error);
  ASSERT_TRUE(v) << error;
  v->set_clock(3.9, false);

  arwb::SourceSpec spec;
  ASSERT_TRUE(arwb::parse_source_spec(cut, &spec, &error)) << error;
  auto src = arwb::open_capture_source(spec, &error);
  ASSERT_TRUE(src) << error;
  arwb::Playback pb;
  pb.loop = false;
  src->set_playback(pb);
  cv::Mat f;
  int last = -1;
  std::string message;
  arwb::SourceStatus s;
  for (int i = 0; i < 100 && s.status != arwb::FrameStatus::end; ++i) {
    s = src->next(i * 0.1, f);  // one frame a call at the video's 10 fps
    ASSERT_NE(s.status, arwb::FrameStatus::gone) << s.message;
    if (s.status == arwb::FrameStatus::ok) last = frame_index(f);
    if (s.status == arwb::FrameStatus::error) message = s.message;
  }
  EXPECT_EQ(s.status, arwb::FrameStatus::end);
  EXPECT_EQ(last, shown_index(*v));
  EXPECT_EQ(message, v->error());
  EXPECT_NE(message, "");
  EXPECT_DOUBLE_EQ(src->info().count / 10.0, v->duration_s());
}

// ---- Cards ---------------------------------------------------------------------------------------------------

namespace {

MediaSpec text_spec(const std::string& text, double font_px = 32) {
  MediaSpec s;
  s.kind = arwb::MediaKind::text;
  s.text = text;
  s.font_px = font_px;
  return s;
}

cv::Mat pixels_of(const std::shared_ptr<MediaContent>& c) {
  auto m = c->current(nullptr);
  EXPECT_TRUE(m);
  return m ? *m : cv::Mat();
}

}  // namespace

TEST(TextCard, GrowsWithTextLinesAndFontSize) {
  MediaStore store(StoreMode::offline);
  const cv::Size short_text = store.text_card(text_spec("ID 7"))->size();
  const cv::Size long_text = store.text_card(text_spec("ID 7 and a much longer caption"))->size();
  const cv::Size two_lines = store.text_card(text_spec("ID 7\nID 7"))->size();
  const cv::Size big_font = store.text_card(text_spec("ID 7", 64))->size();
  EXPECT_GT(long_text.width, short_text.width);
  EXPECT_EQ(long_text.height, short_text.height);
  EXPECT_GT(two_lines.height, short_text.height);
  EXPECT_EQ(two_lines.width, short_text.width);
  EXPECT_GT(big_font.width, short_text.width);
  EXPECT_GT(big_font.height, short_text.height);
  EXPECT_GT(short_text.height, 32);  // at least a line of 32 px glyphs
  const cv::Mat m = pixels_of(store.text_card(text_spec("ID 7")));
  EXPECT_EQ(m.type(), CV_8UC4);
  EXPECT_EQ(m.size(), short_text);
}

TEST(TextCard, DrawsTextOnTheBackgroundWithStraightAlpha) {
  MediaStore store(StoreMode::offline);
  MediaSpec spec = text_spec("Hello");
  spec.colour = cv::Scalar(255, 255, 255, 255);
  spec.background = cv::Scalar(40, 60, 80, 200);
  const cv::Mat m = pixels_of(store.text_card(spec));
  // The padding's middle is plain background, un-premultiplied: its colour (within cairo's 8-bit rounding of
  // the premultiplied value), not 200/255 of it as premultiplied pixels would be.
  const cv::Vec4b pad = m.at<cv::Vec4b>(2, m.cols / 2);
  EXPECT_EQ(pad[3], 200);
  EXPECT_LE(cv::norm(cv::Vec3d(pad[0], pad[1], pad[2]) - cv::Vec3d(40, 60, 80), cv::NORM_INF), 1) << pad;
  // The glyphs are there, opaque white.
  int white = 0;
  for (auto it = m.begin<cv::Vec4b>(); it != m.end<cv::Vec4b>(); ++it) white += *it == cv::Vec4b(255, 255, 255, 255);
  EXPECT_GT(white, 20);
}

TEST(TextCard, AntialiasedEdgesKeepTheirColourOnATransparentCard) {
  MediaStore store(StoreMode::offline);
  MediaSpec spec = text_spec("Wavy @ text", 40);
  spec.colour = cv::Scalar(0, 0, 255, 255);  // red
  spec.background = cv::Scalar(0, 0, 0, 0);
  const cv::Mat m = pixels_of(store.text_card(spec));
  int partial = 0;
  for (auto it = m.begin<cv::Vec4b>(); it != m.end<cv::Vec4b>(); ++it) {
    const cv::Vec4b p = *it;
    if (p[3] == 0) continue;
    if (p[3] < 255) ++partial;
    // Premultiplied edges would be dark red; straight alpha keeps them red. Faint pixels round coarsely.
    if (p[3] >= 32) {
      EXPECT_GE(p[2], 240) << "alpha " << int(p[3]);
      EXPECT_LE(p[0], 8);
      EXPECT_LE(p[1], 8);
    }
  }
  EXPECT_GT(partial, 10) << "expected antialiased edges";
}

TEST(TextCard, EmptyTextIsASmallCardOfBackgroundOnly) {
  MediaStore store(StoreMode::offline);
  MediaSpec spec = text_spec("");
  spec.background = cv::Scalar(40, 40, 40, 200);
  const cv::Mat m = pixels_of(store.text_card(spec));
  ASSERT_FALSE(m.empty());
  EXPECT_LT(m.cols, 100);
  EXPECT_GT(m.rows, 0);
  int background = 0;
  for (auto it = m.begin<cv::Vec4b>(); it != m.end<cv::Vec4b>(); ++it) {
    const cv::Vec4b p = *it;
    // Nothing but background: the same colour wherever there is enough alpha to tell (faint corner pixels
    // lose their colour to rounding).
    if (p[3] >= 64) {
      const int tolerance = (255 + p[3] - 1) / p[3];  // one step of the premultiplied value
      for (int c = 0; c < 3; ++c) EXPECT_LE(std::abs(p[c] - 40), tolerance) << p;
    }
    background += p[3] == 200;
  }
  EXPECT_GT(background, 0);
}

TEST(TextCard, HugeTextIsCutToTheLimits) {
  MediaStore store(StoreMode::offline);
  const auto wide = store.text_card(text_spec(std::string(100000, 'W'), 64));
  EXPECT_LE(wide->size().width, MediaStore::kMaxCardSide);
  EXPECT_GT(wide->size().width, MediaStore::kMaxCardSide / 2);
  std::string many_lines;
  for (int i = 0; i < 3000; ++i) many_lines += "line\n";
  const auto tall = store.text_card(text_spec(many_lines, 64));
  EXPECT_LE(tall->size().height, MediaStore::kMaxCardSide);
  EXPECT_GT(tall->size().height, MediaStore::kMaxCardSide / 2);
  const auto giant = store.text_card(text_spec("x", 1e9));
  EXPECT_LE(giant->size().width, MediaStore::kMaxCardSide);
  EXPECT_LE(giant->size().height, MediaStore::kMaxCardSide);
  const auto nan = store.text_card(text_spec("x", std::nan("")));
  EXPECT_GT(nan->size().area(), 0);
}

TEST(TextCard, InvalidUtf8AndControlCharactersStillDraw) {
  MediaStore store(StoreMode::offline);
  const cv::Size empty = store.text_card(text_spec(""))->size();
  const cv::Size bad = store.text_card(text_spec("\xff\xfe\xc0\x80 abc \x01\x1b[31m"))->size();
  // Cairo stops at invalid UTF-8; the replacement characters and "abc" must have been drawn.
  EXPECT_GT(bad.width, empty.width + 40);
  const cv::Size accented = store.text_card(text_spec("Caf\xc3\xa9 \xe2\x9c\x93"))->size();
  EXPECT_GT(accented.width, empty.width + 40);
}

TEST(TextCard, CachedByTextAndStyle) {
  MediaStore store(StoreMode::offline);
  MediaSpec spec = text_spec("ID 7");
  auto a = store.text_card(spec);
  EXPECT_EQ(store.text_card(spec), a);
  MediaSpec other_colour = spec;
  other_colour.colour = cv::Scalar(0, 255, 0, 255);
  auto b = store.text_card(other_colour);
  EXPECT_NE(b, a);
  EXPECT_NE(version_of(*b), version_of(*a));
  EXPECT_GT(cv::norm(pixels_of(a), pixels_of(b), cv::NORM_INF), 0);
  MediaSpec other_font = spec;
  other_font.font_px = 33;
  EXPECT_NE(store.text_card(other_font), a);
}

TEST(TextCard, TrimForgetsCardsNoOneHolds) {
  MediaStore store(StoreMode::offline);
  auto held = store.text_card(text_spec("held"));
  auto dropped = store.text_card(text_spec("dropped"));
  const uint64_t held_version = version_of(*held), dropped_version = version_of(*dropped);
  dropped.reset();
  // Still cached without a holder, until trim.
  EXPECT_EQ(version_of(*store.text_card(text_spec("dropped"))), dropped_version);
  store.trim();
  EXPECT_NE(version_of(*store.text_card(text_spec("dropped"))), dropped_version);
  EXPECT_EQ(store.text_card(text_spec("held")), held);
  EXPECT_EQ(version_of(*held), held_version);
}

TEST(TextCard, CacheDropsTheLeastRecentlyAskedForPastItsLimit) {
  MediaStore store(StoreMode::offline);
  const uint64_t old_version = version_of(*store.text_card(text_spec("old")));
  const uint64_t busy_version = version_of(*store.text_card(text_spec("busy")));
  auto held = store.text_card(text_spec("held"));
  for (size_t i = 0; i < MediaStore::kMaxCards + 10; ++i) {
    (void)store.text_card(text_spec("counter " + std::to_string(i)));
    (void)store.text_card(text_spec("busy"));  // asked for every frame
  }
  EXPECT_NE(version_of(*store.text_card(text_spec("old"))), old_version) << "the oldest card was not dropped";
  EXPECT_EQ(version_of(*store.text_card(text_spec("busy"))), busy_version) << "a card in use was dropped";
  EXPECT_EQ(store.text_card(text_spec("held")), held);
}

TEST(WebCard, ShowsTheHostWhenThereIsNoTitle) {
  MediaStore store(StoreMode::offline);
  MediaSpec spec;
  spec.kind = arwb::MediaKind::web;
  spec.url = "https://opencv.org/releases";
  const cv::Mat untitled = pixels_of(store.web_card(spec));
  EXPECT_EQ(untitled.type(), CV_8UC4);
  EXPECT_EQ(untitled.size(), cv::Size(MediaStore::kWebCardWidth, MediaStore::kWebCardHeight));
  MediaSpec titled = spec;
  titled.title = "opencv.org";
  EXPECT_EQ(cv::norm(untitled, pixels_of(store.web_card(titled)), cv::NORM_INF), 0);
  titled.title = "OpenCV releases";
  EXPECT_GT(cv::norm(untitled, pixels_of(store.web_card(titled)), cv::NORM_INF), 0);
}

TEST(WebCard, LongUrlsKeepTheCardSize) {
  MediaStore store(StoreMode::offline);
  MediaSpec spec;
  spec.kind = arwb::MediaKind::web;
  spec.url = "https://example.com/" + std::string(2000, 'a');
  spec.title = std::string(500, 'T');
  const auto card = store.web_card(spec);
  EXPECT_EQ(card->size(), cv::Size(MediaStore::kWebCardWidth, MediaStore::kWebCardHeight));
  EXPECT_EQ(store.web_card(spec), card);
}
