// Tests for capture/source and synth's synthetic source: source specs, the five kinds of source, playback in time.
// Videos are written here with cv::VideoWriter, each frame a flat grey whose level tells its index.
#include "capture/image_io.hpp"
#include "synth/synthetic_source.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace arwb {
namespace {

using test::TempDir;
using test::write_file;

constexpr int kLevelStep = 20;

// Frame i of a test video: grey 10 + 20 i, with a small white square so it is not perfectly flat.
cv::Mat video_frame(int i) {
  cv::Mat m(120, 160, CV_8UC3, cv::Scalar::all(10 + kLevelStep * i));
  cv::rectangle(m, cv::Rect(4, 4, 8, 8), cv::Scalar::all(255), -1);
  return m;
}

int frame_index(const cv::Mat& m) {
  const double level = cv::mean(m(cv::Rect(40, 40, 80, 60)))[0];
  return int(std::lround((level - 10) / kLevelStep));
}

// Writes `frames` frames at `fps`; false when this OpenCV build cannot write the codec.
bool write_video(const std::string& path, const char (&fourcc)[5], int frames, double fps) {
  cv::VideoWriter w(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]), fps,
                    cv::Size(160, 120));
  if (!w.isOpened()) return false;
  for (int i = 0; i < frames; ++i) w.write(video_frame(i));
  return true;
}

std::string png(const cv::Mat& m) {
  std::vector<uchar> buf;
  cv::imencode(".png", m, buf);
  return std::string(buf.begin(), buf.end());
}

std::unique_ptr<FrameSource> open(const std::string& text, std::string* error = nullptr) {
  SourceSpec spec;
  std::string err;
  if (!parse_source_spec(text, &spec, &err)) {
    ADD_FAILURE() << "parse " << text << ": " << err;
    return nullptr;
  }
  auto src = open_source(spec, &err);
  if (error) *error = err;
  return src;
}

// [SECTION] specs

TEST(SourceSpec, ParsesSyntheticAndCameras) {
  SourceSpec s;
  std::string err;
  ASSERT_TRUE(parse_source_spec("synthetic", &s, &err)) << err;
  EXPECT_EQ(s.kind, SourceKind::synthetic);
  EXPECT_EQ(s.text(), "synthetic");

  ASSERT_TRUE(parse_source_spec("camera:2", &s, &err)) << err;
  EXPECT_EQ(s.kind, SourceKind::camera);
  EXPECT_EQ(s.device, 2);
  EXPECT_EQ(s.resolution, cv::Size());
  EXPECT_EQ(s.text(), "camera:2");

  ASSERT_TRUE(parse_source_spec("camera:0@1280x720", &s, &err)) << err;
  EXPECT_EQ(s.device, 0);
  EXPECT_EQ(s.resolution, cv::Size(1280, 720));
  EXPECT_EQ(s.text(), "camera:0@1280x720");
  SourceSpec again;
  ASSERT_TRUE(parse_source_spec(s.text(), &again, &err));
  EXPECT_EQ(again.text(), s.text());
}

TEST(SourceSpec, RejectsBadCamerasAndMissingPaths) {
  for (const std::string bad : {"camera:x", "camera:", "camera:-1", "camera:1x", "camera:0@12x", "camera:0@axb",
                                "camera:0@0x480"}) {
    SourceSpec s;
    std::string err;
    EXPECT_FALSE(parse_source_spec(bad, &s, &err)) << bad;
    EXPECT_NE(err.find(bad), std::string::npos) << err;
    EXPECT_EQ(err.find('\n'), std::string::npos) << "one line";
  }
  TempDir dir;
  const std::string missing = dir.str("nothing_here.mp4");
  std::string err;
  SourceSpec s;
  EXPECT_FALSE(parse_source_spec(missing, &s, &err));
  EXPECT_NE(err.find(missing), std::string::npos) << err;
  EXPECT_FALSE(parse_source_spec("", &s, &err));
  EXPECT_FALSE(err.empty());
  // A file that is neither image nor video, whatever its name says.
  write_file(dir.str("notes.png"), "just some text, not an image at all\n");
  EXPECT_FALSE(parse_source_spec(dir.str("notes.png"), &s, &err));
  EXPECT_NE(err.find("notes.png"), std::string::npos) << err;
  // Null out-pointers are allowed.
  EXPECT_FALSE(parse_source_spec("camera:x", nullptr, nullptr));
  EXPECT_TRUE(parse_source_spec("synthetic", nullptr, nullptr));
}

