// Tests for capture/image_io: recognising, checking and loading image files a user names. Every input is made here:
// images are encoded with cv::imencode, bad files are crafted from their bytes.
#include "capture/image_io.hpp"
#include "support/png.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <sys/stat.h>

namespace arwb {
namespace {

using test::png_chunk;
using test::png_declaring;
using test::read_file;
using test::TempDir;
using test::write_file;

// A smooth colour picture (JPEG keeps it close), distinct in every channel so a flipped or swapped image shows.
cv::Mat picture(int width, int height) {
  cv::Mat m(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      m.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(x * 255 / width), static_cast<uchar>(y * 255 / height),
                                        static_cast<uchar>((x + 2 * y) % 256));
  return m;
}

std::string encode(const std::string& ext, const cv::Mat& image, const std::vector<int>& params = {}) {
  std::vector<uchar> buf;
  EXPECT_TRUE(cv::imencode(ext, image, buf, params)) << ext;
  return std::string(buf.begin(), buf.end());
}

// The bytes of a string literal, embedded NULs included (without the terminating one).
template <size_t N>
std::string bytes(const char (&literal)[N]) {
  return std::string(literal, N - 1);
}

// The JPEG with the dimensions in its frame header (SOF0, as cv::imencode writes baseline JPEG) replaced.
std::string with_jpeg_size(std::string jpeg, uint16_t width, uint16_t height) {
  size_t pos = 2;  // after SOI; imencode writes segments back to back
  while (pos + 9 < jpeg.size()) {
    const auto marker = static_cast<uint8_t>(jpeg[pos + 1]);
    const size_t length = static_cast<size_t>(static_cast<uint8_t>(jpeg[pos + 2]) << 8 | static_cast<uint8_t>(jpeg[pos + 3]));
    if (marker == 0xC0) {
      jpeg[pos + 5] = static_cast<char>(height >> 8);
      jpeg[pos + 6] = static_cast<char>(height);
      jpeg[pos + 7] = static_cast<char>(width >> 8);
      jpeg[pos + 8] = static_cast<char>(width);
      return jpeg;
    }
    pos += 2 + length;
  }
  ADD_FAILURE() << "no SOF0 in the encoded JPEG";
  return jpeg;
}

// Records the largest cv::Mat allocation while it exists, so a test can show that no pixel memory was taken.
class MatAllocationRecorder : public cv::MatAllocator {
 public:
  MatAllocationRecorder() : inner_(cv::Mat::getDefaultAllocator()) { cv::Mat::setDefaultAllocator(this); }
  ~MatAllocationRecorder() override { cv::Mat::setDefaultAllocator(inner_); }
  MatAllocationRecorder(const MatAllocationRecorder&) = delete;
  MatAllocationRecorder& operator=(const MatAllocationRecorder&) = delete;

  size_t largest() const { return largest_; }

  cv::UMatData* allocate(int dims, const int* sizes, int type, void* data, size_t* step, cv::AccessFlag flags,
                         cv::UMatUsageFlags usage) const override {
    if (!data) {
      size_t bytes = static_cast<size_t>(CV_ELEM_SIZE(type));
      for (int i = 0; i < dims; ++i) bytes *= static_cast<size_t>(sizes[i]);
      largest_ = std::max(largest_, bytes);
    }
    return inner_->allocate(dims, sizes, type, data, step, flags, usage);
  }
  bool allocate(cv::UMatData* data, cv::AccessFlag flags, cv::UMatUsageFlags usage) const override {
    return inner_->allocate(data, flags, usage);
  }
  void deallocate(cv::UMatData* data) const override { inner_->deallocate(data); }

