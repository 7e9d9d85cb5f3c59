// The player (`arwb play BUNDLE`) and the workbench's File > Export... and File > Play bundle..., in real windows
// (xvfb-run, Mesa): an exported bundle plays from another folder with the original gone and its media land where
// `arwb render` (the workbench's compositor, offscreen) puts them; a tampered bundle is refused before any window;
// the workbench's export is a bundle open_bundle accepts; Play bundle starts the player as a process of its own.
#include "bundle/bundle.hpp"
#include "ui/app.hpp"
#include "support/support.hpp"
#include "support/samples.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace arwb {
namespace {

namespace fs = std::filesystem;
using test::RunResult;
using test::TempDir;
using test::write_file;

using test::kSample;

// A scene in its own folder: a magenta picture stretched over markers 843 and 950 of the sample image (a table
// {843, 950} given to marker() would be the range 843 to 950).
void write_scene(const std::string& dir) {
  fs::create_directories(dir);
  cv::imwrite(dir + "/magenta.png", cv::Mat(64, 64, CV_8UC3, cv::Scalar(255, 0, 255)));
  write_file(dir + "/scene.lua",
             "for _, id in ipairs({843, 950}) do\n"
             "  marker(id, { media = image \"magenta.png\", place = on_marker { fit = \"stretch\" } })\n"
             "end\n");
}

// Every JSON line of a run's stdout (the workbench's, and a player's it started).
std::vector<nlohmann::json> json_lines(const std::string& out) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_object()) lines.push_back(j);
  }
  return lines;
}

// The inside of a media quad (image pixels), shrunk towards its centre so that edges, which the two renderings
// smooth differently, are left out.
cv::Mat quad_mask(cv::Size size, const nlohmann::json& quad, double shrink) {
  std::vector<cv::Point2d> c;
  for (const auto& p : quad) c.emplace_back(p[0].get<double>(), p[1].get<double>());
  cv::Point2d centre(0, 0);
  for (const auto& p : c) centre += p * 0.25;
  std::vector<cv::Point> poly;
  for (const auto& p : c) poly.emplace_back(cv::Point(int(std::lround(centre.x + (p.x - centre.x) * shrink)),
                                                      int(std::lround(centre.y + (p.y - centre.y) * shrink))));
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  cv::fillConvexPoly(mask, poly, cv::Scalar(255));
  return mask;
}