TEST(SourceSpec, PathKindComesFromContent) {
  TempDir dir;
  write_file(dir.str("picture.dat"), png(cv::Mat(8, 8, CV_8UC3, cv::Scalar(1, 2, 3))));
  ASSERT_TRUE(write_video(dir.str("clip.avi"), "MJPG", 3, 10));
  SourceSpec s;
  std::string err;
  ASSERT_TRUE(parse_source_spec(dir.str("picture.dat"), &s, &err)) << err;
  EXPECT_EQ(s.kind, SourceKind::image);
  EXPECT_EQ(s.text(), dir.str("picture.dat"));
  ASSERT_TRUE(parse_source_spec(dir.str("clip.avi"), &s, &err)) << err;
  EXPECT_EQ(s.kind, SourceKind::video);
  ASSERT_TRUE(parse_source_spec(dir.str(), &s, &err)) << err;
  EXPECT_EQ(s.kind, SourceKind::folder);
  EXPECT_EQ(s.text(), dir.str());
}

TEST(SourceSpec, KindNames) {
  EXPECT_EQ(source_kind_name(SourceKind::synthetic), "synthetic");
  EXPECT_EQ(source_kind_name(SourceKind::camera), "camera");
  EXPECT_EQ(source_kind_name(SourceKind::video), "video");
  EXPECT_EQ(source_kind_name(SourceKind::image), "image");
  EXPECT_EQ(source_kind_name(SourceKind::folder), "folder");
}

// [SECTION] synthetic

TEST(SourceSynthetic, AnimatesWithSpeedAndHoldsWhenStill) {
  auto src = open("synthetic");
  ASSERT_TRUE(src);
  auto* syn = dynamic_cast<SyntheticSource*>(src.get());
  ASSERT_NE(syn, nullptr);
  EXPECT_EQ(src->info().kind, SourceKind::synthetic);
  EXPECT_EQ(src->info().name, "synthetic");
  cv::Mat a, b, c;
  EXPECT_EQ(src->next(10.0, a).status, FrameStatus::ok);
  EXPECT_EQ(a.size(), cv::Size(640, 480));
  EXPECT_EQ(a.type(), CV_8UC3);
  EXPECT_EQ(src->next(10.5, b).status, FrameStatus::ok);
  EXPECT_GT(cv::norm(a, b, cv::NORM_INF), 0);
  EXPECT_NEAR(syn->world().controls().time_s, 0.5, 1e-9) << "the synthetic clock starts at the first call";

  syn->world().controls().speed = 2;
  src->next(11.0, c);
  EXPECT_NEAR(syn->world().controls().time_s, 1.5, 1e-9);

  // Still: the world holds where it was, whatever the caller's clock does.
  syn->world().controls().animate = false;
  src->next(20.0, a);
  src->next(30.0, b);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(a, c, cv::NORM_INF), 0);
  // Resuming continues from the held time.
  syn->world().controls().animate = true;
  src->next(31.0, a);
  EXPECT_NEAR(syn->world().controls().time_s, 3.5, 1e-9);
}

// A frame step: the world moves on the same per frame whatever the caller's clock says (a slow machine's frames
// are as far apart in the world as a fast one's), times the speed slider; no step follows the clock again.
TEST(SourceSynthetic, AFrameStepMovesTheWorldPerFrameWhateverTheClock) {
  SyntheticSource src;
  src.set_frame_step(0.25);
  EXPECT_EQ(src.frame_step(), 0.25);
  cv::Mat a, b;
  src.next(10.0, a);
  EXPECT_NEAR(src.world().controls().time_s, 0.0, 1e-9) << "the first frame is at the clock's start";
  src.next(10.0, a);   // no time at all between the calls
  EXPECT_NEAR(src.world().controls().time_s, 0.25, 1e-9);
  src.next(500.0, a);  // a long stall
  EXPECT_NEAR(src.world().controls().time_s, 0.5, 1e-9);
  EXPECT_EQ(cv::norm(a, src.world().render(0.5).image, cv::NORM_INF), 0) << "the world at the stepped time";
  src.world().controls().speed = 2;
  src.next(500.1, b);
  EXPECT_NEAR(src.world().controls().time_s, 1.0, 1e-9);
  src.set_frame_step(std::nan(""));
  EXPECT_EQ(src.frame_step(), 0.0);
  src.set_frame_step(-1);
  EXPECT_EQ(src.frame_step(), 0.0);
  src.next(501.1, b);
  EXPECT_NEAR(src.world().controls().time_s, 3.0, 1e-9) << "back on the caller's clock";
}

// [SECTION] video

