// The desktop habits, in the real window under xvfb-run, driven by --actions as a user would: typing in a text
// field fires no shortcut, files dropped on the window open by kind, the file browser opens what is typed, undo
// and redo of parameter changes, the unsaved-edits question before quitting or switching, the marker sheet
// dialog, presets written rounded into the user's folder, and `arwb --version`.
#include "detect/params.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <string>

namespace arwb {
namespace {

namespace fs = std::filesystem;
using test::RunResult;
using test::TempDir;

using test::stats;

RunResult run(const TempDir& tmp, const std::string& more) {
  return test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --snapshot-dir '" + tmp.str("snaps") +
                               "' --stats --verbose " + more);
}

// A small scene the editor can open (the scripts are the project's; a copy is edited).
std::string scene_copy(const TempDir& tmp) {
  const std::string path = tmp.str("scene.lua");
  test::write_file(path, "dictionary \"ARUCO_ORIGINAL\"\nmarker(0, { media = text(\"hello\") })\n");
  return path;
}

TEST(Habits, VersionIsPrinted) {
  const RunResult r = test::run_arwb("--version");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "arwb 0.1.0\n");
}

// The field takes the keyboard in frame 5 and is activated in frame 6, the frame "t" comes: at that frame's start
// ImGui does not yet want text input, so a check made then lets it open the tour. Then more letters, a space.
TEST(Habits, TypingInATextFieldFiresNoShortcut) {
  TempDir tmp;
  const RunResult r = run(tmp, "--frames 40 --actions '5:focus=source_path;5:type=t;12:type=s n\\n'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = stats(r);
  EXPECT_FALSE(s.value("tour_active", true)) << r.out;   // T
  EXPECT_FALSE(s.value("frozen", true)) << r.out;        // Space
  EXPECT_FALSE(fs::exists(tmp.str("snaps"))) << "S wrote a snapshot";
  // The letters went into the field: Enter opened what they spell.
  EXPECT_NE(r.err.find("error: s n: no such file or folder"), std::string::npos) << r.err;
}

TEST(Habits, TheSameKeysOutsideAFieldAreShortcuts) {
  TempDir tmp;
  const RunResult r = run(tmp, "--frames 40 --actions '5:type=t'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(stats(r).value("tour_active", false)) << r.out;
}

TEST(Habits, DroppedFilesOpenByKind) {
  TempDir tmp;
  cv::imwrite(tmp.str("photo.png"), cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 120, 150)));
  test::write_file(tmp.str("fast.yml"), "%YAML:1.0\n---\nthreshold_window_px: 31\n");
  test::write_file(tmp.str("notes.txt"), "not anything the workbench opens\n");
  const std::string scene = scene_copy(tmp);
  const RunResult r = run(tmp, "--frames 60 --actions '5:drop=" + tmp.str("photo.png") + ";6:drop=" +
                                   tmp.str("fast.yml") + ";7:drop=" + scene + ";8:drop=" + tmp.str("notes.txt") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = stats(r);
  EXPECT_EQ(s.value("source", ""), tmp.str("photo.png")) << r.out;
  EXPECT_EQ(s["params"].value("threshold_window_px", 0.0), 31) << r.out;
  EXPECT_EQ(s.value("scene", ""), scene) << r.out;
  EXPECT_NE(r.err.find(tmp.str("notes.txt") + ": not a scene"), std::string::npos) << r.err;
}

TEST(Habits, FileBrowserOpensWhatIsTypedAndRemembersIt) {
  TempDir tmp;
  const std::string scene = scene_copy(tmp);
  // Enter on a folder lists it; the path then typed on opens the scene.
  // One letter a frame: the folder is typed by frame 50.
  const RunResult r = run(tmp, "--frames 110 --actions '5:browse=scene;10:type=" + tmp.str() + "\\n;60:type=/scene.lua\\n'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = stats(r);
  EXPECT_EQ(s.value("scene", ""), scene) << r.out << r.err;
  EXPECT_EQ(s.value("modal", "?"), "") << "the browser closes once the file is open";
  const std::string recent = test::read_file(tmp.str("config/recent.txt"));
  EXPECT_NE(recent.find("scene\t" + scene + "\n"), std::string::npos) << recent;

  // A damaged recent-files list is a message, and the browser opens all the same.
  test::write_file(tmp.str("config/recent.txt"), std::string("scene\t") + scene + "\ngarbage line\n");
  const RunResult again = run(tmp, "--frames 20 --actions '5:browse=scene'");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.err.find("recent.txt: line 2: expected kind<TAB>path"), std::string::npos) << again.err;
  EXPECT_EQ(stats(again).value("modal", ""), "File browser");
  EXPECT_NE(test::read_file(tmp.str("config/recent.txt")).find("\ngarbage line\n"), std::string::npos)
      << "a line this version does not understand is kept when the list is saved";

  // A list that cannot be read at all (over its limit: 2,000 starred folders and more) is set aside, not
  // written over with what this run opened.
  std::string starred;
  while (starred.size() <= (1u << 20)) starred += "favourite\t/data/" + std::string(500, 'f') + "\n";
  test::write_file(tmp.str("config/recent.txt"), starred);
  const RunResult big = run(tmp, "--frames 10");
  ASSERT_EQ(big.status, 0) << big.err;
  EXPECT_NE(big.err.find("the file is kept as " + tmp.str("config/recent.txt.bad")), std::string::npos) << big.err;
  EXPECT_EQ(test::read_file(tmp.str("config/recent.txt.bad")), starred);
}

TEST(Habits, UndoAndRedoParameterAndPresetChanges) {
  TempDir tmp;
  test::write_file(tmp.str("fast.yml"), "%YAML:1.0\n---\nerror_correction_rate: 0.3\n");
  const std::string preset = tmp.str("fast.yml");
  // Two edits and a preset, then back twice and forth once.
  const RunResult r = run(tmp, "--frames 50 --actions '5:set=threshold_window_px=31;10:preset=" + preset +
                                   ";20:undo;25:undo;30:redo'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = stats(r);
  EXPECT_EQ(s["params"].value("threshold_window_px", 0.0), 31) << r.out;
  EXPECT_EQ(s["params"].value("error_correction_rate", 0.0), 0.6) << r.out;
  EXPECT_EQ(s.value("note", ""), "redo: adaptive_threshold.threshold_window_px 17 -> 31") << r.out;
  EXPECT_EQ(s.value("redo", ""), "preset fast.yml") << r.out;
  EXPECT_NE(r.err.find("undo: preset fast.yml"), std::string::npos) << r.err;
}

// While a widget is held (here a text field has the keyboard, as a slider does while dragged) the values it passes
// through are one edit: one undo goes back to where it started.
TEST(Habits, AnEditInProgressIsOneUndoStep) {
  TempDir tmp;
  const RunResult r = run(tmp, "--frames 40 --actions '5:focus=preset_path;10:set=threshold_window_px=19;"
                               "11:set=threshold_window_px=21;12:set=threshold_window_px=25;15:type=\\n;30:undo'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = stats(r);
  EXPECT_EQ(s["params"].value("threshold_window_px", 0.0), 17) << r.out;
  EXPECT_EQ(s.value("redo", ""), "adaptive_threshold.threshold_window_px 17 -> 25") << r.out;
  EXPECT_EQ(s.value("undo", "?"), "") << r.out;
}

// Edits typed into the Script editor, then a quit: the question comes, and each answer does what it says.
RunResult edit_then(const TempDir& tmp, const std::string& scene, const std::string& then, int frames = 90) {
  return run(tmp, "--scene '" + scene + "' --frames " + std::to_string(frames) +
                      " --actions '20:focus=script;25:type=-- edited\\n;45:" + then + "'");
}

TEST(Habits, QuitWithUnsavedEditsAsksFirst) {
  TempDir tmp;
  const std::string scene = scene_copy(tmp);
  const std::string before = test::read_file(scene);
  const RunResult r = edit_then(tmp, scene, "quit");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = stats(r);
  EXPECT_EQ(s.value("frames", 0), 90) << "the window stayed open";
  EXPECT_EQ(s.value("modal", ""), "Unsaved edits") << r.out;
  EXPECT_TRUE(s.value("script_unsaved", false));
  EXPECT_EQ(test::read_file(scene), before);
}

TEST(Habits, CancelKeepsTheEditsAndTheWindow) {
  TempDir tmp;
  const std::string scene = scene_copy(tmp);
  const std::string before = test::read_file(scene);
  const RunResult r = edit_then(tmp, scene, "quit;55:answer=cancel");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = stats(r);
  EXPECT_EQ(s.value("frames", 0), 90);
  EXPECT_EQ(s.value("modal", "?"), "");
  EXPECT_TRUE(s.value("script_unsaved", false)) << "the edits are still in the editor";
  EXPECT_EQ(test::read_file(scene), before);
}

TEST(Habits, DiscardQuitsWithoutWriting) {
  TempDir tmp;
  const std::string scene = scene_copy(tmp);
  const std::string before = test::read_file(scene);
  const RunResult r = edit_then(tmp, scene, "quit;55:answer=discard");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(stats(r).value("frames", 999), 90) << "quit";
  EXPECT_EQ(test::read_file(scene), before);
}

TEST(Habits, SaveWritesTheEditsThenQuits) {
  TempDir tmp;
  const std::string scene = scene_copy(tmp);
  const RunResult r = edit_then(tmp, scene, "quit;55:answer=save");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(stats(r).value("frames", 999), 90) << "quit";
  EXPECT_EQ(test::read_file(scene).rfind("-- edited\n", 0), 0u) << test::read_file(scene);
}

TEST(Habits, ChangingTheSourceWithUnsavedEditsAsksToo) {
  TempDir tmp;
  const std::string scene = scene_copy(tmp);
  cv::imwrite(tmp.str("photo.png"), cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 120, 150)));
  const RunResult cancel = edit_then(tmp, scene, "source=" + tmp.str("photo.png") + ";55:answer=cancel", 80);
  ASSERT_EQ(cancel.status, 0) << cancel.err;
  EXPECT_EQ(stats(cancel).value("source", ""), "synthetic") << cancel.out;
  const RunResult discard = edit_then(tmp, scene, "source=" + tmp.str("photo.png") + ";55:answer=discard", 80);
  ASSERT_EQ(discard.status, 0) << discard.err;
  EXPECT_EQ(stats(discard).value("source", ""), tmp.str("photo.png")) << discard.out;
  EXPECT_FALSE(stats(discard).value("script_unsaved", true));
}

TEST(Habits, MarkerSheetGoesToTheUsersFolderAndNamesIt) {
  TempDir tmp;
  const RunResult r = run(tmp, "--frames 30 --actions '5:sheet;10:answer=write'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string pdf = tmp.str("config/marker-sheets/ARUCO_ORIGINAL.pdf");
  EXPECT_TRUE(fs::exists(pdf)) << r.err;
  EXPECT_NE(stats(r).value("note", "").find("wrote " + pdf), std::string::npos) << r.out;
}

TEST(Habits, MarkerSheetGoesWhereTheBrowserSays) {
  TempDir tmp;
  const std::string pdf = tmp.str("class.pdf");
  const RunResult r = run(tmp, "--frames 100 --actions '5:sheet;10:answer=browse;20:type=" + pdf + "\\n;90:answer=write'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(pdf)) << r.err;
  EXPECT_NE(stats(r).value("note", "").find("wrote " + pdf), std::string::npos) << r.out;
}

TEST(Habits, PresetsAreSavedRoundedInTheUsersFolder) {
  TempDir tmp;
  const RunResult r =
      run(tmp, "--frames 20 --actions '5:set=polygon_epsilon_rate=0.0333333;6:set=threshold_offset=7.26;10:save_preset=mine'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = test::read_file(tmp.str("config/presets/mine.yml"));
  EXPECT_NE(text.find("\npolygon_epsilon_rate: 0.033\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nthreshold_offset: 7.3\n"), std::string::npos) << text;
}

}  // namespace
}  // namespace arwb
