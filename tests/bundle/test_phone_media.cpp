// With --web, the scene's media as a phone's browser sees them: what it would not show or play is named in a
// warning, or with --convert-for-phones copied into what it does (pictures as PNG, videos as MP4/H.264 by ffmpeg),
// beside the original, listed in the manifest's phone_media. The videos here are made by Debian's ffmpeg.
#include "bundle_fixture.hpp"

#include "base/process.hpp"
#include "bundle/bundle_files.hpp"
#include "capture/image_header.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <cstdlib>
#include <string>
#include <vector>

namespace arwb::bundle {
namespace {

using namespace fixture;
using arwb::test::read_file;
using arwb::test::write_file;

const std::string kOrbit = (kScripts / "museum/media/orbit.mp4").string();

// `out` made from the museum's clip (2 s) by ffmpeg with these output options.
void make_video(const fs::path& out, std::vector<std::string> options) {
  std::vector<std::string> argv = {"ffmpeg", "-nostdin", "-v", "error", "-y", "-i", kOrbit, "-t", "2"};
  argv.insert(argv.end(), options.begin(), options.end());
  argv.push_back(out.string());
  Result<ProcessResult> r = run_program(argv);
  ASSERT_TRUE(r.ok()) << r.error();
  ASSERT_EQ(r->exit_status, 0) << r->output;
}

int frame_count(const std::string& video) {
  cv::VideoCapture v(video, cv::CAP_FFMPEG);
  int n = 0;
  for (cv::Mat f; v.read(f);) ++n;
  return n;
}

// A stand-in for the phone player's site: only its presence matters here.
std::string fake_site(const fs::path& dir) {
  for (const char* f : {"index.html", "sw.js", "web/arwb_core.wasm"}) {
    fs::create_directories((dir / f).parent_path());
    write_file((dir / f).string(), f);
  }
  return dir.string();
}

TEST(PhoneMedia, SaysWhatAPhonesBrowserWouldNotShowOrPlay) {
  test::TempDir tmp;
  const fs::path d = tmp.path();
  const cv::Mat picture(48, 64, CV_8UC3, cv::Scalar(40, 90, 200));
  for (const char* name : {"a.png", "a.jpg", "a.webp", "a.bmp", "a.tif"}) ASSERT_TRUE(cv::imwrite((d / name).string(), picture));
  ASSERT_TRUE(cv::imwrite((d / "a.pgm").string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(90))));
  cv::imwrite((d / "wide.png").string(), cv::Mat(8, kPhoneMaxImageSide + 1, CV_8UC3, cv::Scalar(0)));
  for (const char* fine : {"a.png", "a.jpg", "a.webp", "a.bmp"}) EXPECT_EQ(phone_problem((d / fine).string()), "") << fine;
  EXPECT_EQ(phone_problem((d / "a.tif").string()), "a TIFF picture: phones' browsers show PNG, JPEG and WebP");
  EXPECT_EQ(phone_problem((d / "a.pgm").string()), "a PGM picture: phones' browsers show PNG, JPEG and WebP");
  EXPECT_EQ(phone_problem((d / "wide.png").string()),
            "a 4097x8 picture: many phones draw at most 4096 pixels a side");

  EXPECT_EQ(phone_problem(kOrbit), "") << "H.264 4:2:0 in MP4";
  make_video(d / "part2.avi", {"-c:v", "mpeg4"});
  make_video(d / "part2.mp4", {"-c:v", "mpeg4"});
  make_video(d / "full.mp4", {"-c:v", "libx264", "-pix_fmt", "yuv444p"});
  make_video(d / "vp8.webm", {"-c:v", "libvpx"});
  EXPECT_EQ(phone_problem((d / "part2.avi").string()), "not an MP4 file (FMP4): phones' browsers play MP4 with H.264");
  EXPECT_EQ(phone_problem((d / "part2.mp4").string()), "an MP4 file in mp4v: phones' browsers play H.264");
  EXPECT_EQ(phone_problem((d / "full.mp4").string()), "H.264 in 444P: phones' browsers play 8-bit 4:2:0 (yuv420p)");
  EXPECT_EQ(phone_problem((d / "vp8.webm").string()), "not an MP4 file: phones' browsers play MP4 with H.264");
  write_file((d / "scene.lua").string(), "marker(0, {})\n");
  EXPECT_EQ(phone_problem((d / "scene.lua").string()), "") << "not a picture or video";
}

// A scene with a TIFF and an AVI: named in warnings, or converted; the desktop keeps the originals either way.
class PhoneExport : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(dir_ / "media");
    make_video(dir_ / "media/clip.avi", {"-c:v", "mpeg4"});
    picture_ = cv::Mat(120, 160, CV_8UC3);
    cv::randu(picture_, 0, 255);
    cv::imwrite((dir_ / "media/pic.tif").string(), picture_);
    write_file((dir_ / "scene.lua").string(), "marker(0, { media = video \"media/clip.avi\" })\n"
                                              "marker(1, { media = image \"media/pic.tif\" })\n");
    options_.scene = (dir_ / "scene.lua").string();
    options_.web_site = fake_site(tmp_.path() / "site");
  }
  test::TempDir tmp_;
  const fs::path dir_ = tmp_.path() / "author";
  cv::Mat picture_;
  ExportOptions options_;
};

