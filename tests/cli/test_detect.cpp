// `arwb detect`, `arwb synth` and `arwb bench` run as a user runs them: the JSON line checked field by field
// against a synthetic set's truth, folders, videos, and every kind of bad input named in one line.
#include "calibration/calibration_file.hpp"
#include "detect/dictionary.hpp"
#include "detect/kernels/simd.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <set>
#include <sstream>

using namespace arwb;
using test::run_arwb;
using Json = nlohmann::ordered_json;
using test::parse;
using test::lines;
using test::q;

namespace {

std::vector<std::string> keys(Json& j) {
  std::vector<std::string> out;
  if (j.is_object())
    for (const auto& [k, v] : j.items()) out.push_back(k);
  return out;
}

// An image with two known markers.
std::vector<TruthMarker> write_scene(const std::string& path) {
  const Dictionary d = make_aruco_original();
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar(170, 180, 190));
  std::vector<TruthMarker> truth = {
      {7, d.name(), project_square({180, 200}, 150, 20, 25, -10, 700)},
      {300, d.name(), project_square({470, 260}, 110, 140, -30, 30, 700)}};
  for (const auto& t : truth) draw_marker(img, d, t.id, t.corners);
  cv::imwrite(path, img);
  return truth;
}

}  // namespace

TEST(CliDetect, JsonLineHasExactlyTheDocumentedShape) {
  test::TempDir dir;
  const auto truth = write_scene(dir.str("scene.png"));
  const auto r = run_arwb("detect --json " + q(dir.str("scene.png")));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto out = lines(r.out);
  ASSERT_EQ(out.size(), 1u);
  Json j = parse(out[0]);
  EXPECT_EQ(keys(j), (std::vector<std::string>{"source", "frame", "width", "height", "ms", "markers"})) << out[0];
  EXPECT_EQ(j["source"], dir.str("scene.png"));
  EXPECT_EQ(j["frame"], 0);
  EXPECT_EQ(j["width"], 640);
  EXPECT_EQ(j["height"], 480);
  ASSERT_TRUE(j["ms"].is_number());
  EXPECT_GT(j["ms"].get<double>(), 0.0);
  ASSERT_EQ(j["markers"].size(), 2u) << out[0];
  for (size_t k = 0; k < 2; ++k) {
    Json& m = j["markers"][k];
    EXPECT_EQ(keys(m), (std::vector<std::string>{"id", "dict", "corners", "hamming"})) << m;
    EXPECT_EQ(m["id"], truth[k].id);  // sorted by id
    EXPECT_EQ(m["dict"], "ARUCO_ORIGINAL");
    ASSERT_EQ(m["corners"].size(), 4u) << m;
    for (size_t c = 0; c < 4; ++c) {
      Json& p = m["corners"][c];
      ASSERT_TRUE(p.size() == 2 && p[0].is_number() && p[1].is_number()) << p;
      EXPECT_NEAR(p[0].get<double>(), truth[k].corners[c].x, 0.3) << "marker " << k << " corner " << c;
      EXPECT_NEAR(p[1].get<double>(), truth[k].corners[c].y, 0.3) << "marker " << k << " corner " << c;
    }
    EXPECT_EQ(m["hamming"], 0);
  }
}

TEST(CliDetect, TextOutputThreadsAndDictionaryNames) {
  test::TempDir dir;
  write_scene(dir.str("scene.png"));
  const auto text = run_arwb("detect " + q(dir.str("scene.png")));
  ASSERT_EQ(text.status, 0);
  EXPECT_NE(text.out.find("2 markers"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("id 7 ARUCO_ORIGINAL"), std::string::npos);
  const auto one = run_arwb("detect --json --threads 1 --dict aruco_original " + q(dir.str("scene.png")));
  const auto two = run_arwb("detect --json --threads 2 --dict DICT_ARUCO_ORIGINAL,4x4_50 " + q(dir.str("scene.png")));
  // The same line but for the time.
  Json a = parse(one.out), b = parse(two.out);
  ASSERT_TRUE(a.contains("ms") && b.contains("ms")) << one.out << two.out;
  a.erase("ms");
  b.erase("ms");
  EXPECT_EQ(a, b);
}

// --resize detects at the workbench's working size; the corners stay in the image's pixels, and the line says the
// size it was detected at.
TEST(CliDetect, ResizeDetectsAtTheWorkingSizeAndGivesTheImagesPixels) {
  test::TempDir dir;
  const auto truth = write_scene(dir.str("scene.png"));
  const auto text = run_arwb("detect --resize 480 " + q(dir.str("scene.png")));
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find(": 2 markers (640x480, detected at 480x360, "), std::string::npos) << text.out;
  const auto r = run_arwb("detect --json --resize 480 " + q(dir.str("scene.png")));
  Json j = parse(r.out);
  EXPECT_EQ(j["width"], 640);
  EXPECT_EQ(j["detected_at"], Json::array({480, 360})) << r.out;
  ASSERT_EQ(j["markers"].size(), 2u) << r.out;
  for (size_t k = 0; k < 2; ++k)
    for (size_t c = 0; c < 4; ++c)
      EXPECT_NEAR(j["markers"][k]["corners"][c][0].get<double>(), truth[k].corners[c].x, 1.0) << k << " " << c;
  const auto bad = run_arwb("detect --resize 9x " + q(dir.str("scene.png")));
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--resize 9x: expected a width W in 16..8192"), std::string::npos) << bad.err;
}

