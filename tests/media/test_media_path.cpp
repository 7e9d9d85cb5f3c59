// check_media_path, check_url and url_host: what a scene may name, and the messages for what it may not.
#include "media/media_path.hpp"
#include "support/png.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sys/stat.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using arwb::media::check_media_path;
using arwb::media::check_url;
using arwb::media::MediaFileKind;
using arwb::media::url_host;
using arwb::test::png_declaring;
using arwb::test::TempDir;
using arwb::test::write_file;

namespace {

void write_png(const std::string& path, int w, int h) {
  ASSERT_TRUE(cv::imwrite(path, cv::Mat(h, w, CV_8UC3, cv::Scalar(10, 20, 30))));
}

void write_video(const std::string& path, int fourcc) {
  cv::VideoWriter w(path, cv::CAP_FFMPEG, fourcc, 10, cv::Size(64, 48));
  ASSERT_TRUE(w.isOpened()) << path;
  for (int i = 0; i < 5; ++i) w.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(40 * i)));
}

class MediaPath : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(scene / "media");
    write_png((scene / "media/painting.png").string(), 40, 30);
  }
  TempDir tmp;
  fs::path scene = tmp.path() / "scene";
};

}  // namespace

TEST_F(MediaPath, AcceptsAnImageInsideTheFolderWithItsHeaderSize) {
  const auto c = check_media_path(scene, "media/painting.png");
  ASSERT_TRUE(c.ok()) << c.error;
  EXPECT_EQ(c.kind, MediaFileKind::image);
  EXPECT_EQ(c.size, cv::Size(40, 30));
  EXPECT_EQ(c.format, "PNG");
  EXPECT_EQ(c.path, fs::canonical(scene / "media/painting.png").string());
  EXPECT_TRUE(fs::path(c.path).is_absolute());
}

TEST_F(MediaPath, AcceptsJpegAndDotComponents) {
  ASSERT_TRUE(cv::imwrite((scene / "photo.jpg").string(), cv::Mat(24, 32, CV_8UC3, cv::Scalar(1, 2, 3))));
  const auto c = check_media_path(scene, "./photo.jpg");
  ASSERT_TRUE(c.ok()) << c.error;
  EXPECT_EQ(c.format, "JPEG");
  EXPECT_EQ(c.size, cv::Size(32, 24));
  EXPECT_EQ(c.path, fs::canonical(scene / "photo.jpg").string());
}