TEST(Player, ExportedBundlePlaysFromAnotherFolderWithTheMediaWhereRenderPutsThem) {
  TempDir tmp;
  const std::string src = tmp.str("author");
  write_scene(src);
  // What the workbench's compositor makes of the sample with this scene (arwb render: the same code, offscreen).
  RunResult r = test::run_arwb("render --scene '" + src + "/scene.lua' --input '" + kSample + "' --out '" +
                               tmp.str("rendered") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const cv::Mat rendered = cv::imread(tmp.str("rendered/frame_000000.png"));
  ASSERT_EQ(rendered.size(), cv::Size(640, 480));

  r = test::run_arwb("export --scene '" + src + "/scene.lua' --out '" + tmp.str("made.arwb") + "' --title 'Magenta'");
  ASSERT_EQ(r.status, 0) << r.err;
  // The bundle moves elsewhere and the author's folder is gone: everything it needs is inside it.
  fs::create_directories(tmp.str("elsewhere"));
  fs::rename(tmp.str("made.arwb"), tmp.str("elsewhere/played.arwb"));
  fs::remove_all(src);

  r = test::run_arwb_window("play '" + tmp.str("elsewhere/played.arwb") + "' --source '" + kSample +
                            "' --frames 40 --stats --screenshot '" + tmp.str("shot.png") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto stats = test::stats(r);
  EXPECT_EQ(stats["title"], "Magenta") << r.out;
  EXPECT_EQ(stats["scene_ok"], true) << r.out;
  EXPECT_EQ(stats["dictionary"], "ARUCO_ORIGINAL") << r.out;
  EXPECT_EQ(stats["marker_ids"], nlohmann::ordered_json::array({843, 950})) << r.out;
  ASSERT_EQ(stats["overlays"], 2) << r.out;
  EXPECT_EQ(stats["pose_marker_side"], 50.0) << "poses in the bundle's millimetres";

  // The picture fills the 1280x720 window with its aspect kept: 960x720 between two black bars.
  const cv::Mat shot = cv::imread(tmp.str("shot.png"));
  ASSERT_EQ(shot.size(), cv::Size(1280, 720));
  const auto& pic = stats["picture"];
  EXPECT_EQ(pic, nlohmann::ordered_json::array({160.0, 0.0, 960.0, 720.0})) << r.out;
  EXPECT_LT(cv::norm(cv::mean(shot(cv::Rect(0, 0, 150, 720)))), 1.0) << "the bars are black";
  // The player's picture at the image's own size, to compare pixel for pixel with the rendered frame.
  cv::Mat played;
  cv::resize(shot(cv::Rect(160, 0, 960, 720)), played, rendered.size(), 0, 0, cv::INTER_AREA);
  for (const auto& m : stats["media"]) {
    const cv::Mat mask = quad_mask(rendered.size(), m["quad"], 0.7);
    ASSERT_GT(cv::countNonZero(mask), 200) << m.dump();
    const cv::Scalar in_player = cv::mean(played, mask), in_render = cv::mean(rendered, mask);
    // The media's colour (BGR 255, 0, 255) in both, on the same pixels.
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(in_player[c], c == 1 ? 0 : 255, 20) << "marker " << m["marker"] << " channel " << c;
      EXPECT_NEAR(in_player[c], in_render[c], 12) << "marker " << m["marker"] << " channel " << c;
    }
  }
  // And the whole picture matches the rendered frame closely (scaling up and down blurs it a little).
  cv::Mat diff;
  cv::absdiff(played, rendered, diff);
  const cv::Scalar d = cv::mean(diff);
  EXPECT_LT((d[0] + d[1] + d[2]) / 3, 6.0);
}

TEST(Player, TamperedBundleIsRefusedNamingTheEntryWithoutAWindow) {
  TempDir tmp;
  write_scene(tmp.str("author"));
  RunResult r = test::run_arwb("export --scene '" + tmp.str("author/scene.lua") + "' --out '" + tmp.str("bundle") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  // One pixel of the media changed after the export.
  std::string media_entry;
  for (const auto& e : fs::recursive_directory_iterator(tmp.str("bundle")))
    if (e.path().filename() == "magenta.png") media_entry = fs::relative(e.path(), tmp.str("bundle")).string();
  ASSERT_FALSE(media_entry.empty());
  cv::Mat img = cv::imread(tmp.str("bundle/" + media_entry));
  img.at<cv::Vec3b>(0, 0) = {0, 0, 0};
  cv::imwrite(tmp.str("bundle/" + media_entry), img);
  // No xvfb here: a player that opened a window would fail for want of a display, not for the bundle.
  r = test::run_arwb("play '" + tmp.str("bundle") + "' --frames 5");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(media_entry), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("window"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
}

// A player stopped by SIGTERM leaves no copy of its bundle behind; one killed with SIGKILL leaves its copy, which
// the next player removes once it is a minute old (nobody holds its lock).
std::string copies_in(const std::string& dir) {
  std::string names;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("arwb-bundle-", 0) == 0) names += e.path().filename().string() + " ";
  return names;
}

TEST(Player, AStoppedPlayersCopyIsRemovedAndAKilledOnesGoesAtTheNextStart) {
  TempDir tmp;
  write_scene(tmp.str("author"));
  RunResult r = test::run_arwb("export --scene '" + tmp.str("author/scene.lua") + "' --out '" + tmp.str("b.arwb") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  fs::create_directory(tmp.str("t"));
  // The player runs until the signal; the script waits for its copy to appear first (at most 60 s).
  auto play_and_send = [&](const char* sig) {
    const std::string script =
        "export TMPDIR='" + tmp.str("t") + "'; xvfb-run -a -s '-screen 0 1920x1080x24' sh -c '" +
        "\"$0\" play \"$1\" --source synthetic & p=$!; i=0; "
        "while ! ls \"$TMPDIR\" | grep -q arwb-bundle- && [ $i -lt 600 ]; do sleep 0.1; i=$((i+1)); done; "
        "sleep 0.5; kill -" + sig + " $p; wait $p; echo status=$?' '" + ARWB_BINARY + "' '" + tmp.str("b.arwb") +
        "' > '" + tmp.str("status.txt") + "' 2>&1";
    EXPECT_EQ(std::system(script.c_str()), 0);
    return test::read_file(tmp.str("status.txt"));
  };
  // Ended by the signal, as without the handler (the shell adds its own "Terminated" line).
  std::string said = play_and_send("TERM");
  EXPECT_NE(said.find("status=143\n"), std::string::npos) << said;
  EXPECT_EQ(copies_in(tmp.str("t")), "");
  said = play_and_send("KILL");
  EXPECT_NE(said.find("status=137\n"), std::string::npos) << said;
  const std::string left = copies_in(tmp.str("t"));
  ASSERT_NE(left, "");
  for (const auto& e : fs::directory_iterator(tmp.str("t")))
    fs::last_write_time(e.path(), fs::last_write_time(e.path()) - std::chrono::minutes(2));
  const char* was = std::getenv("TMPDIR");
  const std::string tmpdir_before = was ? was : "";
  ::setenv("TMPDIR", tmp.str("t").c_str(), 1);
  r = test::run_arwb("play '" + tmp.str("nowhere.arwb") + "'");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(copies_in(tmp.str("t")), left) << "a bundle that does not exist makes no copy";
  r = test::run_arwb("play '" + tmp.str("author") + "'");   // not a bundle, but copied first, so orphans are looked for
  if (was) ::setenv("TMPDIR", tmpdir_before.c_str(), 1);
  else ::unsetenv("TMPDIR");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(copies_in(tmp.str("t")), "");
}

// The bounding box of the dark pixels (all channels under 60) inside `area` of a screenshot.
cv::Rect dark_box(const cv::Mat& shot, cv::Rect area) {
  cv::Mat dark;
  cv::inRange(shot(area), cv::Scalar(0, 0, 0), cv::Scalar(60, 60, 60), dark);
  const cv::Rect box = cv::boundingRect(dark);
  return {box.x + area.x, box.y + area.y, box.width, box.height};
}

// A white image with a black square of `side` pixels in its middle: a source whose aspect shows in the player.
std::string write_square_image(const TempDir& tmp, const std::string& name, cv::Size size, int side) {
  cv::Mat img(size, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::rectangle(img, cv::Rect((size.width - side) / 2, (size.height - side) / 2, side, side), cv::Scalar(0, 0, 0),
                cv::FILLED);
  const std::string path = tmp.str(name);
  cv::imwrite(path, img);
  return path;
}

TEST(Player, SixteenByNineSourcePlaysAtItsOwnAspectAndASquareStaysSquare) {
  TempDir tmp;
  write_scene(tmp.str("author"));
  RunResult r = test::run_arwb("export --scene '" + tmp.str("author/scene.lua") + "' --out '" + tmp.str("b.arwb") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string wide = write_square_image(tmp, "wide.png", {1280, 720}, 300);
  r = test::run_arwb_window("play '" + tmp.str("b.arwb") + "' --source '" + wide + "' --frames 10 --stats --screenshot '" +
                            tmp.str("wide_shot.png") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  auto stats = test::stats(r);
  // The paper's 640 width, the height from the source's 16:9 (not the paper's 640x480, which squashed it).
  EXPECT_EQ(stats["image_size"], nlohmann::ordered_json::array({640, 360})) << r.out;
  // A 16:9 picture fills the 16:9 window: no bars.
  EXPECT_EQ(stats["picture"], nlohmann::ordered_json::array({0.0, 0.0, 1280.0, 720.0})) << r.out;
  cv::Mat shot = cv::imread(tmp.str("wide_shot.png"));
  ASSERT_EQ(shot.size(), cv::Size(1280, 720));
  cv::Rect box = dark_box(shot, {0, 0, 1280, 720});
  EXPECT_NEAR(box.width, 300, 4) << "the square drawn 1:1 in a window as large as the source";
  EXPECT_NEAR(box.height, 300, 4);
  EXPECT_NEAR(box.width, box.height, 2) << "a square stays square";

  // A square source: a square image, drawn square between two bars.
  const std::string square = write_square_image(tmp, "square.png", {500, 500}, 200);
  r = test::run_arwb_window("play '" + tmp.str("b.arwb") + "' --source '" + square + "' --frames 10 --stats --screenshot '" +
                            tmp.str("square_shot.png") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  stats = test::stats(r);
  EXPECT_EQ(stats["image_size"], nlohmann::ordered_json::array({640, 640})) << r.out;
  EXPECT_EQ(stats["picture"], nlohmann::ordered_json::array({280.0, 0.0, 720.0, 720.0})) << r.out;
  shot = cv::imread(tmp.str("square_shot.png"));
  ASSERT_EQ(shot.size(), cv::Size(1280, 720));
  box = dark_box(shot, {280, 0, 720, 720});   // inside the picture: the bars are black too
  EXPECT_NEAR(box.width, 288, 4) << "200 of 500 pixels, in a 720-pixel picture";
  EXPECT_NEAR(box.width, box.height, 2) << "a square stays square";
}

TEST(Player, ResizeOptionChoosesTheWorkingSize) {
  TempDir tmp;
  write_scene(tmp.str("author"));
  RunResult r = test::run_arwb("export --scene '" + tmp.str("author/scene.lua") + "' --out '" + tmp.str("b.arwb") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string wide = write_square_image(tmp, "wide.png", {1280, 720}, 300);
  const std::vector<std::pair<std::string, std::vector<int>>> cases = {
      {"off", {1280, 720}}, {"320x240", {320, 240}}, {"800", {800, 450}}};
  for (const auto& [resize, size] : cases) {
    r = test::run_arwb_window("play '" + tmp.str("b.arwb") + "' --source '" + wide + "' --frames 3 --stats --resize " + resize);
    ASSERT_EQ(r.status, 0) << resize << ": " << r.err;
    EXPECT_EQ(test::stats(r)["image_size"], nlohmann::ordered_json(size)) << resize << ": " << r.out;
  }
  // Checked before the bundle is opened or a window is, as a usage error.
  for (const std::string bad : {"0", "10", "640x", "x480", "wide"}) {
    r = test::run_arwb("play '" + tmp.str("b.arwb") + "' --resize " + bad);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("--resize"), std::string::npos) << bad << ": " << r.err;
  }
}

TEST(Player, RefusedBundleWithErrorWindowSaysItInAWindowAndExitsOne) {
  TempDir tmp;
  write_scene(tmp.str("author"));
  RunResult r = test::run_arwb("export --scene '" + tmp.str("author/scene.lua") + "' --out '" + tmp.str("bundle") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  write_file(tmp.str("bundle/extra.lua"), "print('not exported')\n");
  // What the desktop's file association runs (packaging/arwb-player.desktop), with frames to end it.
  r = test::run_arwb_window("play --error-window '" + tmp.str("bundle") + "' --frames 5 --stats --screenshot '" +
                            tmp.str("refused.png") + "'");
  EXPECT_EQ(r.status, 1) << r.err;
  // Still the one line on stderr, for whoever has a terminal.
  EXPECT_NE(r.err.find("extra.lua"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  const auto stats = test::stats(r);
  EXPECT_EQ(stats["window"], "error") << r.out;
  EXPECT_EQ(stats["frames"], 5) << r.out;
  EXPECT_EQ(stats["closed_by"], "frames") << r.out;
  EXPECT_EQ(stats["heading"], "This bundle cannot be played.") << r.out;
  // The window says what stderr says.
  const std::string line = r.err.substr(r.err.find("arwb play: ") + std::string("arwb play: ").size());
  EXPECT_EQ(stats["message"].get<std::string>() + "\n", line) << r.out;
  // And the pixels show text: light glyphs below the heading, above the button row.
  const cv::Mat shot = cv::imread(tmp.str("refused.png"));
  ASSERT_EQ(shot.size(), cv::Size(640, 220));
  cv::Mat grey, light;
  cv::cvtColor(shot(cv::Rect(0, 40, 640, 120)), grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, light, 150, 255, cv::THRESH_BINARY);
  EXPECT_GT(cv::countNonZero(light), 300) << "no message text drawn";
}

TEST(Player, ErrorWindowChangesNothingForABundleThatPlays) {
  TempDir tmp;
  write_scene(tmp.str("author"));
  RunResult r = test::run_arwb("export --scene '" + tmp.str("author/scene.lua") + "' --out '" + tmp.str("b.arwb") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  r = test::run_arwb_window("play --error-window '" + tmp.str("b.arwb") + "' --source '" + kSample +
                            "' --frames 5 --stats --verbose");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto stats = test::stats(r);
  EXPECT_FALSE(stats.contains("window")) << r.out;
  EXPECT_EQ(stats["overlays"], 2) << r.out;
  // The log names the bundle the user gave, not the private copy the player reads it from.
  EXPECT_NE(r.err.find("scene: " + tmp.str("b.arwb") + "/scene/scene.lua"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("arwb-bundle-"), std::string::npos) << r.err;
}

TEST(WorkbenchExport, FileExportWritesABundleThatOpenBundleAcceptsAndPlayBundleStartsThePlayer) {
  TempDir tmp;
  write_scene(tmp.str("author"));
  const std::string out = tmp.str("exports/from-the-window");   // its folder does not exist yet
  const RunResult r = test::run_arwb_window(
      "--verbose --config-dir '" + tmp.str("config") + "' --source '" + kSample + "' --scene '" + tmp.str("author/scene.lua") +
      "' --frames 30 --stats --actions '3:export_title=From the window;3:export_size=65;3:export_web=on;4:export=" + out +
      ";4:export_wait;6:play_args=--frames 15 --stats --source " + kSample + ";6:play=" + out + ";6:play_wait'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<nlohmann::json> lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 2u) << "the player's stats line, then the workbench's:\n" << r.out;
  const nlohmann::json& player = lines[0];
  const nlohmann::json& wb = lines[1];
  EXPECT_EQ(wb["export"]["written"], out) << wb["export"].dump();
  EXPECT_EQ(wb["export"]["self_test_passed"], true);
  ASSERT_EQ(wb["export"]["self_test"].size(), 2u) << wb["export"].dump();
  for (const auto& row : wb["export"]["self_test"]) {
    EXPECT_TRUE(row["detected"].get<bool>() && row["fired"].get<bool>()) << row.dump();
    EXPECT_EQ(row["line"], 2);
  }
  EXPECT_EQ(wb["players"]["started"], 1) << wb["players"].dump();
  EXPECT_EQ(wb["players"]["ended"], 1);
  EXPECT_EQ(wb["players"]["exit_codes"], nlohmann::json::array({0}));
  EXPECT_NE(r.err.find("ended (exit status 0)"), std::string::npos) << r.err;
  // The player showed the bundle: its title, its markers, its media.
  EXPECT_EQ(player["title"], "From the window") << player.dump();
  EXPECT_EQ(player["frames"], 15);
  EXPECT_EQ(player["overlays"], 2) << player.dump();

  // What the window wrote is a bundle the player's own check accepts.
  Result<bundle::OpenedBundle> opened = bundle::open_bundle(out);
  ASSERT_TRUE(opened) << opened.error();
  EXPECT_EQ(opened->manifest().title, "From the window");
  EXPECT_EQ(opened->manifest().marker_size_mm, 65);
  EXPECT_EQ(opened->manifest().ids, (std::vector<int>{843, 950}));
  EXPECT_TRUE(opened->manifest().self_test_passed);
  // With the dialog's web page for phones (export_web=on): the player's site, with its own role.
  size_t web = 0;
  for (const bundle::BundleFile& f : opened->manifest().files) web += f.role == "web";
  EXPECT_GE(web, 4u);
  EXPECT_TRUE(std::filesystem::is_regular_file(out + "/index.html"));
  EXPECT_TRUE(std::filesystem::is_regular_file(out + "/web/arwb_core.wasm"));
}

TEST(WorkbenchExport, DialogSaysTheExportsMessagesInItsOwnWordsNotTheCommandLines) {
  TempDir tmp;
  write_scene(tmp.str("author"));
  const std::string out = tmp.str("twice.arwb");
  // Exported once (no calibration: a warning), then again to the same name without the replace checkbox (an error).
  const RunResult r = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --source '" + kSample +
                                            "' --scene '" + tmp.str("author/scene.lua") + "' --frames 20 --stats --actions '3:export=" +
                                            out + ";4:export_wait;8:export=" + out + ";9:export_wait'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto stats = test::stats(r);
  const std::string error = stats["export"]["error"].get<std::string>();
  EXPECT_EQ(error, out + " exists; tick 'replace an existing bundle there' to replace it") << stats["export"].dump();
  // The warning in the log as the window says it, with no option of `arwb export` anywhere in it.
  EXPECT_NE(r.err.find("export: no calibration: the player uses the paper's default camera"), std::string::npos) << r.err;
  for (const char* option : {"--calib", "--out", "--force"}) EXPECT_EQ(r.err.find(option), std::string::npos) << option << ": " << r.err;
}

TEST(WorkbenchExport, WindowWordingOfTheExportsMessages) {
  EXPECT_EQ(export_window_wording("no --calib: the player uses the paper's default camera values"),
            "no calibration: the player uses the paper's default camera values");
  EXPECT_EQ(export_window_wording("--out /tmp/x is not a bundle (no readable manifest.json); not replacing it"),
            "/tmp/x is not a bundle (no readable manifest.json); not replacing it");
  EXPECT_EQ(export_window_wording("--out: no bundle named"), "where to export: no bundle named");
  EXPECT_EQ(export_window_wording("--calib c.yml: no camera matrix"), "the calibration c.yml: no camera matrix");
  EXPECT_EQ(export_window_wording("museum.lua:3: marker(5000) skipped"), "museum.lua:3: marker(5000) skipped");
}

TEST(WorkbenchExport, PlayBundleRefusesATamperedBundleInTheLog) {
  TempDir tmp;
  write_scene(tmp.str("author"));
  RunResult r = test::run_arwb("export --scene '" + tmp.str("author/scene.lua") + "' --out '" + tmp.str("bundle") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  write_file(tmp.str("bundle/extra.lua"), "print('not exported')\n");
  r = test::run_arwb_window("--config-dir '" + tmp.str("config") + "' --source synthetic --frames 10 --stats "
                            "--actions '2:play_args=--frames 5;2:play=" + tmp.str("bundle") + ";2:play_wait'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<nlohmann::json> lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 1u) << "no player ran:\n" << r.out;
  EXPECT_EQ(lines[0]["players"]["refused"], 1) << lines[0]["players"].dump();
  EXPECT_EQ(lines[0]["players"]["started"], 0);
  EXPECT_NE(r.err.find("play: refused:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("extra.lua"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace arwb