// No marker found, where the quads read as a dictionary not searched: said on stderr in one line, as the Why panel
// says it; nothing is said when the dictionary is given.
TEST(CliDetect, NoMarkerButQuadsOfAnotherDictionaryIsSaid) {
  test::TempDir dir;
  const Dictionary d = *dictionary_by_name("6X6_250");
  cv::Mat img(480, 640, CV_8UC3, cv::Scalar::all(200));
  for (int i = 0; i < 3; ++i) draw_marker(img, d, 200 + i, project_square({120.0 + 200 * i, 240}, 110, 10.0 * i, 0, 0, 800));
  cv::imwrite(dir.str("six.png"), img);
  auto r = run_arwb("detect " + q(dir.str("six.png")));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(": 0 markers"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, dir.str("six.png") + ": 0 markers; 3 quads read as 6X6_250: try --dict 6X6_250\n");
  r = run_arwb("detect --dict 6X6_250 " + q(dir.str("six.png")));
  EXPECT_NE(r.out.find(": 3 markers"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");
}

TEST(CliDetect, FolderInNameOrderAndSynthTruthAgrees) {
  test::TempDir dir;
  const auto s = run_arwb("synth --out " + q(dir.str("set")) + " --count 4 --seed 3 --size 640x480");
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_NE(s.out.find("wrote 4 images"), std::string::npos);
  const auto truth = lines(test::read_file(dir.str("set/truth.jsonl")));
  ASSERT_EQ(truth.size(), 4u);
  const auto r = run_arwb("detect --json " + q(dir.str("set")));
  ASSERT_EQ(r.status, 0);
  const auto out = lines(r.out);
  ASSERT_EQ(out.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    Json found = parse(out[i]), want = parse(truth[i]);
    ASSERT_TRUE(found["source"].is_string()) << out[i];
    EXPECT_NE(found["source"].get<std::string>().find("img_0000" + std::to_string(i) + ".png"), std::string::npos);
    EXPECT_EQ(want["file"], "img_0000" + std::to_string(i) + ".png");
    // Every id in the truth is found.
    ASSERT_TRUE(want["markers"].is_array()) << truth[i];
    for (Json& t : want["markers"])
      EXPECT_TRUE(std::any_of(found["markers"].begin(), found["markers"].end(),
                              [&](Json& m) { return m["id"] == t["id"] && m["dict"] == t["dict"]; }))
          << t << " in " << out[i];
  }
  EXPECT_NE(r.err.find("truth.jsonl: skipped, not an image"), std::string::npos) << r.err;
}

TEST(CliDetect, VideoFramesAndAVideoThatEndsEarly) {
  test::TempDir dir;
  const Dictionary d = make_aruco_original();
  cv::VideoWriter w(dir.str("clip.avi"), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, {320, 240});
  ASSERT_TRUE(w.isOpened());
  cv::RNG rng(1);
  for (int i = 0; i < 12; ++i) {
    cv::Mat f(240, 320, CV_8UC3);
    rng.fill(f, cv::RNG::UNIFORM, 0, 255);  // noise: frames that do not compress away
    cv::rectangle(f, cv::Rect(40 + i * 5, 40, 140, 140), cv::Scalar::all(255), -1);
    const float x = 60.f + 5.f * float(i);
    draw_marker(f, d, 42, Quad{cv::Point2f(x, 60), {x + 100, 60}, {x + 100, 160}, {x, 160}});
    w.write(f);
  }
  w.release();
  auto r = run_arwb("detect --json " + q(dir.str("clip.avi")));
  ASSERT_EQ(r.status, 0) << r.err;
  auto out = lines(r.out);
  ASSERT_EQ(out.size(), 12u);
  for (size_t i = 0; i < 12; ++i) {
    Json j = parse(out[i]);
    EXPECT_EQ(j["frame"], i);
    EXPECT_TRUE(j["markers"].size() == 1 && j["markers"][0]["id"] == 42) << out[i];
  }
  const std::string bytes = test::read_file(dir.str("clip.avi"));
  test::write_file(dir.str("cut.avi"), bytes.substr(0, bytes.size() / 2));
  r = run_arwb("detect --json " + q(dir.str("cut.avi")));
  EXPECT_EQ(r.status, 0);
  out = lines(r.out);
  EXPECT_GT(out.size(), 0u);
  EXPECT_LT(out.size(), 12u);
  EXPECT_NE(r.err.find(dir.str("cut.avi") + ": video ended early"), std::string::npos) << r.err;
}

TEST(CliDetect, EachBadPathGetsOneLineAndTheOthersAreStillProcessed) {
  test::TempDir dir;
  write_scene(dir.str("good.png"));
  test::write_file(dir.str("empty.png"), "");
  const std::string png = test::read_file(dir.str("good.png"));
  test::write_file(dir.str("truncated.png"), png.substr(0, png.size() / 2));
  // A PNG header declaring 60000x60000 pixels and nothing else.
  std::string huge = png.substr(0, 33);
  auto put32 = [&](size_t at, uint32_t v) {
    for (int i = 0; i < 4; ++i) huge[at + size_t(i)] = char((v >> (24 - 8 * i)) & 0xff);
  };
  put32(16, 60000);
  put32(20, 60000);
  test::write_file(dir.str("huge.png"), huge + std::string(64, '\0'));
  test::write_file(dir.str("notes.txt.png"), "just text");
  const std::vector<std::string> bad = {"missing.png", "empty.png", "truncated.png", "huge.png", "notes.txt.png"};
  std::string args = "detect --json";
  // Appended, not " " + q(..): g++ 12 warns falsely (-Wrestrict) on literal + string.
  for (const auto& b : bad) args.append(" ").append(q(dir.str(b)));
  args += " " + q(dir.str("good.png"));
  const auto r = run_arwb(args);
  EXPECT_EQ(r.status, 0) << "one good path processed";
  EXPECT_EQ(lines(r.out).size(), 1u);
  for (const auto& b : bad) {
    int naming = 0;
    for (const auto& l : lines(r.err))
      if (l.rfind(dir.str(b) + ": ", 0) == 0) ++naming;
    EXPECT_EQ(naming, 1) << b << " in:\n" << r.err;
  }
  EXPECT_NE(r.err.find("60000x60000"), std::string::npos);
  EXPECT_NE(r.err.find("empty file"), std::string::npos);

  std::string all_bad = "detect";
  for (const auto& b : bad) all_bad.append(" ").append(q(dir.str(b)));
  const auto none = run_arwb(all_bad);
  EXPECT_EQ(none.status, 1) << "nothing processed";
  EXPECT_TRUE(none.out.empty());
}

TEST(CliDetect, BadOptionsAreNamed) {
  test::TempDir dir;
  write_scene(dir.str("good.png"));
  auto r = run_arwb("detect --dict 9X9_1 " + q(dir.str("good.png")));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("9X9_1"), std::string::npos);
  test::write_file(dir.str("p.yml"), "threshold_offset: [oops\n");
  r = run_arwb("detect --params " + q(dir.str("p.yml")) + " " + q(dir.str("good.png")));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(dir.str("p.yml")), std::string::npos) << r.err;
  test::write_file(dir.str("q.yml"), "threshold_ofset: 3\n");
  r = run_arwb("detect --params " + q(dir.str("q.yml")) + " " + q(dir.str("good.png")));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("threshold_ofset"), std::string::npos) << r.err;
  r = run_arwb("detect --threads 0 " + q(dir.str("good.png")));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--threads"), std::string::npos);
  r = run_arwb("detect --jsn " + q(dir.str("good.png")));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("unknown option --jsn"), std::string::npos);
  r = run_arwb("frobnicate");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("unknown subcommand 'frobnicate'"), std::string::npos);
}

