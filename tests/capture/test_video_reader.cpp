// The one video reader (capture/video_reader.hpp): opening with a message naming the file, the count and rate the
// container gives, reading, skipping and seeking, and a truncated file: read up to where it is cut, reported
// once, counted as what could be decoded. Videos are written here with cv::VideoWriter, frame i showing i in
// stripes, so a test can tell which frame it got.
#include "capture/video_reader.hpp"
#include "support/numbered_video.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <opencv2/videoio.hpp>

#include <chrono>
#include <string>

#include <sys/stat.h>

namespace arwb {
namespace {

using test::TempDir;
using test::write_file;

constexpr int kFrames = 40;
constexpr double kFps = 10;
const cv::Size kSize(64, 48);

bool write_grey_video(const std::string& path, const char (&fourcc)[5], int frames) {
  return test::write_numbered_video(path, fourcc, frames, kSize, kFps);
}

int frame_index(const cv::Mat& m) { return test::numbered_frame(m); }

// A copy of `whole` cut to half its bytes.
std::string cut_in_half(const TempDir& dir, const std::string& whole, const std::string& name) {
  const std::string bytes = test::read_file(whole);
  write_file(dir.str(name), bytes.substr(0, bytes.size() / 2));
  return dir.str(name);
}

class Reader : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    const std::string ext = GetParam();
    whole_ = dir_.str("whole." + ext);
    if (!write_grey_video(whole_, ext == "avi" ? "MJPG" : "mp4v", kFrames))
      GTEST_SKIP() << "no writer for " << ext << " in this OpenCV";
  }
  TempDir dir_;
  std::string whole_;
};

TEST_P(Reader, OpensWithTheFirstFrameAndReadsToTheEnd) {
  cv::Mat first;
  Result<VideoReader> r = VideoReader::open(whole_, &first);
  ASSERT_TRUE(r) << r.error();
  EXPECT_EQ(r->path(), whole_);
  EXPECT_EQ(r->size(), kSize);
  EXPECT_NEAR(r->fps(), kFps, 0.01);
  EXPECT_EQ(r->frame_count(), kFrames);
  EXPECT_EQ(r->next_index(), 1);
  ASSERT_EQ(first.type(), CV_8UC3);
  EXPECT_EQ(frame_index(first), 0);

  cv::Mat f;
  for (int i = 1; i < kFrames; ++i) {
    ASSERT_EQ(r->read(i % 3 ? nullptr : &f), VideoReader::Read::frame) << "frame " << i;
    if (i % 3 == 0) {
      EXPECT_EQ(frame_index(f), i);
    }
  }
  EXPECT_EQ(r->read(&f), VideoReader::Read::end);
  EXPECT_EQ(r->next_index(), kFrames);
  EXPECT_EQ(r->frame_count(), kFrames);
  EXPECT_EQ(r->error(), "") << "a whole file ends without a message";
}

TEST_P(Reader, SeeksBackAndForward) {
  Result<VideoReader> r = VideoReader::open(whole_, nullptr);
  ASSERT_TRUE(r) << r.error();
  cv::Mat f;
  for (const int target : {25, 3, 0, 17}) {
    ASSERT_TRUE(r->seek(target));
    while (r->next_index() < target) ASSERT_EQ(r->read(nullptr), VideoReader::Read::frame);
    ASSERT_EQ(r->read(&f), VideoReader::Read::frame);
    EXPECT_EQ(frame_index(f), target);
  }
}