TEST_F(MediaPath, RecognisesVideosByTheirBytesNotTheirNames) {
  write_video((scene / "clip.avi").string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'));
  write_video((scene / "clip.mp4").string(), cv::VideoWriter::fourcc('m', 'p', '4', 'v'));
  fs::copy_file(scene / "clip.mp4", scene / "disguised.png");

  const auto avi = check_media_path(scene, "clip.avi");
  ASSERT_TRUE(avi.ok()) << avi.error;
  EXPECT_EQ(avi.kind, MediaFileKind::video);
  EXPECT_EQ(avi.format, "AVI");
  const auto mp4 = check_media_path(scene, "clip.mp4");
  ASSERT_TRUE(mp4.ok()) << mp4.error;
  EXPECT_EQ(mp4.kind, MediaFileKind::video);
  EXPECT_EQ(mp4.format, "MP4/MOV");
  const auto disguised = check_media_path(scene, "disguised.png");
  ASSERT_TRUE(disguised.ok()) << disguised.error;
  EXPECT_EQ(disguised.kind, MediaFileKind::video);
}

TEST_F(MediaPath, RefusesParentComponentsEvenWhenTheTargetExists) {
  write_png((tmp.path() / "x.png").string(), 8, 8);  // really there, one level up
  EXPECT_EQ(check_media_path(scene, "../x.png").error, "../x.png: leaves the scene's folder");
  EXPECT_EQ(check_media_path(scene, "a/../../x.png").error, "a/../../x.png: leaves the scene's folder");
  EXPECT_EQ(check_media_path(scene, "media/../../x.png").error, "media/../../x.png: leaves the scene's folder");
  // Any "..", even one that would come back inside: the rule is simple to state and to check.
  EXPECT_EQ(check_media_path(scene, "media/../media/painting.png").error,
            "media/../media/painting.png: leaves the scene's folder");
  EXPECT_TRUE(check_media_path(scene, "../x.png").path.empty());
}

TEST_F(MediaPath, DecidesTraversalAndAbsolutePathsBeforeTheFileSystem) {
  // The scene's folder does not exist: these must be refused from the text alone, not for a missing folder.
  const fs::path nowhere = tmp.path() / "no" / "such" / "folder";
  EXPECT_EQ(check_media_path(nowhere, "../x.png").error, "../x.png: leaves the scene's folder");
  EXPECT_EQ(check_media_path(nowhere, "/etc/passwd").error, "/etc/passwd: absolute paths are not allowed");
  EXPECT_NE(check_media_path(nowhere, "x.png").error.find("cannot be resolved"), std::string::npos);
}

TEST_F(MediaPath, RefusesAbsolutePaths) {
  EXPECT_EQ(check_media_path(scene, "/etc/passwd").error, "/etc/passwd: absolute paths are not allowed");
  EXPECT_EQ(check_media_path(scene, "/dev/zero").error, "/dev/zero: absolute paths are not allowed");
  // Even one naming a file inside the folder.
  const std::string inside = fs::canonical(scene / "media/painting.png").string();
  EXPECT_EQ(check_media_path(scene, inside).error, inside + ": absolute paths are not allowed");
}

TEST_F(MediaPath, RefusesSymbolicLinksLeadingOut) {
  write_png((tmp.path() / "outside.png").string(), 8, 8);
  fs::create_symlink(tmp.path() / "outside.png", scene / "link.png");
  EXPECT_EQ(check_media_path(scene, "link.png").error, "link.png: leaves the scene's folder");

  fs::create_directories(tmp.path() / "elsewhere");
  write_png((tmp.path() / "elsewhere/inner.png").string(), 8, 8);
  fs::create_directory_symlink(tmp.path() / "elsewhere", scene / "linked_dir");
  EXPECT_EQ(check_media_path(scene, "linked_dir/inner.png").error, "linked_dir/inner.png: leaves the scene's folder");

  // A relative link climbing out is no different.
  fs::create_symlink("../outside.png", scene / "relative_link.png");
  EXPECT_EQ(check_media_path(scene, "relative_link.png").error, "relative_link.png: leaves the scene's folder");

  // A sibling folder whose name starts like the scene's is still outside.
  fs::create_directories(tmp.path() / "scene2");
  write_png((tmp.path() / "scene2/p.png").string(), 8, 8);
  fs::create_symlink(tmp.path() / "scene2/p.png", scene / "sibling.png");
  EXPECT_EQ(check_media_path(scene, "sibling.png").error, "sibling.png: leaves the scene's folder");
}

TEST_F(MediaPath, FollowsSymbolicLinksThatStayInside) {
  fs::create_symlink("media/painting.png", scene / "alias.png");
  const auto c = check_media_path(scene, "alias.png");
  ASSERT_TRUE(c.ok()) << c.error;
  EXPECT_EQ(c.path, fs::canonical(scene / "media/painting.png").string());
}

TEST_F(MediaPath, WorksWhenTheSceneFolderItselfIsReachedThroughALink) {
  fs::create_directory_symlink(scene, tmp.path() / "scene_link");
  const auto c = check_media_path(tmp.path() / "scene_link", "media/painting.png");
  ASSERT_TRUE(c.ok()) << c.error;
  EXPECT_EQ(c.path, fs::canonical(scene / "media/painting.png").string());
}

TEST_F(MediaPath, RefusesDevicesReachedThroughLinks) {
  fs::create_symlink("/dev/zero", scene / "zero.png");
  EXPECT_EQ(check_media_path(scene, "zero.png").error, "zero.png: leaves the scene's folder");
}

TEST_F(MediaPath, RefusesFifosWithoutOpeningThem) {
  // Opening a FIFO with no writer blocks: this test hangs if the check reads it.
  ASSERT_EQ(::mkfifo((scene / "media/fifo").c_str(), 0600), 0);
  EXPECT_EQ(check_media_path(scene, "media/fifo").error, "media/fifo: not a regular file (FIFO)");
}

TEST_F(MediaPath, RefusesFolders) {
  EXPECT_EQ(check_media_path(scene, "media").error, "media: not a regular file (folder)");
  EXPECT_EQ(check_media_path(scene, "media/").error, "media/: not a regular file (folder)");
  EXPECT_EQ(check_media_path(scene, ".").error, ".: not a regular file (folder)");
}

TEST_F(MediaPath, RefusesWhatIsNotAnImageOrVideo) {
  write_file((scene / "media/notes.png").string(), "just some text, named like a picture\n");
  EXPECT_EQ(check_media_path(scene, "media/notes.png").error, "media/notes.png: not an image or video");
  write_file((scene / "media/notes.txt").string(), "plain text\n");
  EXPECT_EQ(check_media_path(scene, "media/notes.txt").error, "media/notes.txt: not an image or video");
  write_file((scene / "media/empty.png").string(), "");
  EXPECT_EQ(check_media_path(scene, "media/empty.png").error, "media/empty.png: empty file (0 bytes)");
  write_file((scene / "anim.gif").string(), std::string("GIF89a\x01\x00\x01\x00\x00\x00\x00;", 13));
  EXPECT_EQ(check_media_path(scene, "anim.gif").error, "anim.gif: unsupported image format (GIF)");
}

TEST_F(MediaPath, RefusesMissingFiles) {
  EXPECT_EQ(check_media_path(scene, "media/x.png").error, "media/x.png: no such file");
  EXPECT_EQ(check_media_path(scene, "nope/x.png").error, "nope/x.png: no such file");
  fs::create_symlink("gone.png", scene / "dangling.png");
  EXPECT_EQ(check_media_path(scene, "dangling.png").error, "dangling.png: no such file");
  EXPECT_FALSE(check_media_path(scene, "").ok());
}

TEST_F(MediaPath, RefusesHugeImagesFromTheHeaderAlone) {
  // 60000 x 60000 x 3 bytes would be 10 GB: refused on the 33 bytes of its IHDR.
  write_file((scene / "media/huge.png").string(), png_declaring(60000, 60000));
  EXPECT_EQ(check_media_path(scene, "media/huge.png").error,
            "media/huge.png: declares 60000x60000 pixels, more than 40000000");
  // Few pixels, but one side past kMaxImageSide.
  write_file((scene / "media/long.png").string(), png_declaring(40000, 16));
  EXPECT_EQ(check_media_path(scene, "media/long.png").error,
            "media/long.png: declares 40000x16 pixels, a side longer than 32768");
  // Just within both limits: accepted on its header (its pixels are not decoded here).
  write_file((scene / "media/big.png").string(), png_declaring(8000, 5000));
  const auto big = check_media_path(scene, "media/big.png");
  ASSERT_TRUE(big.ok()) << big.error;
  EXPECT_EQ(big.size, cv::Size(8000, 5000));
}

TEST_F(MediaPath, ShowsControlCharactersInNamesAsQuestionMarks) {
  const std::string error = check_media_path(scene, "bad\nname.png").error;
  EXPECT_EQ(error, "bad?name.png: no such file");
}

TEST(Url, AcceptsHttpAndHttps) {
  EXPECT_EQ(check_url("https://opencv.org/releases"), "");
  EXPECT_EQ(check_url("http://example.com"), "");
  EXPECT_EQ(check_url("HTTPS://EXAMPLE.COM/A"), "");
  EXPECT_EQ(check_url("HtTp://example.com:8080/x?y=1#z"), "");
  EXPECT_EQ(check_url("http://[::1]:8080/"), "");
  EXPECT_EQ(check_url("https://example.com/a;b?c=$(id)&d='e'\"f\"%20g"), "");
}

TEST(Url, RefusesOtherSchemes) {
  EXPECT_EQ(check_url("ftp://x"), "ftp://x: only http and https links are opened");
  EXPECT_EQ(check_url("javascript:alert(1)"), "javascript:alert(1): only http and https links are opened");
  EXPECT_EQ(check_url("file:///etc/passwd"), "file:///etc/passwd: only http and https links are opened");
  EXPECT_EQ(check_url("httpx://example.com"), "httpx://example.com: only http and https links are opened");
  EXPECT_EQ(check_url("example.com"), "example.com: only http and https links are opened");
  EXPECT_EQ(check_url("http:example.com"), "http:example.com: only http and https links are opened");
  EXPECT_FALSE(check_url("").empty());
  EXPECT_FALSE(check_url("-https://example.com").empty());
}

TEST(Url, RefusesMissingHostsSpacesAndControlCharacters) {
  EXPECT_EQ(check_url("https://"), "https://: no host");
  EXPECT_EQ(check_url("https:///path"), "https:///path: no host");
  EXPECT_EQ(check_url("https://user@/x"), "https://user@/x: no host");
  EXPECT_EQ(check_url("https://a b"), "https://a b: contains spaces or control characters");
  EXPECT_EQ(check_url("https://a\nb"), "https://a?b: contains spaces or control characters");
  EXPECT_EQ(check_url(std::string("https://a\0b", 11)), "https://a?b: contains spaces or control characters");
  EXPECT_EQ(check_url("https://a\x7f"), "https://a?: contains spaces or control characters");
  EXPECT_EQ(check_url("https://host:80x/"), "https://host:80x/: invalid port");
}

TEST(Url, LimitsTheLength) {
  const std::string base = "https://example.com/";
  const std::string longest = base + std::string(2048 - base.size(), 'a');
  EXPECT_EQ(check_url(longest), "");
  const std::string error = check_url(longest + "a");
  EXPECT_NE(error.find(": longer than 2048 characters"), std::string::npos) << error;
  EXPECT_LT(error.size(), 200u);  // the message does not repeat the whole URL
}

TEST(Url, HostIsTheAuthorityWithoutUserPortOrPath) {
  EXPECT_EQ(url_host("https://opencv.org/releases"), "opencv.org");
  EXPECT_EQ(url_host("HTTP://Example.com"), "Example.com");
  EXPECT_EQ(url_host("https://user:pw@host.example:8443/p?q#f"), "host.example");
  EXPECT_EQ(url_host("https://bank.example@evil.example/"), "evil.example");
  EXPECT_EQ(url_host("https://h?x=/y"), "h");
  EXPECT_EQ(url_host("https://h#frag"), "h");
  EXPECT_EQ(url_host("http://[::1]:8080/"), "[::1]");
  EXPECT_EQ(url_host("ftp://x/y"), "");
  EXPECT_EQ(url_host("javascript:alert(1)"), "");
  EXPECT_EQ(url_host("https://"), "");
  EXPECT_EQ(url_host("not a url"), "");
}

// A browser reads a backslash in an http(s) URL as a slash, so the host it opens ends there: the card's title
// (url_host) must name that host, not the text after a later '@' (found by fuzz/url.cpp; the input is
// fuzz/regressions/url/backslash_userinfo_spoof).
TEST(Url, HostEndsAtABackslashAsInABrowser) {
  EXPECT_EQ(url_host("https://evil.example\\@good.example/"), "evil.example");
  EXPECT_EQ(url_host("http://ex%2\\hpexample.comG0"), "ex%2");
  EXPECT_EQ(url_host("https://h\\x"), "h");
}