TEST_F(PhoneExport, WithoutConvertingTheFilesAreNamedInWarnings) {
  options_.out = (tmp_.path() / "plain").string();
  Result<ExportPlan> plan = plan_export(options_);
  ASSERT_TRUE(plan.ok()) << plan.error();
  std::vector<std::string> phone;
  for (const std::string& w : plan->warnings)
    if (w.find("phones") != std::string::npos) phone.push_back(w);
  EXPECT_EQ(phone, (std::vector<std::string>{
                       "scene/media/clip.avi: not an MP4 file (FMP4): phones' browsers play MP4 with H.264; "
                       "--convert-for-phones makes a copy they play",
                       "scene/media/pic.tif: a TIFF picture: phones' browsers show PNG, JPEG and WebP; "
                       "--convert-for-phones makes a copy they play"}));
  EXPECT_TRUE(plan->manifest.phone_media.empty());

  // Without --web nothing is said: the desktop plays both.
  options_.web_site.clear();
  plan = plan_export(options_);
  ASSERT_TRUE(plan.ok()) << plan.error();
  for (const std::string& w : plan->warnings) EXPECT_EQ(w.find("phones"), std::string::npos) << w;
}

TEST_F(PhoneExport, ConvertedCopiesPlayOnPhonesAndShowTheSamePictures) {
  options_.out = (tmp_.path() / "converted").string();
  options_.convert_for_phones = true;
  Result<ExportPlan> plan = plan_export(options_);
  ASSERT_TRUE(plan.ok()) << plan.error();
  ASSERT_TRUE(write_export(*plan).ok());
  const fs::path out = options_.out;
  const std::vector<PhoneCopy>& copies = plan->manifest.phone_media;
  ASSERT_EQ(copies.size(), 2u);
  EXPECT_EQ(copies[0].path, "scene/media/clip.avi");
  EXPECT_EQ(copies[0].phone, "web/phone/scene/media/clip.avi.mp4");
  EXPECT_EQ(copies[1].path, "scene/media/pic.tif");
  EXPECT_EQ(copies[1].phone, "web/phone/scene/media/pic.tif.png");
  for (const PhoneCopy& c : copies) EXPECT_EQ(phone_problem((out / c.phone).string()), "") << c.phone;
  // The same frames (ffmpeg keeps every one) and the same pixels.
  EXPECT_EQ(frame_count((out / copies[0].phone).string()), frame_count((out / copies[0].path).string()));
  const cv::Mat png = cv::imread((out / copies[1].phone).string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(png.size(), picture_.size());
  EXPECT_EQ(cv::norm(png, picture_, cv::NORM_INF), 0);
  // The originals stay for the desktop, and the copies are the web's, listed in the manifest that opens.
  EXPECT_TRUE(fs::is_regular_file(out / "scene/media/clip.avi"));
  PrivateTmp private_tmp;
  Result<OpenedBundle> opened = open_bundle(out.string());
  ASSERT_TRUE(opened.ok()) << opened.error();
  EXPECT_EQ(opened->manifest().phone_media.size(), 2u);
  for (const BundleFile& f : opened->manifest().files) {
    if (f.path.rfind("web/phone/", 0) == 0) {
      EXPECT_EQ(f.role, "web") << f.path;
    }
  }

  // A manifest whose phone copy is not among its files is refused, naming the field.
  std::string text = read_file((out / "manifest.json").string());
  const std::string from = "\"phone\": \"web/phone/scene/media/pic.tif.png\"";
  ASSERT_NE(text.find(from), std::string::npos) << text;
  text.replace(text.find(from), from.size(), "\"phone\": \"web/phone/elsewhere.png\"");
  EXPECT_EQ(parse_manifest(text).error(),
            "manifest.json: phone_media[1].phone: \"web/phone/elsewhere.png\" is not among files");
}

TEST_F(PhoneExport, ConvertingWithoutFfmpegSaysSoAndWritesNothing) {
  options_.out = (tmp_.path() / "no-ffmpeg").string();
  options_.convert_for_phones = true;
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", tmp_.str("empty").c_str(), 1);
  Result<ExportPlan> plan = plan_export(options_);
  ::setenv("PATH", path.c_str(), 1);
  EXPECT_EQ(plan.error(), "--convert-for-phones: ffmpeg is not installed (not found on PATH) (Debian: apt install ffmpeg)");
  EXPECT_FALSE(fs::exists(options_.out));
}

}  // namespace
}  // namespace arwb::bundle
