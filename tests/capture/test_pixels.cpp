// The one conversion to 8-bit BGR: every depth scaled one way, alpha dropped or kept.
#include "capture/opencv_error.hpp"
#include "capture/pixels.hpp"

#include <gtest/gtest.h>

namespace arwb {
namespace {

TEST(Pixels, DepthsScaleToEightBits) {
  const cv::Mat grey16(2, 2, CV_16UC1, cv::Scalar(65535));
  EXPECT_EQ(to_8bit(grey16).at<uchar>(0, 0), 255);
  EXPECT_EQ(to_8bit(cv::Mat(1, 1, CV_16UC1, cv::Scalar(257 * 100))).at<uchar>(0, 0), 100);
  EXPECT_EQ(to_8bit(cv::Mat(1, 1, CV_32FC1, cv::Scalar(0.5))).at<uchar>(0, 0), 128);
  EXPECT_EQ(to_8bit(cv::Mat(1, 1, CV_64FC1, cv::Scalar(2.0))).at<uchar>(0, 0), 255);
  const cv::Mat eight(1, 1, CV_8UC3, cv::Scalar(1, 2, 3));
  EXPECT_EQ(to_8bit(eight).data, eight.data) << "8-bit is shared, not copied";
  EXPECT_TRUE(to_bgr8(cv::Mat()).empty());
}

TEST(Pixels, ChannelsBecomeBgrOrBgra) {
  const cv::Mat grey(1, 1, CV_16UC1, cv::Scalar(257 * 40));
  cv::Mat bgr = to_bgr8(grey);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(40, 40, 40));

  const cv::Mat bgra(1, 1, CV_8UC4, cv::Scalar(10, 20, 30, 40));
  EXPECT_EQ(to_bgr8(bgra).type(), CV_8UC3);
  EXPECT_EQ(to_bgr8(bgra).at<cv::Vec3b>(0, 0), cv::Vec3b(10, 20, 30));
  EXPECT_EQ(to_bgr8(bgra, Alpha::keep).at<cv::Vec4b>(0, 0), cv::Vec4b(10, 20, 30, 40));

  const cv::Mat ga(1, 1, CV_8UC2, cv::Scalar(70, 90));
  EXPECT_EQ(to_bgr8(ga).at<cv::Vec3b>(0, 0), cv::Vec3b(70, 70, 70));
  EXPECT_EQ(to_bgr8(ga, Alpha::keep).at<cv::Vec4b>(0, 0), cv::Vec4b(70, 70, 70, 90));
}

}  // namespace
}  // namespace arwb

// What threw reaches users as one line: cv::Exception's what() names OpenCV's source file over several lines.
TEST(OneLineReason, OpenCvExceptionsAreOneLineWithoutOpenCvsSourceFile) {
  try {
    cv::Mat a(2, 2, CV_8U), b(3, 3, CV_8U);
    cv::Mat c = a + b;   // sizes differ: OpenCV throws
    FAIL() << "OpenCV did not throw";
  } catch (const std::exception& e) {
    const std::string reason = arwb::one_line_reason(e);
    EXPECT_EQ(reason.find('\n'), std::string::npos) << reason;
    EXPECT_EQ(reason.find(".cpp"), std::string::npos) << reason;
    EXPECT_EQ(reason.rfind("OpenCV failed (", 0), 0u) << reason;
    EXPECT_NE(std::string(e.what()).find('\n'), std::string::npos) << "OpenCV's own text was expected to be several lines";
  }
  EXPECT_EQ(arwb::one_line_reason(std::runtime_error("plain")), "plain");
}
