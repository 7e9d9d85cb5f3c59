// OpenCV's own image limits: set at start to capture's limits, a user's setting kept, and in force in arwb.
#include "cli/opencv_limits.hpp"
#include "capture/image_io.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <string>

using namespace arwb;

namespace {

const char* const kNames[] = {"OPENCV_IO_MAX_IMAGE_WIDTH", "OPENCV_IO_MAX_IMAGE_HEIGHT", "OPENCV_IO_MAX_IMAGE_PIXELS"};

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "(unset)";
}

// Puts the three variables back as they were when the test ends.
struct SavedLimits {
  SavedLimits() {
    for (size_t i = 0; i < 3; ++i) saved[i] = std::getenv(kNames[i]) ? std::getenv(kNames[i]) : "";
  }
  ~SavedLimits() {
    for (size_t i = 0; i < 3; ++i)
      if (saved[i].empty()) unsetenv(kNames[i]);
      else setenv(kNames[i], saved[i].c_str(), 1);
  }
  std::string saved[3];
};

}  // namespace

TEST(OpenCvLimits, SetToCapturesLimitsOnceAndAUsersSettingIsKept) {
  SavedLimits keep;
  for (const char* n : kNames) unsetenv(n);
  EXPECT_TRUE(set_opencv_image_limits());
  EXPECT_EQ(env("OPENCV_IO_MAX_IMAGE_WIDTH"), std::to_string(kMaxImageSide));
  EXPECT_EQ(env("OPENCV_IO_MAX_IMAGE_HEIGHT"), std::to_string(kMaxImageSide));
  EXPECT_EQ(env("OPENCV_IO_MAX_IMAGE_PIXELS"), std::to_string(kDefaultMaxPixels));
  EXPECT_FALSE(set_opencv_image_limits()) << "all set: arwb must not start again";

  unsetenv("OPENCV_IO_MAX_IMAGE_HEIGHT");
  setenv("OPENCV_IO_MAX_IMAGE_WIDTH", "10", 1);
  EXPECT_TRUE(set_opencv_image_limits());
  EXPECT_EQ(env("OPENCV_IO_MAX_IMAGE_WIDTH"), "10");
  EXPECT_EQ(env("OPENCV_IO_MAX_IMAGE_HEIGHT"), std::to_string(kMaxImageSide));
}

TEST(OpenCvLimits, OpenCvsLimitIsInForceBehindTheHeaderChecks) {
  // A 64x64 PNG passes arwb's own header checks (limits 32768 a side, 100 Mpx); with OpenCV's limit at 1000
  // pixels, set as a user would, OpenCV's decoder refuses it in arwb. arwb sets the other two variables itself
  // and starts again, and the user's value still reaches OpenCV.
  SavedLimits keep;
  test::TempDir dir;
  ASSERT_TRUE(cv::imwrite(dir.str("small.png"), cv::Mat(64, 64, CV_8UC3, cv::Scalar::all(128))));
  for (const char* n : kNames) unsetenv(n);
  const auto fine = test::run_arwb("detect '" + dir.str("small.png") + "'");
  EXPECT_EQ(fine.status, 0) << fine.err;
  setenv("OPENCV_IO_MAX_IMAGE_PIXELS", "1000", 1);
  const auto refused = test::run_arwb("detect '" + dir.str("small.png") + "'");
  EXPECT_EQ(refused.status, 1) << refused.out;
  EXPECT_NE(refused.err.find(dir.str("small.png") + ": corrupt or truncated image data"), std::string::npos)
      << refused.err;
}
