// The pure logic behind the desktop habits: the undo history, the recent-files list and its file, what a dropped
// file opens as, and presets written rounded to each parameter's precision.
#include "detect/params.hpp"
#include "support/support.hpp"
#include "ui/history.hpp"
#include "ui/recent_files.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace arwb::ui {
namespace {

DetectorState with(double window_px, double rate = 0.6) {
  DetectorState s;
  s.dictionaries = {"ARUCO_ORIGINAL"};
  set_param(s.params, *find_param("threshold_window_px"), window_px);
  set_param(s.params, *find_param("error_correction_rate"), rate);
  return s;
}

TEST(SettingsHistory, UndoAndRedoWalkTheEditsNamed) {
  SettingsHistory h;
  const DetectorState a = with(17), b = with(31), c = with(31, 0.3);
  h.record(a, b, "");
  h.record(b, c, "preset fast.yml");
  EXPECT_EQ(h.undo_name(), "preset fast.yml");
  DetectorState s;
  std::string name;
  ASSERT_TRUE(h.undo(&s, &name));
  EXPECT_EQ(s, b);
  EXPECT_EQ(name, "preset fast.yml");
  ASSERT_TRUE(h.undo(&s, &name));
  EXPECT_EQ(s, a);
  EXPECT_EQ(name, "adaptive_threshold.threshold_window_px 17 -> 31");
  EXPECT_FALSE(h.undo(&s, &name));
  ASSERT_TRUE(h.redo(&s, &name));
  EXPECT_EQ(s, b);
  // A new edit after an undo drops what could be redone.
  h.record(b, with(21), "");
  EXPECT_FALSE(h.can_redo());
  EXPECT_EQ(h.size(), 2u);
}

TEST(SettingsHistory, NothingIsRecordedWhenNothingChanged) {
  SettingsHistory h;
  h.record(with(17), with(17), "x");
  EXPECT_FALSE(h.can_undo());
}

TEST(SettingsHistory, KeepsTheNewestEntriesOnly) {
  SettingsHistory h;
  for (int i = 0; i < static_cast<int>(SettingsHistory::kMax) + 5; ++i) h.record(with(3 + 2 * (i % 90)), with(5 + 2 * (i % 90)), "");
  EXPECT_EQ(h.size(), SettingsHistory::kMax);
}

TEST(DescribeChange, NamesTheStageParameterAndValuesAtTheirPrecision) {
  EXPECT_EQ(describe_change(with(17, 0.6), with(17, 0.25)), "identification.error_correction_rate 0.6 -> 0.25");
  EXPECT_EQ(describe_change(with(17, 0.6), with(21, 0.25)), "2 parameters");
  DetectorState d = with(17);
  d.dictionaries = {"6X6_250"};
  EXPECT_EQ(describe_change(with(17), d), "dictionaries ARUCO_ORIGINAL -> 6X6_250");
  EXPECT_EQ(describe_change(d, d), "");
}

TEST(RecentFiles, NewestFirstEachOnceAtMostTen) {
  RecentFiles r;
  for (int i = 0; i < 12; ++i) r.add(FileKind::scene, "/s/" + std::to_string(i) + ".lua");
  r.add(FileKind::scene, "/s/5.lua");
  const auto& list = r.of(FileKind::scene);
  ASSERT_EQ(list.size(), RecentFiles::kMax);
  EXPECT_EQ(list[0], "/s/5.lua");
  EXPECT_EQ(list[1], "/s/11.lua");
  EXPECT_EQ(std::count(list.begin(), list.end(), "/s/5.lua"), 1);
  EXPECT_TRUE(r.of(FileKind::source).empty());
}

TEST(RecentFiles, FileRoundTripsAndBadLinesAreNamed) {
  RecentFiles r;
  r.add(FileKind::source, "/v/a.mp4");
  r.add(FileKind::source, "/v/b.mp4");
  r.add(FileKind::preset, "/p/fast.yml");
  r.toggle_favourite("/data");
  const RecentFiles back = parse_recent(recent_text(r), nullptr);
  EXPECT_EQ(back.of(FileKind::source), r.of(FileKind::source));
  EXPECT_EQ(back.of(FileKind::preset), r.of(FileKind::preset));
  EXPECT_EQ(back.favourites, r.favourites);
  std::vector<std::string> problems;
  const RecentFiles bad = parse_recent("scene\t/a.lua\nnonsense\nmovie\t/x\n", &problems);
  EXPECT_EQ(bad.of(FileKind::scene), std::vector<std::string>{"/a.lua"});
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0], "line 2: expected kind<TAB>path");
  EXPECT_EQ(problems[1], "line 3: unknown kind 'movie'");
  // What this version does not understand is written back as it was.
  EXPECT_EQ(bad.kept, (std::vector<std::string>{"nonsense", "movie\t/x"}));
  const std::string saved = recent_text(bad);
  EXPECT_NE(saved.find("\nnonsense\n"), std::string::npos) << saved;
  EXPECT_NE(saved.find("\nmovie\t/x\n"), std::string::npos) << saved;
}