 private:
  cv::MatAllocator* inner_;
  mutable size_t largest_ = 0;
};

// A failed load: no image, and one line "<path>: <reason>..." (the reason may go on with details).
void expect_failure(const LoadedImage& r, const std::string& path, const std::string& reason) {
  EXPECT_FALSE(r.ok()) << path;
  EXPECT_TRUE(r.image.empty()) << path;
  EXPECT_TRUE(r.error.rfind(path + ": " + reason, 0) == 0) << "expected \"" << path << ": " << reason
                                                            << "...\", got \"" << r.error << "\"";
  EXPECT_EQ(r.error.find('\n'), std::string::npos) << r.error;
}

double mean_abs_diff(const cv::Mat& a, const cv::Mat& b) {
  return cv::norm(a, b, cv::NORM_L1) / static_cast<double>(a.total() * static_cast<size_t>(a.channels()));
}

// ---------------------------------------------------------------------------------------------------------------
// Valid images

struct FormatCase {
  const char* file;
  const char* ext;
  const char* format;  // as read_image_header names it
  std::vector<int> params;
  bool gray;           // encoded from a one-channel image
  double max_error;    // mean absolute difference allowed after decoding
};

TEST(ImageIo, LoadsEachSupportedFormatWithItsSize) {
  const std::vector<FormatCase> cases = {
      {"a.png", ".png", "PNG", {}, false, 0},
      {"a.jpg", ".jpg", "JPEG", {cv::IMWRITE_JPEG_QUALITY, 95}, false, 4},
      {"progressive.jpg", ".jpg", "JPEG", {cv::IMWRITE_JPEG_PROGRESSIVE, 1}, false, 6},
      {"a.bmp", ".bmp", "BMP", {}, false, 0},
      {"a.pgm", ".pgm", "PGM", {}, true, 0},
      {"ascii.pgm", ".pgm", "PGM", {cv::IMWRITE_PXM_BINARY, 0}, true, 0},
      {"a.ppm", ".ppm", "PPM", {}, false, 0},
      {"a.tiff", ".tiff", "TIFF", {}, false, 0},
      {"lossless.webp", ".webp", "WebP", {cv::IMWRITE_WEBP_QUALITY, 101}, false, 0},
      {"lossy.webp", ".webp", "WebP", {cv::IMWRITE_WEBP_QUALITY, 90}, false, 6},
  };
  TempDir dir;
  const cv::Mat colour = picture(97, 61);  // odd sizes catch row padding and swapped axes
  cv::Mat gray;
  cv::extractChannel(colour, gray, 0);
  for (const FormatCase& c : cases) {
    SCOPED_TRACE(c.file);
    const std::string path = dir.str(c.file);
    write_file(path, encode(c.ext, c.gray ? gray : colour, c.params));

    EXPECT_EQ(classify_path(path), PathKind::image);
    std::string error = "stale";
    const std::optional<ImageHeader> header = read_image_header(path, &error);
    ASSERT_TRUE(header.has_value()) << error;
    EXPECT_EQ(error, "");
    EXPECT_EQ(header->format, c.format);
    EXPECT_EQ(header->width, 97);
    EXPECT_EQ(header->height, 61);

    const LoadedImage r = load_image(path, c.gray ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.image.cols, 97);
    EXPECT_EQ(r.image.rows, 61);
    EXPECT_EQ(r.image.type(), c.gray ? CV_8UC1 : CV_8UC3);
    EXPECT_LE(mean_abs_diff(r.image, c.gray ? gray : colour), c.max_error);
  }
}

TEST(ImageIo, FlagsAreThoseOfImread) {
  TempDir dir;
  cv::Mat gray;
  cv::extractChannel(picture(40, 30), gray, 1);
  const std::string path = dir.str("g.pgm");
  write_file(path, encode(".pgm", gray));
  const LoadedImage as_is = load_image(path, cv::IMREAD_UNCHANGED);
  ASSERT_TRUE(as_is.ok()) << as_is.error;
  EXPECT_EQ(as_is.image.type(), CV_8UC1);
  const LoadedImage colour = load_image(path);  // default IMREAD_COLOR
  ASSERT_TRUE(colour.ok()) << colour.error;
  EXPECT_EQ(colour.image.type(), CV_8UC3);
  EXPECT_EQ(colour.image.size(), cv::Size(40, 30));
}

TEST(ImageIo, SignatureDecidesNotTheExtension) {
  TempDir dir;
  const cv::Mat img = picture(20, 10);
  write_file(dir.str("photo.jpg"), encode(".png", img));
  write_file(dir.str("scan.dat"), encode(".jpg", img));
  write_file(dir.str("noextension"), encode(".bmp", img));
  for (const char* name : {"photo.jpg", "scan.dat", "noextension"}) {
    SCOPED_TRACE(name);
    EXPECT_EQ(classify_path(dir.str(name)), PathKind::image);
    const LoadedImage r = load_image(dir.str(name));
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.image.size(), cv::Size(20, 10));
  }
  EXPECT_EQ(read_image_header(dir.str("photo.jpg"))->format, "PNG");
}

TEST(ImageIo, BmpWithNegativeHeightIsStoredTopDown) {
  TempDir dir;
  const cv::Mat img = picture(16, 12);
  std::string bmp = encode(".bmp", img);  // bottom-up, 24-bit BITMAPINFOHEADER, rows of 48 bytes (no padding)
  ASSERT_EQ(bmp.size(), 54u + 16 * 12 * 3);
  // Make it top-down: height -12 and the rows in the opposite order.
  const uint32_t minus12 = static_cast<uint32_t>(-12);
  for (int i = 0; i < 4; ++i) bmp[static_cast<size_t>(22 + i)] = static_cast<char>(minus12 >> (8 * i));
  std::string rows = bmp.substr(54), flipped;
  for (size_t r = 12; r-- > 0;) flipped += rows.substr(r * 48, 48);
  const std::string path = dir.str("topdown.bmp");
  write_file(path, bmp.substr(0, 54) + flipped);

  const auto header = read_image_header(path);
  ASSERT_TRUE(header.has_value());
  EXPECT_EQ(header->width, 16);
  EXPECT_EQ(header->height, 12);
  const LoadedImage r = load_image(path);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(cv::norm(r.image, img, cv::NORM_INF), 0.0);
}

TEST(ImageIo, PnmHeaderWithComments) {
  TempDir dir;
  std::string pixels;
  for (int i = 0; i < 7 * 5; ++i) pixels += static_cast<char>(i * 7);
  const std::string path = dir.str("commented.pgm");
  write_file(path, "P5\n# made by hand\n7 # width\n# height next\n5\n255\n" + pixels);

  const auto header = read_image_header(path);
  ASSERT_TRUE(header.has_value());
  EXPECT_EQ(header->format, "PGM");
  EXPECT_EQ(header->width, 7);
  EXPECT_EQ(header->height, 5);
  const LoadedImage r = load_image(path, cv::IMREAD_GRAYSCALE);
  ASSERT_TRUE(r.ok()) << r.error;
  ASSERT_EQ(r.image.size(), cv::Size(7, 5));
  EXPECT_EQ(r.image.at<uchar>(4, 6), 34 * 7);
}

TEST(ImageIo, DataAfterTheEndOfTheImageIsIgnored) {
  // Cameras append thumbnails or a whole video after a JPEG's EOI; PNG writers sometimes leave junk after IEND.
  TempDir dir;
  const cv::Mat img = picture(30, 20);
  const std::string trailer = bytes("\xFF\xD8\xFF\xE1 trailer \x00\x00\x00\x18" "ftypmp42") + std::string(5000, 'x');
  for (const char* ext : {".jpg", ".png"}) {
    SCOPED_TRACE(ext);
    const std::string path = dir.str(std::string("trailer") + ext);
    write_file(path, encode(ext, img) + trailer);
    const LoadedImage r = load_image(path);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.image.size(), cv::Size(30, 20));
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Paths that are not image files

TEST(ImageIo, MissingFile) {
  TempDir dir;
  const std::string path = dir.str("nothere.png");
  const LoadedImage r = load_image(path);
  EXPECT_EQ(r.error, path + ": no such file");
  EXPECT_TRUE(r.image.empty());
  std::string error;
  EXPECT_FALSE(read_image_header(path, &error).has_value());
  EXPECT_EQ(error, "no such file");
}

TEST(ImageIo, Directory) {
  TempDir dir;
  const std::string path = dir.str("folder.png");  // a folder, whatever its name says
  std::filesystem::create_directory(path);
  const LoadedImage r = load_image(path);
  EXPECT_EQ(r.error, path + ": not a regular file (a folder)");
  EXPECT_TRUE(r.image.empty());
}

TEST(ImageIo, DeviceFile) {
  const LoadedImage r = load_image("/dev/null");  // reading it would give 0 bytes; a device is refused first
  EXPECT_EQ(r.error, "/dev/null: not a regular file (a character device)");
}

// A FIFO named like an image: opening it to read would wait for a writer forever. Refused by name, at once.
TEST(ImageIo, FifoIsRefusedByNameWithoutBlocking) {
  TempDir dir;
  const std::string path = dir.str("photo.png");
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(load_image(path).error, path + ": not a regular file (a FIFO)");
  std::string error;
  EXPECT_FALSE(read_image_header(path, &error));
  EXPECT_EQ(error, "not a regular file (a FIFO)");
  EXPECT_EQ(classify_path(path), PathKind::other);
  std::vector<std::string> skipped;
  EXPECT_TRUE(list_images(dir.str(), &skipped).empty());
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_EQ(skipped[0], path + ": skipped, not a regular file (a FIFO)");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
}

// An image file is at most 1 GiB (100 megapixels of 16-bit RGBA is 800 MB): a sparse file of terabytes costs
// nothing to make and must not be walked.
TEST(ImageIo, AnImageFileLargerThanTheLimitIsRefusedBeforeItIsRead) {
  TempDir dir;
  const std::string path = dir.str("huge.jpg");
  write_file(path, "\xFF\xD8\xFF");
  std::filesystem::resize_file(path, std::uintmax_t{4} << 30);  // sparse
  expect_failure(load_image(path), path, "larger than 1 GiB, the limit for an image");
  std::string error;
  EXPECT_FALSE(read_image_header(path, &error));
  EXPECT_EQ(error, "larger than 1 GiB, the limit for an image");
}

// A JPEG's frame header is searched for past stray bytes, as libjpeg does; byte by byte through 500 MB of them
// (a sparse file) took seconds per file, for a header that no writer puts there. The search stops at 64 MiB.
TEST(ImageIo, JpegHeaderSearchStopsAt64MiBOfStrayBytes) {
  TempDir dir;
  const std::string path = dir.str("stray.jpg");
  write_file(path, "\xFF\xD8\xFF");
  std::filesystem::resize_file(path, std::uintmax_t{500} << 20);  // zeros: stray bytes, never a marker
  std::string error;
  EXPECT_FALSE(read_image_header(path, &error));
  EXPECT_EQ(error, "invalid header (no frame header in the first 64 MiB)");
  // The same with FF fill bytes, which may precede a marker.
  // Appended, not "..." + std::string: GCC 12 with the precompiled header warns of a false out-of-bounds copy there.
  std::string ff = "\xFF\xD8";
  ff.append(size_t{65} << 20, '\xFF');
  write_file(path, ff);
  EXPECT_FALSE(read_image_header(path, &error));
  EXPECT_EQ(error, "invalid header (no frame header in the first 64 MiB)");
}

TEST(ImageIo, EmptyFile) {
  TempDir dir;
  const std::string path = dir.str("empty.jpg");
  write_file(path, "");
  const LoadedImage r = load_image(path);
  EXPECT_EQ(r.error, path + ": empty file (0 bytes)");
  EXPECT_TRUE(r.image.empty());
}

TEST(ImageIo, RandomBytesNamedPng) {
  TempDir dir;
  cv::Mat noise(1, 4096, CV_8U);
  cv::RNG(7).fill(noise, cv::RNG::UNIFORM, 0, 256);
  noise.at<uchar>(0, 0) = 'x';  // make sure the noise does not start like some format
  const std::string path = dir.str("noise.png");
  write_file(path, std::string(noise.ptr<char>(), noise.total()));
  expect_failure(load_image(path), path, "not an image (unknown signature)");
  EXPECT_EQ(classify_path(path), PathKind::other);
}

TEST(ImageIo, TextFileNamedJpg) {
  TempDir dir;
  const std::string path = dir.str("notes.jpg");
  write_file(path, "BM is how this text starts, which is also how a BMP starts.\n");
  const LoadedImage r = load_image(path);
  EXPECT_EQ(r.error, path + ": not an image (unknown signature)");
}

TEST(ImageIo, VideosAndUnsupportedFormatsAreNamed) {
  TempDir dir;
  const std::string mp4 = dir.str("clip.png");
  write_file(mp4, bytes("\x00\x00\x00\x18" "ftypisom\x00\x00\x02\x00" "isomiso2") + std::string(100, '\0'));
  expect_failure(load_image(mp4), mp4, "not an image (video: MP4/MOV)");
  const std::string gif = dir.str("anim.gif");
  write_file(gif, bytes("GIF89a\x10\x00\x10\x00\x00\x00\x00;"));
  expect_failure(load_image(gif), gif, "unsupported image format (GIF)");
}

// ---------------------------------------------------------------------------------------------------------------
// Truncated and corrupt images

TEST(ImageIo, PngTruncatedToHalf) {
  TempDir dir;
  const std::string png = encode(".png", picture(120, 80));
  const std::string path = dir.str("half.png");
  write_file(path, png.substr(0, png.size() / 2));
  expect_failure(load_image(path), path, "truncated image data (no IEND chunk)");
  // The header is intact, so the header alone still reads.
  const auto header = read_image_header(path);
  ASSERT_TRUE(header.has_value());
  EXPECT_EQ(header->width, 120);
}

TEST(ImageIo, JpegTruncatedToHalf) {
  TempDir dir;
  const std::string jpg = encode(".jpg", picture(120, 80));
  const std::string path = dir.str("half.jpg");
  write_file(path, jpg.substr(0, jpg.size() / 2));
  expect_failure(load_image(path), path, "truncated image data (no end-of-image marker)");
}

TEST(ImageIo, JpegWithoutItsLastBytesIsRejectedThoughOpenCvDecodesIt) {
  TempDir dir;
  const std::string jpg = encode(".jpg", picture(120, 80));
  const std::string cut = jpg.substr(0, jpg.size() - 2);  // just the EOI marker missing
  // What this check is for: OpenCV alone returns a (possibly partial) image for this file.
  const std::vector<uchar> buf(cut.begin(), cut.end());
  EXPECT_FALSE(cv::imdecode(buf, cv::IMREAD_COLOR).empty());
  const std::string path = dir.str("cut.jpg");
  write_file(path, cut);
  expect_failure(load_image(path), path, "truncated image data");
}

TEST(ImageIo, PngWithoutIendIsTruncated) {
  TempDir dir;
  const std::string png = encode(".png", picture(120, 80));
  const std::string cut = png.substr(0, png.size() - 12);  // every IDAT there, the IEND chunk gone
  const std::string path = dir.str("cut.png");
  write_file(path, cut);
  expect_failure(load_image(path), path, "truncated image data (no IEND chunk)");
}

TEST(ImageIo, TruncatedBinaryPnmAndBmp) {
  TempDir dir;
  const cv::Mat img = picture(50, 40);
  for (const char* ext : {".ppm", ".bmp"}) {
    SCOPED_TRACE(ext);
    const std::string bytes = encode(ext, img);
    const std::string path = dir.str(std::string("short") + ext);
    write_file(path, bytes.substr(0, bytes.size() - 100));
    expect_failure(load_image(path), path, "truncated image data");
  }
}

TEST(ImageIo, TruncatedHeader) {
  TempDir dir;
  const std::string path = dir.str("stub.png");
  write_file(path, encode(".png", picture(10, 10)).substr(0, 20));  // signature and part of IHDR
  expect_failure(load_image(path), path, "truncated header");
  std::string error;
  EXPECT_FALSE(read_image_header(path, &error).has_value());
  EXPECT_EQ(error, "truncated header");
}

TEST(ImageIo, CorruptPngData) {
  TempDir dir;
  std::string png = encode(".png", picture(64, 48));
  const size_t idat = png.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  for (size_t i = idat + 4; i < idat + 40; ++i) png[i] = '\x55';  // complete structure, garbage inside
  const std::string path = dir.str("corrupt.png");
  write_file(path, png);
  expect_failure(load_image(path), path, "corrupt or truncated image data");
}

// ---------------------------------------------------------------------------------------------------------------
// Declared sizes that would take gigabytes

TEST(ImageIo, HugePngIsRejectedBeforeDecoding) {
  TempDir dir;
  // 60000x60000 is the classic decompression bomb; 20000x20000 (400 Mpx) is still under OpenCV's own limit of
  // 2^30 pixels, so without the check OpenCV would allocate 1.2 GB for it before failing on the data.
  for (uint32_t side : {60000u, 20000u}) {
    const std::string dims = std::to_string(side) + "x" + std::to_string(side);
    SCOPED_TRACE(dims);
    const std::string path = dir.str("bomb" + dims + ".png");
    write_file(path, png_declaring(side, side));

    const auto header = read_image_header(path);
    ASSERT_TRUE(header.has_value());
    EXPECT_EQ(header->width, static_cast<int>(side));

    MatAllocationRecorder recorder;
    const auto start = std::chrono::steady_clock::now();
    const LoadedImage r = load_image(path);
    const auto elapsed = std::chrono::steady_clock::now() - start;
    expect_failure(r, path, "declares " + dims + " pixels, more than the limit of 100000000");
    EXPECT_EQ(recorder.largest(), 0u) << "pixel memory was allocated";
    EXPECT_LT(elapsed, std::chrono::seconds(1));
  }
}

TEST(ImageIo, HugeJpegIsRejectedBeforeDecoding) {
  TempDir dir;
  const std::string path = dir.str("bomb.jpg");
  write_file(path, with_jpeg_size(encode(".jpg", picture(64, 48)), 60000, 60000));
  const auto header = read_image_header(path);
  ASSERT_TRUE(header.has_value());
  EXPECT_EQ(header->width, 60000);
  EXPECT_EQ(header->height, 60000);

  MatAllocationRecorder recorder;
  const auto start = std::chrono::steady_clock::now();
  const LoadedImage r = load_image(path);
  expect_failure(r, path, "declares 60000x60000 pixels, more than the limit of 100000000");
  EXPECT_EQ(recorder.largest(), 0u);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
}

TEST(ImageIo, RecorderSeesDecoderAllocations) {
  // The control for the two tests above: a valid image does go through the recorded allocator.
  TempDir dir;
  const std::string path = dir.str("ok.png");
  write_file(path, encode(".png", picture(64, 48)));
  MatAllocationRecorder recorder;
  ASSERT_TRUE(load_image(path).ok());
  EXPECT_GE(recorder.largest(), 64u * 48u * 3u);
}

TEST(ImageIo, SideLimitAndPixelBudget) {
  TempDir dir;
  const std::string wide = dir.str("wide.png");
  write_file(wide, png_declaring(40000, 16));  // only 640000 pixels, but one side too long
  expect_failure(load_image(wide), wide, "declares 40000x16 pixels, a side longer than the limit of 32768");

  const std::string small = dir.str("small.png");
  write_file(small, encode(".png", picture(64, 64)));
  expect_failure(load_image(small, cv::IMREAD_COLOR, 1000), small, "declares 64x64 pixels, more than the limit of 1000");
  EXPECT_TRUE(load_image(small, cv::IMREAD_COLOR, 64 * 64).ok());
}

TEST(ImageIo, FileFarLargerThanItsImageIsNotRead) {
  TempDir dir;
  const std::string path = dir.str("padded.png");
  write_file(path, encode(".png", picture(8, 8)));
  std::filesystem::resize_file(path, 200u << 20);  // 200 MB of zeros after IEND (sparse, so cheap to make)
  expect_failure(load_image(path), path, "file is 209715200 bytes, too large for its declared 8x8 pixels");
}

// ---------------------------------------------------------------------------------------------------------------
// Folders and path kinds

TEST(ImageIo, ListImagesInNameOrder) {
  TempDir dir;
  const cv::Mat img = picture(12, 9);
  write_file(dir.str("b.png"), encode(".png", img));
  write_file(dir.str("a.jpg"), encode(".jpg", img));
  write_file(dir.str("Z.bmp"), encode(".bmp", img));     // upper case sorts first in byte order
  write_file(dir.str("scan.dat"), encode(".ppm", img));  // an image whatever its extension
  write_file(dir.str("notes.txt"), "not a picture\n");
  write_file(dir.str(".hidden.png"), encode(".png", img));
  std::filesystem::create_directory(dir.str("sub"));
  write_file(dir.str("sub/c.png"), encode(".png", img));

  std::vector<std::string> skipped;
  std::string error = "stale";
  const std::vector<std::string> images = list_images(dir.str(), &skipped, &error);
  EXPECT_EQ(error, "");
  EXPECT_EQ(images, (std::vector<std::string>{dir.str("Z.bmp"), dir.str("a.jpg"), dir.str("b.png"), dir.str("scan.dat")}));
  EXPECT_EQ(skipped, std::vector<std::string>{dir.str("notes.txt") + ": skipped, not an image"});
  // Without the out-parameters it is the same list.
  EXPECT_EQ(list_images(dir.str()), images);
}

TEST(ImageIo, ListImagesOfAFolderThatIsNotThere) {
  TempDir dir;
  std::string error;
  EXPECT_TRUE(list_images(dir.str("nope"), nullptr, &error).empty());
  EXPECT_EQ(error, dir.str("nope") + ": no such folder");
  write_file(dir.str("file.png"), encode(".png", picture(4, 4)));
  EXPECT_TRUE(list_images(dir.str("file.png"), nullptr, &error).empty());
  EXPECT_EQ(error, dir.str("file.png") + ": not a folder");
}

TEST(ImageIo, ClassifyPath) {
  TempDir dir;
  write_file(dir.str("pic.dat"), encode(".png", picture(8, 8)));
  write_file(dir.str("clip.bin"), bytes("\x00\x00\x00\x18" "ftypisom\x00\x00\x02\x00" "isomiso2mp41") +
                                      std::string(64, '\0'));
  write_file(dir.str("old.avi"), bytes("RIFF\x24\x00\x00\x00" "AVI LIST") + std::string(32, '\0'));
  write_file(dir.str("film.mkv"), bytes("\x1A\x45\xDF\xA3\x9F\x42\x86\x81\x01") + std::string(32, '\0'));
  write_file(dir.str("photo.heic"), bytes("\x00\x00\x00\x18" "ftypheic\x00\x00\x00\x00" "mif1heic"));
  write_file(dir.str("readme.txt"), "hello\n");
  write_file(dir.str("empty.png"), "");

  EXPECT_EQ(classify_path(dir.str()), PathKind::folder);
  EXPECT_EQ(classify_path(dir.str("missing.png")), PathKind::missing);
  EXPECT_EQ(classify_path(dir.str("pic.dat")), PathKind::image);
  EXPECT_EQ(classify_path(dir.str("clip.bin")), PathKind::video);
  EXPECT_EQ(classify_path(dir.str("old.avi")), PathKind::video);
  EXPECT_EQ(classify_path(dir.str("film.mkv")), PathKind::video);
  EXPECT_EQ(classify_path(dir.str("photo.heic")), PathKind::other);  // same box structure as MP4, but a still
  EXPECT_EQ(classify_path(dir.str("readme.txt")), PathKind::other);
  EXPECT_EQ(classify_path(dir.str("empty.png")), PathKind::other);
  EXPECT_EQ(classify_path("/dev/null"), PathKind::other);
  EXPECT_STREQ(to_string(PathKind::video), "video");
}

// A valid PNG with a damaged colour profile made libpng print "libpng warning: iCCP: ..." on the terminal, and a
// damaged one "libpng error: ..." beside our message. Neither reaches stderr now; the error is in our message.
TEST(ImageIo, DecoderLibrariesPrintNothingOnStderr) {
  TempDir dir;
  std::vector<uint8_t> encoded;
  ASSERT_TRUE(cv::imencode(".png", cv::Mat(16, 16, CV_8UC3, cv::Scalar(10, 200, 30)), encoded));
  std::string png(encoded.begin(), encoded.end());
  const std::string iccp = "iCCPbad\0\0" + std::string(40, 'x');  // not even deflate data
  const std::string chunk = png_chunk("iCCP", iccp.substr(4));
  png.insert(8 + 25, chunk);  // after the signature and IHDR
  write_file(dir.str("iccp.png"), png);
  testing::internal::CaptureStderr();
  const LoadedImage ok = load_image(dir.str("iccp.png"));
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_TRUE(ok.ok()) << ok.error;

  png = std::string(encoded.begin(), encoded.end());
  png[png.find("IDAT") + 10] ^= 0x5A;
  write_file(dir.str("idat.png"), png);
  testing::internal::CaptureStderr();
  const LoadedImage bad = load_image(dir.str("idat.png"));
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(bad.error.rfind(dir.str("idat.png") + ": corrupt or truncated image data (IDAT: ", 0), 0u) << bad.error;
}

// A classic TIFF whose ImageWidth entry says LONG8 (a BigTIFF type, 8 value bytes) in a 12-byte entry that ends
// the file: reading its value as 8 bytes went 4 bytes past the file (found by fuzzing). It is refused by type.
TEST(ImageIo, ClassicTiffWithALong8SizeIsRefusedWithoutReadingPastTheEntry) {
  TempDir dir;
  std::string b("II*\0", 4);
  b += std::string("\x08\0\0\0", 4);          // first IFD at byte 8
  b += std::string("\x02\0", 2);                // two entries
  b += std::string("\x01\x01\x04\0\x01\0\0\0\x10\0\0\0", 12);   // ImageLength, LONG, 1, 16
  b += std::string("\0\x01\x10\0\x01\0\0\0\x10\0\0\0", 12);     // ImageWidth, LONG8 (16), 1, 16...
  ASSERT_EQ(b.size(), 34u) << "the entry ends the file";
  const std::string path = dir.str("long8.tif");
  write_file(path, b);
  std::string error;
  EXPECT_FALSE(read_image_header(path, &error));
  EXPECT_NE(error.find("TIFF size of type 16"), std::string::npos) << error;
}

TEST(ImageIo, ReadImageHeaderReadsOnlyTheHeader) {
  TempDir dir;
  // A PNG whose data is missing altogether still has a readable header.
  const std::string path = dir.str("header_only.png");
  write_file(path, png_declaring(300, 200).substr(0, 33));
  std::string error;
  const auto header = read_image_header(path, &error);
  ASSERT_TRUE(header.has_value()) << error;
  EXPECT_EQ(header->format, "PNG");
  EXPECT_EQ(header->width, 300);
  EXPECT_EQ(header->height, 200);

  write_file(dir.str("text.png"), "just text");
  EXPECT_FALSE(read_image_header(dir.str("text.png"), &error).has_value());
  EXPECT_EQ(error, "not an image (unknown signature)");
  EXPECT_FALSE(read_image_header(dir.str(), &error).has_value());
  EXPECT_EQ(error, "not a regular file (a folder)");
  EXPECT_FALSE(read_image_header(dir.str("missing"), nullptr).has_value());  // error is optional
}

// The in-memory readers (what fuzz/image_header.cpp calls) give the answers the file readers give.
TEST(ImageIo, BytesInMemoryReadAsTheirFile) {
  const std::string png = encode(".png", picture(40, 30));
  const auto span_of = [](const std::string& s) {
    return std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(s.data()), s.size());
  };
  std::string error = "stale";
  const auto header = parse_image_header(span_of(png), &error);
  ASSERT_TRUE(header.has_value()) << error;
  EXPECT_EQ(error, "");
  EXPECT_EQ(header->format, "PNG");
  EXPECT_EQ(header->width, 40);
  EXPECT_EQ(header->height, 30);
  const LoadedImage img = decode_image(span_of(png), "mem.png");
  ASSERT_TRUE(img.ok()) << img.error;
  EXPECT_EQ(img.image.size(), cv::Size(40, 30));

  EXPECT_FALSE(parse_image_header(span_of(png.substr(0, 20)), &error));
  EXPECT_EQ(error, "truncated header");
  EXPECT_FALSE(parse_image_header({}, &error));
  EXPECT_EQ(error, "empty file (0 bytes)");
  EXPECT_EQ(decode_image({}, "mem.png").error, "mem.png: empty file (0 bytes)");
  EXPECT_EQ(decode_image(span_of(png.substr(0, png.size() - 12)), "mem.png").error,
            "mem.png: truncated image data (no IEND chunk)");
  // The LONG8 over-read's input, in memory: its entry ends the bytes, as it ended the file.
  const std::string tiff = bytes("II*\0\x08\0\0\0\x02\0\x01\x01\x04\0\x01\0\0\0\x10\0\0\0\0\x01\x10\0\x01\0\0\0\x10\0\0\0");
  ASSERT_EQ(tiff.size(), 34u);
  EXPECT_FALSE(parse_image_header(span_of(tiff), &error));
  EXPECT_EQ(error, "invalid header (TIFF size of type 16)");
}

}  // namespace
}  // namespace arwb