TEST(CliBench, ComparesWithOpenCvAndAprilTagOnTheSameFrames) {
  const auto r = run_arwb("bench --count 9 --reps 1 --json --dict APRILTAG_36h11 --set standard");
  ASSERT_EQ(r.status, 0) << r.err;
  Json j = parse(r.out);
  Json& rows = j["rows"];
  ASSERT_TRUE(rows.is_array()) << r.out;
  auto has = [&](const char* key, const char* value) {
    return std::any_of(rows.begin(), rows.end(), [&](Json& row) { return row[key] == value; });
  };
  for (const char* det : {"arwb", "opencv", "aruco3", "apriltag"}) EXPECT_TRUE(has("detector", det)) << det;
  EXPECT_FALSE(has("resolution", "3840x2160"));  // the standard set only
  for (const char* res : {"640x480", "1920x1080", "all"}) EXPECT_TRUE(has("resolution", res)) << res;
  const auto arwb_all = std::find_if(rows.begin(), rows.end(),
                                     [](Json& row) { return row["resolution"] == "all" && row["detector"] == "arwb"; });
  ASSERT_NE(arwb_all, rows.end()) << r.out;
  for (const char* key : {"time_ratio_opencv", "time_ratio_aruco3", "time_ratio_apriltag", "corner_error_px"})
    EXPECT_TRUE(arwb_all->contains(key)) << key;
  EXPECT_EQ((*arwb_all)["images"], 9);
  EXPECT_TRUE((*arwb_all)["median_ms"].is_number());
  EXPECT_EQ(j["trace_cost_640x480"]["images"], 3);
  EXPECT_EQ(j["not_run"], Json::array()) << "every peer reads APRILTAG_36h11";
  EXPECT_TRUE(j["trace_cost_640x480"].contains("full_over_off"));
  // The figures' record: the processor and the vector code the detector took on it.
  EXPECT_TRUE(j["cpu"].is_string() && !j["cpu"].get<std::string>().empty());
  EXPECT_EQ(j["vector_code"], simd_name(simd()));
  // arwb finds the markers of its own synthetic set.
  const int markers = (*arwb_all)["markers"], found = (*arwb_all)["found"];
  EXPECT_GT(markers, 0);
  EXPECT_GE(found * 10, markers * 9);

  test::TempDir dir;
  ASSERT_EQ(run_arwb("synth --out " + q(dir.str("set")) + " --count 3").status, 0);
  const auto from_dir = run_arwb("bench " + q(dir.str("set")) + " --reps 1");
  EXPECT_EQ(from_dir.status, 0) << from_dir.err;
  EXPECT_NE(from_dir.out.find(" arwb "), std::string::npos) << from_dir.out;   // a row of the table
  // A peer that cannot read the set's dictionary is named; a median of one image is not printed.
  EXPECT_NE(from_dir.out.find("(apriltag not run: AprilTag reads its own families only (APRILTAG_*), not "
                              "ARUCO_ORIGINAL)"), std::string::npos) << from_dir.out;
  EXPECT_NE(from_dir.out.find("trace cost: not measured (1 image at 640x480; a median needs 3)"), std::string::npos)
      << from_dir.out;
  EXPECT_NE(from_dir.out.find(std::string("arwb's vector code: ") + simd_name(simd())), std::string::npos)
      << from_dir.out;
  EXPECT_EQ(run_arwb("bench " + q(dir.str("nowhere"))).status, 1);
}

