// The Lab's Record (capture/clip_recorder.hpp): frames pushed are in the file, bit for bit (lossless), in order;
// a clip never overwrites a file; a frame of another size ends the clip with the frames before it kept; a folder
// that cannot be made is named; every frame pushed is either written or counted as dropped.
#include "capture/clip_recorder.hpp"
#include "capture/video_reader.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <string>
#include <vector>

namespace arwb {
namespace {

using test::TempDir;

// Frame i: noise seeded with i, so that a lossy codec or a frame out of order shows as a difference.
cv::Mat noisy(int i, cv::Size size = {96, 64}) {
  cv::Mat m(size, CV_8UC3);
  cv::RNG rng(uint64_t(i) + 1);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

std::vector<cv::Mat> read_all(const std::string& path) {
  std::vector<cv::Mat> frames(1);
  Result<VideoReader> r = VideoReader::open(path, &frames[0]);
  EXPECT_TRUE(r.ok()) << r.error();
  if (!r) return {};
  for (cv::Mat m; r->read(&m) == VideoReader::Read::frame;) frames.push_back(m.clone());
  return frames;
}

TEST(ClipRecorder, WritesEveryFramePushedLosslesslyAndInOrder) {
  TempDir d;
  const std::string path = d.str("clips/a.mkv");   // the folder is made
  ClipRecorder rec;
  ASSERT_TRUE(rec.start(path, {96, 64}, 25).ok());
  EXPECT_TRUE(rec.recording());
  for (int i = 0; i < 12; ++i) ASSERT_TRUE(rec.push(noisy(i)));
  cv::Mat grey;
  cv::cvtColor(noisy(12), grey, cv::COLOR_BGR2GRAY);
  ASSERT_TRUE(rec.push(grey)) << "a grey camera's frames are taken too";
  const ClipSummary s = rec.stop();
  EXPECT_FALSE(rec.recording());
  EXPECT_FALSE(rec.push(noisy(0))) << "stopped: nothing is taken";
  EXPECT_EQ(s.path, path);
  EXPECT_EQ(s.frames + s.dropped, 13);
  EXPECT_TRUE(s.error.empty()) << s.error;
  const std::vector<cv::Mat> back = read_all(path);
  ASSERT_EQ(int64_t(back.size()), s.frames);
  // Without drops (kQueueBytes holds far more than 13 small frames), frame i is noisy(i) exactly.
  ASSERT_EQ(s.dropped, 0);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(cv::norm(back[size_t(i)], noisy(i), cv::NORM_INF), 0) << "frame " << i;
  cv::Mat grey_bgr;
  cv::cvtColor(grey, grey_bgr, cv::COLOR_GRAY2BGR);
  EXPECT_EQ(cv::norm(back[12], grey_bgr, cv::NORM_INF), 0);
}

TEST(ClipRecorder, NeverOverwritesAndNamesWhatItCannotWrite) {
  TempDir d;
  test::write_file(d.str("taken.mkv"), "an earlier clip");
  ClipRecorder rec;
  const Status s = rec.start(d.str("taken.mkv"), {96, 64}, 30);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error(), d.str("taken.mkv") + ": exists (a recorded clip is never overwritten)");
  EXPECT_EQ(test::read_file(d.str("taken.mkv")), "an earlier clip");
  test::write_file(d.str("file"), "x");
  const Status under_file = rec.start(d.str("file/clips/a.mkv"), {96, 64}, 30);
  ASSERT_FALSE(under_file.ok());
  EXPECT_EQ(under_file.error().rfind(d.str("file/clips") + ": cannot create the folder", 0), 0u) << under_file.error();
  EXPECT_FALSE(rec.recording());
  EXPECT_FALSE(rec.start(d.str("b.mkv"), {0, 0}, 30).ok()) << "no size: nothing to record";
}

TEST(ClipRecorder, AFrameOfAnotherSizeEndsTheClipKeepingTheFramesBefore) {
  TempDir d;
  ClipRecorder rec;
  ASSERT_TRUE(rec.start(d.str("a.mkv"), {96, 64}, 0).ok()) << "no rate from the source: 30";
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(rec.push(noisy(i)));
  EXPECT_FALSE(rec.push(noisy(5, {128, 96})));
  EXPECT_FALSE(rec.recording());
  EXPECT_FALSE(rec.push(noisy(6))) << "ended: the clip takes nothing more";
  const ClipSummary s = rec.stop();
  EXPECT_EQ(s.error,
            "the source's frames changed from 96x64 to 128x96 (or their type); the clip ends before that frame");
  EXPECT_EQ(s.frames, 5);
  EXPECT_EQ(read_all(d.str("a.mkv")).size(), 5u);
}

TEST(ClipRecorder, EveryFramePushedIsWrittenOrCountedAsDropped) {
  TempDir d;
  const size_t queue = size_t{8} << 20;
  ClipRecorder rec(queue);
  const cv::Size big(640, 480);
  ASSERT_TRUE(rec.start(d.str("a.mkv"), big, 30).ok());
  const cv::Mat f = noisy(1, big);
  const int pushed = 80;   // faster than FFV1 encodes noise: the queue fills
  for (int i = 0; i < pushed; ++i) ASSERT_TRUE(rec.push(f));
  const ClipSummary s = rec.stop();
  EXPECT_EQ(s.frames + s.dropped, pushed);
  EXPECT_GT(s.dropped, 0) << "the queue is bounded";
  EXPECT_GE(s.frames, int64_t(queue / (f.total() * 3))) << "a full queue is written before it closes";
  EXPECT_EQ(int64_t(read_all(d.str("a.mkv")).size()), s.frames);
}

}  // namespace
}  // namespace arwb