TEST_P(Reader, TruncatedFileEndsWhereItIsCutAndSaysSoOnce) {
  const std::string cut = cut_in_half(dir_, whole_, std::string("cut.") + GetParam());
  cv::Mat first;
  testing::internal::CaptureStderr();
  Result<VideoReader> r = VideoReader::open(cut, &first);
  // When FFmpeg refuses the file, GStreamer is tried: OpenCV logged "[ WARN:0@0.03] ... GStreamer warning" and
  // "[ERROR:0@0.03] ... raised OpenCV exception:" with its source path on the terminal. Only our message says it.
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  if (!r && std::string(GetParam()) == "mp4") {
    // OpenCV writes an MP4's index (the moov box) last: cut in half, nothing can be found, and that is said.
    EXPECT_EQ(r.error(), cut + ": cannot open the video");
    return;
  }
  ASSERT_TRUE(r) << r.error();
  EXPECT_EQ(frame_index(first), 0);
  cv::Mat f;
  VideoReader::Read got = VideoReader::Read::frame;
  int frames = 1;
  while ((got = r->read(&f)) == VideoReader::Read::frame) {
    EXPECT_EQ(frame_index(f), frames) << "frames in order, none skipped";
    ++frames;
    ASSERT_LT(frames, kFrames);
  }
  EXPECT_GT(frames, 5);
  EXPECT_LT(frames, kFrames - 2);
  EXPECT_EQ(frame_index(f), frames - 1) << "a failed read leaves *out alone";
  // An AVI declares its frame count in its header, so the cut is known for what it is.
  if (std::string(GetParam()) == "avi") {
    EXPECT_EQ(got, VideoReader::Read::damaged);
  }
  if (r->error().empty()) {
    // A container that declares no count (or the cut one's) cannot tell a cut file from a short one.
    EXPECT_EQ(got, VideoReader::Read::end);
  } else {
    EXPECT_EQ(got, VideoReader::Read::damaged);
    EXPECT_EQ(r->error(), cut + ": cannot decode frame " + std::to_string(frames) + " of " +
                              std::to_string(kFrames) + " (damaged or truncated file); the video ends at frame " +
                              std::to_string(frames - 1));
  }
  // From now on the video is as long as what could be decoded, and its end is a plain end.
  EXPECT_EQ(r->frame_count(), frames);
  const std::string said = r->error();
  EXPECT_EQ(r->read(&f), VideoReader::Read::end);
  EXPECT_EQ(r->error(), said);
  // Going back still works.
  ASSERT_TRUE(r->seek(2));
  while (r->next_index() < 2) ASSERT_EQ(r->read(nullptr), VideoReader::Read::frame);
  ASSERT_EQ(r->read(&f), VideoReader::Read::frame);
  EXPECT_EQ(frame_index(f), 2);
}

INSTANTIATE_TEST_SUITE_P(Containers, Reader, ::testing::Values("avi", "mp4"));

TEST(ReaderFaults, MessagesNameTheFile) {
  TempDir dir;
  write_file(dir.str("text.mp4"), "not a video at all\n");
  write_file(dir.str("broken.avi"), std::string("RIFF\x10\x00\x00\x00" "AVI LIST", 16) + std::string(4000, '\x5a'));
  for (const char* name : {"text.mp4", "broken.avi", "missing.avi"}) {
    Result<VideoReader> r = VideoReader::open(dir.str(name), nullptr);
    ASSERT_FALSE(r) << name;
    EXPECT_EQ(r.error().rfind(dir.str(name) + ": ", 0), 0u) << r.error();
    EXPECT_TRUE(r.error().find("cannot open the video") != std::string::npos ||
                r.error().find("has no frames that can be decoded") != std::string::npos ||
                r.error() == dir.str(name) + ": no such file")
        << r.error();
  }
}

// FFmpeg would wait forever for a writer on a FIFO: refused by name, before any backend sees it.
TEST(ReaderFaults, AFifoIsRefusedByNameWithoutBlocking) {
  TempDir dir;
  const std::string fifo = dir.str("clip.mp4");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  Result<VideoReader> r = VideoReader::open(fifo, nullptr);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error(), fifo + ": not a regular file (a FIFO)");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
}

TEST(ReaderFaults, RefusesFramesLargerThanTheLimit) {
  TempDir dir;
  ASSERT_TRUE(write_grey_video(dir.str("clip.avi"), "MJPG", 3));
  Result<VideoReader> r = VideoReader::open(dir.str("clip.avi"), nullptr, 1000);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error(), dir.str("clip.avi") + ": frames of 64x48 pixels, more than 1000");
  EXPECT_TRUE(VideoReader::open(dir.str("clip.avi"), nullptr, 64 * 48));
}

}  // namespace
}  // namespace arwb