// The hard set: a row per condition beside the rows per resolution, 4K frames among them; --peers chooses the
// detectors compared, and a wrong name is a usage error naming it.
// arwb bench --video: arwb searching every frame whole and in video mode over the same synthetic sequences, a row
// per resolution and one over all; the marker coming into view at frame 20 to 24 is found within
// full_search_interval frames by video mode, at once by the whole search.
TEST(CliBench, VideoSequencesCompareWholeAndVideoSearch) {
  const auto r = run_arwb("bench --video --count 1 --frames 28 --peers none --dict ARUCO_ORIGINAL --json");
  ASSERT_EQ(r.status, 0) << r.err;
  Json j = parse(r.out);
  EXPECT_EQ(j["full_search_interval"], 5);
  std::set<std::string> resolutions;
  int all_rows = 0;
  for (Json& row : j["rows"]) {
    resolutions.insert(row["resolution"].get<std::string>());
    EXPECT_EQ(row["dictionary"], "ARUCO_ORIGINAL");
    EXPECT_EQ(row["false_positives"], 0) << row.dump();
    EXPECT_GE(row["recall"].get<double>(), 0.95) << row.dump();
    if (row["resolution"] != "all") continue;
    ++all_rows;
    EXPECT_EQ(row["frames"], 4 * 28);
    EXPECT_EQ(row["new_marker_sequences"], 4);
    EXPECT_EQ(row["new_marker_never_found"], 0) << row.dump();
    if (row["detector"] == "arwb") {
      EXPECT_EQ(row["new_marker_frames_max"], 0) << row.dump();
    } else {
      EXPECT_EQ(row["detector"], "arwb-video");
      EXPECT_LE(row["new_marker_frames_max"].get<double>(), 4) << row.dump();
      // A time, so printed by the bench and never asserted here: only that the ratio is there and is a ratio.
      EXPECT_GT(row["median_ratio_arwb"].get<double>(), 0.0) << row.dump();
    }
  }
  EXPECT_EQ(all_rows, 2);
  EXPECT_EQ(resolutions, (std::set<std::string>{"640x480", "1280x720", "1920x1080", "3840x2160", "all"}));
  const auto table = run_arwb("bench --video --count 1 --frames 3 --peers none --dict ARUCO_ORIGINAL");
  ASSERT_EQ(table.status, 0) << table.err;
  EXPECT_NE(table.out.find("\nall        arwb-video "), std::string::npos) << table.out;
  EXPECT_EQ(run_arwb("bench --video --set hard").status, 2);
  EXPECT_EQ(run_arwb("bench --video --pose").status, 2);
}

