// `arwb detect`, `arwb synth` and `arwb bench` run as a user runs them: the JSON line checked field by field
// against a synthetic set's truth, folders, videos, and every kind of bad input named in one line.
#include "detect/dictionary.hpp"
#include "synth/synth.hpp"
#include "support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <filesystem>
#include <regex>
#include <sstream>

using namespace arwb;
using test::run_arwb;

namespace {

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string l; std::getline(ss, l);)
    if (!l.empty()) out.push_back(l);
  return out;
}

std::string q(const std::string& s) { return "'" + s + "'"; }

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
  const std::string num = "(-?[0-9]+(?:\\.[0-9]+)?)";
  const std::string pt = "\\[" + num + "," + num + "\\]";
  const std::string marker = "\\{\"id\":([0-9]+),\"dict\":\"([A-Z0-9_a-z]+)\",\"corners\":\\[" + pt + "," + pt + "," +
                             pt + "," + pt + "\\],\"hamming\":([0-9]+)\\}";
  const std::regex line("^\\{\"source\":\"([^\"]+)\",\"frame\":0,\"width\":640,\"height\":480,\"ms\":" + num +
                        ",\"markers\":\\[" + marker + "," + marker + "\\]\\}$");
  std::smatch m;
  ASSERT_TRUE(std::regex_match(out[0], m, line)) << out[0];
  EXPECT_EQ(m[1].str(), dir.str("scene.png"));
  EXPECT_GT(std::stod(m[2].str()), 0.0);  // ms
  for (int k = 0; k < 2; ++k) {
    const int base = 3 + k * 11;
    EXPECT_EQ(std::stoi(m[size_t(base)].str()), truth[size_t(k)].id);  // sorted by id
    EXPECT_EQ(m[size_t(base + 1)].str(), "ARUCO_ORIGINAL");
    for (int c = 0; c < 4; ++c) {
      const double x = std::stod(m[size_t(base + 2 + 2 * c)].str()), y = std::stod(m[size_t(base + 3 + 2 * c)].str());
      EXPECT_NEAR(x, truth[size_t(k)].corners[size_t(c)].x, 0.3) << "marker " << k << " corner " << c;
      EXPECT_NEAR(y, truth[size_t(k)].corners[size_t(c)].y, 0.3) << "marker " << k << " corner " << c;
    }
    EXPECT_EQ(m[size_t(base + 10)].str(), "0");
  }
}

TEST(CliDetect, TextOutputThreadsAndDictionaryNames) {
  test::TempDir dir;
  write_scene(dir.str("scene.png"));
  const auto text = run_arwb("detect " + q(dir.str("scene.png")));
  ASSERT_EQ(text.status, 0);
  EXPECT_NE(text.out.find("2 markers"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("id 7 ARUCO_ORIGINAL"), std::string::npos);
  const std::regex ms("\"ms\":[0-9.]+");
  const auto one = run_arwb("detect --json --threads 1 --dict aruco_original " + q(dir.str("scene.png")));
  const auto two = run_arwb("detect --json --threads 2 --dict DICT_ARUCO_ORIGINAL,4x4_50 " + q(dir.str("scene.png")));
  EXPECT_EQ(std::regex_replace(one.out, ms, ""), std::regex_replace(two.out, ms, ""));
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
  const std::regex id_re("\"id\":([0-9]+)");
  for (int i = 0; i < 4; ++i) {
    EXPECT_NE(out[size_t(i)].find("img_0000" + std::to_string(i) + ".png"), std::string::npos);
    // Every id in the truth is found.
    for (std::sregex_iterator it(truth[size_t(i)].begin(), truth[size_t(i)].end(), id_re), end; it != end; ++it)
      EXPECT_NE(out[size_t(i)].find("\"id\":" + (*it)[1].str() + ","), std::string::npos) << out[size_t(i)];
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
  for (int i = 0; i < 12; ++i) {
    EXPECT_NE(out[size_t(i)].find("\"frame\":" + std::to_string(i) + ","), std::string::npos);
    EXPECT_NE(out[size_t(i)].find("\"id\":42,"), std::string::npos) << out[size_t(i)];
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
  for (const auto& b : bad) args += " " + q(dir.str(b));
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
  for (const auto& b : bad) all_bad += " " + q(dir.str(b));
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
  const auto r = run_arwb("bench --count 6 --reps 1 --json --dict APRILTAG_36h11");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* det : {"\"detector\":\"arwb\"", "\"detector\":\"opencv\"", "\"detector\":\"apriltag\"",
                          "\"resolution\":\"640x480\"", "\"resolution\":\"1920x1080\"", "\"resolution\":\"all\"",
                          "\"time_ratio_opencv\":", "\"time_ratio_apriltag\":", "\"corner_error_px\":",
                          "\"trace_cost_640x480\":{\"images\":2,", "\"full_over_off\":"})
    EXPECT_NE(r.out.find(det), std::string::npos) << det;
  // arwb finds the markers of its own synthetic set.
  const std::regex arwb_all("\"resolution\":\"all\",\"detector\":\"arwb\",\"images\":6,\"median_ms\":[0-9.]+,"
                            "\"markers\":([0-9]+),\"found\":([0-9]+)");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, arwb_all)) << r.out;
  EXPECT_GT(std::stoi(m[1].str()), 0);
  EXPECT_GE(std::stoi(m[2].str()) * 10, std::stoi(m[1].str()) * 9);

  test::TempDir dir;
  ASSERT_EQ(run_arwb("synth --out " + q(dir.str("set")) + " --count 3").status, 0);
  const auto from_dir = run_arwb("bench " + q(dir.str("set")) + " --reps 1");
  EXPECT_EQ(from_dir.status, 0) << from_dir.err;
  EXPECT_NE(from_dir.out.find("arwb"), std::string::npos);
  EXPECT_EQ(run_arwb("bench " + q(dir.str("nowhere"))).status, 1);
}
