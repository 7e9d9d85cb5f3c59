// The detector, calibration and pose read no files, so a program of theirs loads none of OpenCV's image and video
// file readers (libopencv_imgcodecs and libopencv_videoio bring 240 more libraries, about a quarter of a second of
// every start). A call from them into capture's readers fails here, and so does a link line that pulls a reader in
// unasked (the GoogleTest note in tests/CMakeLists.txt).
#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace {

TEST(LoadedLibraries, PoseCalibrationAndTheDetectorLoadNoFileReader) {
  std::ifstream maps("/proc/self/maps");
  ASSERT_TRUE(maps) << "/proc/self/maps cannot be read";
  std::string line;
  bool opencv = false;
  while (std::getline(maps, line)) {
    opencv = opencv || line.find("libopencv_core") != std::string::npos;
    EXPECT_EQ(line.find("libopencv_imgcodecs"), std::string::npos) << line;
    EXPECT_EQ(line.find("libopencv_videoio"), std::string::npos) << line;
  }
  EXPECT_TRUE(opencv) << "OpenCV's core is not loaded: this is not a program of the pose library";
}

}  // namespace