TEST(CliBench, TheHardSetHasARowPerConditionAndPeersAreChosen) {
  const auto r = run_arwb("bench --count 16 --reps 1 --json --set hard --peers aruco3 --dict ARUCO_ORIGINAL");
  ASSERT_EQ(r.status, 0) << r.err;
  Json j = parse(r.out);
  EXPECT_EQ(j["peers"], Json::array({"aruco3"}));
  std::set<std::string> detectors, resolutions, conditions;
  for (Json& row : j["rows"]) {
    EXPECT_EQ(row["set"], "hard ARUCO_ORIGINAL");
    detectors.insert(row["detector"].get<std::string>());
    resolutions.insert(row["resolution"].get<std::string>());
    if (row.contains("condition")) {
      conditions.insert(row["condition"].get<std::string>());
      EXPECT_EQ(row["resolution"], "all");
      EXPECT_EQ(row["images"], 4);
    }
  }
  EXPECT_EQ(detectors, (std::set<std::string>{"arwb", "aruco3"}));
  EXPECT_EQ(resolutions, (std::set<std::string>{"640x480", "1280x720", "1920x1080", "3840x2160", "all"}));
  EXPECT_EQ(conditions, (std::set<std::string>{"low_contrast", "tiny", "low_light", "crossed"}));

  const auto table = run_arwb("bench --count 3 --reps 1 --set hard --peers none");
  ASSERT_EQ(table.status, 0) << table.err;
  EXPECT_NE(table.out.find("hard ARUCO_ORIGINAL (3 images"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("\nlow_contrast "), std::string::npos) << table.out;
  EXPECT_EQ(table.out.find("opencv"), std::string::npos) << table.out;

  const auto bad = run_arwb("bench --peers opencv,apriltagg");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--peers: unknown peer 'apriltagg'"), std::string::npos) << bad.err;
  EXPECT_EQ(run_arwb("bench --set easy").status, 2);
  test::TempDir dir;
  ASSERT_EQ(run_arwb("synth --out " + q(dir.str("set")) + " --count 2 --set hard").status, 0);
  const auto dir_set = run_arwb("bench " + q(dir.str("set")) + " --set hard");
  EXPECT_EQ(dir_set.status, 2);
  EXPECT_NE(dir_set.err.find("--set"), std::string::npos) << dir_set.err;
  const auto from_dir = run_arwb("bench " + q(dir.str("set")) + " --reps 1 --peers none --json");
  ASSERT_EQ(from_dir.status, 0) << from_dir.err;
  EXPECT_NE(from_dir.out.find("\"condition\":\"low_contrast\""), std::string::npos) << from_dir.out;
}

namespace {

std::string write_camera(const std::string& path, cv::Size size, double f, std::vector<double> distortion) {
  Calibration c;
  c.camera_matrix = cv::Matx33d(f, 0, (size.width - 1) / 2.0, 0, f, (size.height - 1) / 2.0, 0, 0, 1);
  c.distortion = std::move(distortion);
  c.image_size = size;
  const Status st = write_calibration(path, c, {});
  EXPECT_TRUE(st.ok()) << st.error();
  return path;
}

}  // namespace

TEST(CliDetect, ACalibrationAddsEachMarkersCornersWithTheLensDistortionRemoved) {
  test::TempDir dir;
  write_scene(dir.str("scene.png"));
  const std::vector<double> barrel{-0.3, 0.1, 0.001, -0.002, 0};
  write_camera(dir.str("cam.yml"), {640, 480}, 600, barrel);
  const auto r = run_arwb("detect --json --calib " + q(dir.str("cam.yml")) + " " + q(dir.str("scene.png")));
  ASSERT_EQ(r.status, 0) << r.err;
  Json j = parse(lines(r.out).at(0));
  ASSERT_EQ(j["markers"].size(), 2u);
  const cv::Matx33d K(600, 0, 319.5, 0, 600, 239.5, 0, 0, 1);
  for (Json& m : j["markers"]) {
    std::vector<cv::Point2f> corners, expected;
    for (Json& c : m["corners"]) corners.emplace_back(c[0].get<float>(), c[1].get<float>());
    cv::undistortPoints(corners, expected, cv::Mat(K), barrel, cv::noArray(), cv::Mat(K));
    ASSERT_EQ(m["corners_undistorted"].size(), 4u) << m.dump();
    double moved = 0;
    for (size_t k = 0; k < 4; ++k) {
      EXPECT_NEAR(m["corners_undistorted"][k][0].get<double>(), expected[k].x, 0.01);
      EXPECT_NEAR(m["corners_undistorted"][k][1].get<double>(), expected[k].y, 0.01);
      moved += cv::norm(expected[k] - corners[k]);
    }
    EXPECT_GT(moved, 4.0) << "barrel distortion should move corners away from the centre";
  }
  // Without --calib the field is absent: the JSON's documented shape is unchanged.
  const auto plain = run_arwb("detect --json " + q(dir.str("scene.png")));
  EXPECT_EQ(plain.out.find("corners_undistorted"), std::string::npos);
}

TEST(CliDetect, ACalibrationIsScaledToTheSameAspectAndRefusedForAnother) {
  test::TempDir dir;
  write_scene(dir.str("scene.png"));   // 640x480
  // Made at 1280x960 (4:3): the same camera at half the size, focal length and centre halved.
  write_camera(dir.str("big.yml"), {1280, 960}, 1200, {0, 0, 0, 0, 0});
  const auto scaled = run_arwb("detect --json --calib " + q(dir.str("big.yml")) + " " + q(dir.str("scene.png")));
  ASSERT_EQ(scaled.status, 0) << scaled.err;
  Json j = parse(lines(scaled.out).at(0));
  ASSERT_FALSE(j["markers"].empty());
  for (Json& m : j["markers"])   // no distortion: undistorted corners are the corners, at any scale
    for (size_t k = 0; k < 4; ++k)
      EXPECT_NEAR(m["corners_undistorted"][k][0].get<double>(), m["corners"][k][0].get<double>(), 0.01);

  write_camera(dir.str("wide.yml"), {1280, 720}, 1000, {0, 0, 0, 0, 0});
  const auto wide = run_arwb("detect --json --calib " + q(dir.str("wide.yml")) + " " + q(dir.str("scene.png")));
  EXPECT_EQ(wide.status, 1) << "no frame could be processed";
  EXPECT_EQ(lines(wide.err).size(), 1u) << wide.err;
  EXPECT_NE(wide.err.find("made for 1280x720 (16:9), the source is 640x480 (4:3)"), std::string::npos) << wide.err;
  EXPECT_NE(wide.err.find(dir.str("scene.png")), std::string::npos) << wide.err;
}

TEST(CliDetect, ABadCalibrationFileIsNamedWithItsKey) {
  test::TempDir dir;
  write_scene(dir.str("scene.png"));
  test::write_file(dir.str("bad.yml"), "%YAML:1.0\n---\ncamera_matrix: !!opencv-matrix\n  rows: 2\n  cols: 3\n"
                                       "  dt: d\n  data: [1, 0, 0, 0, 1, 0]\n");
  const auto r = run_arwb("detect --calib " + q(dir.str("bad.yml")) + " " + q(dir.str("scene.png")));
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
  EXPECT_NE(r.err.find("--calib " + dir.str("bad.yml") + ": camera_matrix"), std::string::npos) << r.err;
  const auto missing = run_arwb("detect --calib " + q(dir.str("none.yml")) + " " + q(dir.str("scene.png")));
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find(dir.str("none.yml")), std::string::npos) << missing.err;
}
