// Marking a clip in videos.csv (save_video_row, what the Lab workspace's "Save to videos.csv" does): the row is
// written relative to the folder, replaces the same clip's row, keeps the rest, and every mistake is named.
#include "lab/videos.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace arwb::lab {
namespace {

VideoRow row(int first, int last) {
  VideoRow r;
  r.id = 17;
  r.dictionary = "ARUCO_ORIGINAL";
  r.size_mm = 65;
  r.distance_m = 1;
  r.lux = 850;
  r.first_frame = first;
  r.last_frame = last;
  return r;
}

TEST(VideoRows, ARowIsWrittenReplacedAndReadBack) {
  test::TempDir d;
  std::filesystem::create_directories(d.str("clips"));
  test::write_file(d.str("clips/a.mp4"), "not read here");
  ASSERT_TRUE(save_video_row(d.str(), d.str("clips/a.mp4"), row(12, 140)));
  EXPECT_EQ(test::read_file(d.str("videos.csv")), "file,id,dictionary,size_mm,distance_m,lux,first_frame,last_frame\n"
                                        "clips/a.mp4,17,ARUCO_ORIGINAL,65,1,850,12,140\n");
  // Marked again: the row is replaced, not added; the whole clip has no span.
  ASSERT_TRUE(save_video_row(d.str(), d.str("clips/a.mp4"), row(0, -1)));
  EXPECT_EQ(test::read_file(d.str("videos.csv")), "file,id,dictionary,size_mm,distance_m,lux,first_frame,last_frame\n"
                                        "clips/a.mp4,17,ARUCO_ORIGINAL,65,1,850\n");
  const Result<std::vector<VideoRow>> back = read_video_list(d.str());
  ASSERT_TRUE(back) << back.error();
  ASSERT_EQ(back->size(), 1u);
  EXPECT_EQ((*back)[0].id, 17);
  EXPECT_EQ((*back)[0].last_frame, -1);
}

TEST(VideoRows, MistakesAreNamedAndNothingIsWritten) {
  test::TempDir d;
  test::write_file(d.str("a.mp4"), "x");
  test::TempDir elsewhere;
  test::write_file(elsewhere.str("b.mp4"), "x");
  struct Case {
    std::string clip;
    VideoRow r;
    std::string message;
  } cases[] = {
      {elsewhere.str("b.mp4"), row(0, 5), "not inside the videos' folder"},
      {d.str("a.mp4"), row(8, 3), "last_frame 3 is before first_frame 8"},
      {d.str("a.mp4"), [] { VideoRow r = row(0, 5); r.id = 1024; return r; }(), "id 1024 is not a marker of ARUCO_ORIGINAL"},
      {d.str("a.mp4"), [] { VideoRow r = row(0, 5); r.lux = -1; return r; }(), "lux -1 is outside 0.1 to 200000"},
      {d.str("a.mp4"), [] { VideoRow r = row(0, 5); r.dictionary = "NOPE"; return r; }(), "dictionary: unknown 'NOPE'"},
  };
  for (const Case& c : cases) {
    const Status s = save_video_row(d.str(), c.clip, c.r);
    ASSERT_FALSE(s) << c.message;
    EXPECT_NE(s.error().find(c.message), std::string::npos) << s.error();
  }
  EXPECT_FALSE(std::filesystem::exists(d.str("videos.csv")));
  EXPECT_FALSE(save_video_row(d.str("missing"), d.str("a.mp4"), row(0, 5)));
}

// A videos.csv of 1,000 rows each of its own size, distance and light asked for 10^9 cells and ran out of memory:
// the grid is counted before a cell is made.
TEST(VideoRows, AGridOfTooManyCellsIsRefusedBeforeItIsMade) {
  std::vector<VideoRow> rows;
  for (int i = 0; i < 1000; ++i) {
    VideoRow r = row(0, -1);
    r.size_mm = 10 + i, r.distance_m = 0.1 + 0.01 * i, r.lux = 1 + i, r.line = i + 2;
    rows.push_back(r);
  }
  LabOptions o;
  o.detectors = {"arwb"};
  std::vector<std::string> warnings;
  const Result<LabResults> r = run_videos("/nonexistent", rows, o, &warnings);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error(), "videos.csv: 1000 sizes x 1000 distances x 1000 lights make 1000000000 cells, more than 10000 "
                       "(rows with the same three share a cell)");
}

}  // namespace
}  // namespace arwb::lab