TEST(RecentFiles, StarringAFolderTwiceUnstarsIt) {
  RecentFiles r;
  r.toggle_favourite("/data");
  EXPECT_TRUE(r.is_favourite("/data"));
  r.toggle_favourite("/data");
  EXPECT_FALSE(r.is_favourite("/data"));
}

TEST(DropKind, ByExtensionThenByContent) {
  EXPECT_EQ(drop_kind("/a/scene.lua", false, false), DropKind::scene);
  EXPECT_EQ(drop_kind("/a/db.XML", false, false), DropKind::scene);
  EXPECT_EQ(drop_kind("/a/fast.yml", false, false), DropKind::preset);
  EXPECT_EQ(drop_kind("/a/photos", true, false), DropKind::source);
  EXPECT_EQ(drop_kind("/a/photos.lua", true, false), DropKind::source);   // a folder is a folder
  EXPECT_EQ(drop_kind("/a/clip.bin", false, true), DropKind::source);     // its bytes say video
  EXPECT_EQ(drop_kind("/a/notes.txt", false, false), DropKind::none);
  EXPECT_EQ(drop_kind("/a.d/noext", false, false), DropKind::none);
}

TEST(ListedFor, FiltersByTheKindBeingOpened) {
  EXPECT_TRUE(listed_for(FileKind::source, "a.PNG"));
  EXPECT_TRUE(listed_for(FileKind::source, "clip.mp4"));
  EXPECT_FALSE(listed_for(FileKind::source, "scene.lua"));
  EXPECT_TRUE(listed_for(FileKind::scene, "scene.lua"));
  EXPECT_FALSE(listed_for(FileKind::scene, "fast.yml"));
  EXPECT_TRUE(listed_for(FileKind::preset, "fast.yml"));
}

TEST(Presets, AreWrittenRoundedToEachParametersPrecision) {
  test::TempDir dir;
  DetectorParams p;
  set_param(p, *find_param("polygon_epsilon_rate"), 0.0333333333);
  set_param(p, *find_param("threshold_offset"), 7.26);
  set_param(p, *find_param("min_perimeter_px"), 48.4);
  std::string err;
  ASSERT_TRUE(save_params_yaml(dir.str("p.yml"), p, &err)) << err;
  const std::string text = test::read_file(dir.str("p.yml"));
  EXPECT_NE(text.find("\npolygon_epsilon_rate: 0.033\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nthreshold_offset: 7.3\n"), std::string::npos) << text;   // range 0..100: one decimal
  EXPECT_NE(text.find("\nmin_perimeter_px: 48\n"), std::string::npos) << text;     // range 4..100000: none
  EXPECT_NE(text.find("\nerror_correction_rate: 0.6\n"), std::string::npos) << text;
  DetectorParams back;
  std::vector<std::string> errors;
  ASSERT_TRUE(load_params_yaml(dir.str("p.yml"), back, &errors)) << (errors.empty() ? "" : errors[0]);
  EXPECT_DOUBLE_EQ(back.polygon_epsilon_rate, 0.033);
}

}  // namespace
}  // namespace arwb::ui