class SourceVideo : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = dir_.str("clip.avi");
    ASSERT_TRUE(write_video(path_, "MJPG", 10, 10));
  }
  TempDir dir_;
  std::string path_;
};

TEST_F(SourceVideo, PlaysInTimeAndSkipsFrames) {
  std::string err;
  auto src = open(path_, &err);
  ASSERT_TRUE(src) << err;
  const SourceInfo info = src->info();
  EXPECT_EQ(info.kind, SourceKind::video);
  EXPECT_EQ(info.name, "clip.avi");
  EXPECT_EQ(info.size, cv::Size(160, 120));
  EXPECT_NEAR(info.native_fps, 10, 0.01);
  EXPECT_EQ(info.count, 10);
  cv::Mat f;
  ASSERT_EQ(src->next(100.0, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 0);
  EXPECT_EQ(src->next(100.05, f).status, FrameStatus::same);
  ASSERT_EQ(src->next(100.1, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 1);
  // A slow caller: 0.25 s later the video is 2.5 frames on; frames 2 is skipped.
  ASSERT_EQ(src->next(100.35, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 3);
  EXPECT_EQ(src->info().position, 3);
  // Twice the speed.
  Playback pb;
  pb.speed = 2;
  src->set_playback(pb);
  ASSERT_EQ(src->next(100.45, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 5);
}

TEST_F(SourceVideo, PausesStepsAndSeeks) {
  auto src = open(path_);
  ASSERT_TRUE(src);
  cv::Mat f;
  ASSERT_EQ(src->next(0, f).status, FrameStatus::ok);
  Playback pb;
  pb.playing = false;
  src->set_playback(pb);
  EXPECT_EQ(src->next(5, f).status, FrameStatus::same);
  EXPECT_EQ(frame_index(f), 0) << "the previous frame stands";

  src->step(+1);
  ASSERT_EQ(src->next(5.1, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 1);
  src->step(+1);
  src->step(+1);
  ASSERT_EQ(src->next(5.2, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 3);
  src->step(-1);
  ASSERT_EQ(src->next(5.3, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 2);
  EXPECT_EQ(src->next(9, f).status, FrameStatus::same);

  src->seek(7);
  ASSERT_EQ(src->next(9.1, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 7);
  EXPECT_EQ(src->info().position, 7);
  src->seek(1);
  ASSERT_EQ(src->next(9.2, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 1);

  // Stepping pauses a playing video.
  pb.playing = true;
  src->set_playback(pb);
  src->step(+1);
  ASSERT_EQ(src->next(9.3, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 2);
  EXPECT_EQ(src->next(20, f).status, FrameStatus::same);
}

TEST_F(SourceVideo, LoopsOrEnds) {
  auto src = open(path_);
  ASSERT_TRUE(src);
  cv::Mat f;
  double now = 0;
  ASSERT_EQ(src->next(now, f).status, FrameStatus::ok);
  // Looping (the default): play 2.5 s of a 1 s video; it wraps and frame 0 comes again.
  int wraps = 0, last = 0;
  for (int i = 0; i < 50; ++i) {
    now += 0.05;
    const SourceStatus s = src->next(now, f);
    ASSERT_TRUE(s.status == FrameStatus::ok || s.status == FrameStatus::same) << s.message;
    if (s.status == FrameStatus::ok) {
      const int idx = frame_index(f);
      if (idx < last) ++wraps;
      last = idx;
    }
  }
  EXPECT_EQ(wraps, 2);

  Playback pb;
  pb.loop = false;
  src->set_playback(pb);
  int ends = 0;
  for (int i = 0; i < 40; ++i) {
    now += 0.05;
    const SourceStatus s = src->next(now, f);
    ASSERT_NE(s.status, FrameStatus::error) << s.message;
    ASSERT_NE(s.status, FrameStatus::gone) << s.message;
    if (s.status == FrameStatus::end) ++ends;
    else if (ends) ADD_FAILURE() << "a frame after the end";
  }
  EXPECT_GT(ends, 10) << "the end stays the end";
  EXPECT_EQ(frame_index(f), 9);
  // A seek brings it back.
  src->seek(4);
  ASSERT_EQ(src->next(now + 0.01, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 4);
}

TEST_F(SourceVideo, Mp4AlsoPlays) {
  const std::string mp4 = dir_.str("clip.mp4");
  if (!write_video(mp4, "mp4v", 12, 24)) GTEST_SKIP() << "no mp4v writer in this OpenCV";
  std::string err;
  auto src = open(mp4, &err);
  ASSERT_TRUE(src) << err;
  EXPECT_EQ(src->info().kind, SourceKind::video);
  cv::Mat f;
  ASSERT_EQ(src->next(0, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 0);
  src->seek(9);
  ASSERT_EQ(src->next(0, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 9);
  src->step(-1);
  ASSERT_EQ(src->next(0, f).status, FrameStatus::ok);
  EXPECT_EQ(frame_index(f), 8);
}

TEST_F(SourceVideo, UnreadableOrTruncatedVideos) {
  // The right magic, then garbage: classified as a video, but no frame can be read.
  const std::string bad = dir_.str("broken.avi");
  write_file(bad, std::string("RIFF\x10\x00\x00\x00" "AVI LIST", 16) + std::string(4000, '\x5a'));
  SourceSpec spec;
  std::string err;
  ASSERT_TRUE(parse_source_spec(bad, &spec, &err)) << err;
  ASSERT_EQ(spec.kind, SourceKind::video);
  EXPECT_EQ(open_source(spec, &err), nullptr);
  EXPECT_NE(err.find("broken.avi"), std::string::npos) << err;

  // Cut a longer video in half: it plays what is there and then ends, saying where when it can tell.
  const std::string longer = dir_.str("long.avi");
  ASSERT_TRUE(write_video(longer, "MJPG", 40, 10));
  const std::string cut = dir_.str("cut.avi");
  const std::string bytes = test::read_file(longer);
  write_file(cut, bytes.substr(0, bytes.size() / 2));
  auto src = open(cut, &err);
  ASSERT_TRUE(src) << err;
  Playback pb;
  pb.loop = false;
  src->set_playback(pb);
  cv::Mat f;
  int frames = 0;
  SourceStatus s;
  for (int i = 0; i < 100 && s.status != FrameStatus::end; ++i) {
    s = src->next(i * 0.1, f);
    if (s.status == FrameStatus::ok) ++frames;
    if (s.status == FrameStatus::error) {
      EXPECT_NE(s.message.find("cut.avi"), std::string::npos) << s.message;
      EXPECT_NE(s.message.find("frame"), std::string::npos) << s.message;
    }
    ASSERT_NE(s.status, FrameStatus::gone);
  }
  EXPECT_EQ(s.status, FrameStatus::end);
  EXPECT_GT(frames, 5);
  EXPECT_LT(frames, 30);
}

// [SECTION] image and folder

TEST(SourceImage, FirstCallOkThenSame) {
  TempDir dir;
  write_file(dir.str("one.png"), png(cv::Mat(30, 40, CV_8UC1, cv::Scalar(77))));
  std::string err;
  auto src = open(dir.str("one.png"), &err);
  ASSERT_TRUE(src) << err;
  EXPECT_EQ(src->info().kind, SourceKind::image);
  EXPECT_EQ(src->info().name, "one.png");
  EXPECT_EQ(src->info().size, cv::Size(40, 30));
  cv::Mat f;
  ASSERT_EQ(src->next(0, f).status, FrameStatus::ok);
  EXPECT_EQ(f.type(), CV_8UC3) << "grey images come as BGR";
  EXPECT_EQ(f.at<cv::Vec3b>(5, 5), cv::Vec3b(77, 77, 77));
  for (int i = 1; i < 5; ++i) EXPECT_EQ(src->next(i, f).status, FrameStatus::same);
  src->step(1);
  src->seek(3);
  EXPECT_EQ(src->next(9, f).status, FrameStatus::same);
}

TEST(SourceImage, CorruptImageFailsToOpen) {
  TempDir dir;
  const std::string bytes = png(cv::Mat(64, 64, CV_8UC3, cv::Scalar(1, 2, 3)));
  write_file(dir.str("half.png"), bytes.substr(0, bytes.size() / 2));
  SourceSpec spec;
  std::string err;
  ASSERT_TRUE(parse_source_spec(dir.str("half.png"), &spec, &err)) << err;
  EXPECT_EQ(open_source(spec, &err), nullptr);
  EXPECT_NE(err.find("half.png"), std::string::npos) << err;
  // A path that vanished between parsing and opening.
  spec.path = dir.str("gone.png");
  EXPECT_EQ(open_source(spec, &err), nullptr);
  EXPECT_NE(err.find("gone.png"), std::string::npos) << err;
}

class SourceFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    write_file(dir_.str("a.png"), png(cv::Mat(20, 30, CV_8UC3, cv::Scalar(10, 10, 10))));
    write_file(dir_.str("b.png"), png(cv::Mat(40, 50, CV_8UC3, cv::Scalar(200, 200, 200))));
    write_file(dir_.str("c.png"), "\x89PNG\r\n\x1a\n" + std::string(200, '\x01'));
    write_file(dir_.str("readme.txt"), "not an image");
  }
  TempDir dir_;
};

TEST_F(SourceFolder, StepsThroughImagesAndReportsTheCorruptOne) {
  std::string err;
  auto src = open(dir_.str(), &err);
  ASSERT_TRUE(src) << err;
  Playback pb;
  pb.playing = false;
  src->set_playback(pb);
  EXPECT_EQ(src->info().kind, SourceKind::folder);
  EXPECT_EQ(src->info().count, 3);
  cv::Mat f;
  ASSERT_EQ(src->next(0, f).status, FrameStatus::ok);
  EXPECT_EQ(f.size(), cv::Size(30, 20));
  EXPECT_EQ(src->info().item, "a.png");
  EXPECT_EQ(src->next(5, f).status, FrameStatus::same);

  src->step(+1);
  ASSERT_EQ(src->next(6, f).status, FrameStatus::ok);
  EXPECT_EQ(f.size(), cv::Size(50, 40));
  EXPECT_EQ(src->info().item, "b.png");
  EXPECT_EQ(src->info().size, cv::Size(50, 40));

  src->step(+1);
  const SourceStatus s = src->next(7, f);
  EXPECT_EQ(s.status, FrameStatus::error);
  EXPECT_NE(s.message.find("c.png"), std::string::npos) << s.message;
  EXPECT_EQ(src->info().item, "c.png");
  EXPECT_EQ(src->next(8, f).status, FrameStatus::same);

  // Past the corrupt one, wrapping (loop is on by default).
  src->step(+1);
  ASSERT_EQ(src->next(9, f).status, FrameStatus::ok);
  EXPECT_EQ(src->info().item, "a.png");
  src->step(-1);
  EXPECT_EQ(src->next(10, f).status, FrameStatus::error);
  src->step(-1);
  ASSERT_EQ(src->next(11, f).status, FrameStatus::ok);
  EXPECT_EQ(src->info().item, "b.png");

  // Without looping the last image is the end.
  pb.loop = false;
  src->set_playback(pb);
  src->seek(2);
  EXPECT_EQ(src->next(12, f).status, FrameStatus::error);
  src->step(+1);
  EXPECT_EQ(src->next(13, f).status, FrameStatus::end);
}

TEST_F(SourceFolder, PlayingShowsOneImageASecond) {
  auto src = open(dir_.str());
  ASSERT_TRUE(src);
  cv::Mat f;
  ASSERT_EQ(src->next(50.0, f).status, FrameStatus::ok);
  EXPECT_EQ(src->next(50.5, f).status, FrameStatus::same);
  ASSERT_EQ(src->next(51.01, f).status, FrameStatus::ok);
  EXPECT_EQ(src->info().item, "b.png");
  EXPECT_EQ(src->next(52.02, f).status, FrameStatus::error);
  ASSERT_EQ(src->next(53.03, f).status, FrameStatus::ok);
  EXPECT_EQ(src->info().item, "a.png");
}

TEST(SourceFolderEmpty, FolderWithoutImagesFailsToOpen) {
  TempDir dir;
  write_file(dir.str("notes.txt"), "hello");
  SourceSpec spec;
  std::string err;
  ASSERT_TRUE(parse_source_spec(dir.str(), &spec, &err)) << err;
  EXPECT_EQ(open_source(spec, &err), nullptr);
  EXPECT_NE(err.find(dir.str()), std::string::npos) << err;
}

// [SECTION] camera

TEST(SourceCamera, MissingDeviceFailsWithAMessage) {
  SourceSpec spec;
  std::string err;
  ASSERT_TRUE(parse_source_spec("camera:99", &spec, &err)) << err;
  EXPECT_EQ(open_source(spec, &err), nullptr);
  EXPECT_NE(err.find("camera:99"), std::string::npos) << err;
  EXPECT_EQ(open_source(spec, nullptr), nullptr) << "a null error pointer is fine";
}

TEST(SourceCamera, ListsDevicesSorted) {
  const std::vector<int> cams = list_cameras();
  EXPECT_TRUE(std::is_sorted(cams.begin(), cams.end()));
  for (int c : cams) {
    EXPECT_GE(c, 0);
    EXPECT_TRUE(std::filesystem::exists("/dev/video" + std::to_string(c)));
  }
}

}  // namespace
}  // namespace arwb
