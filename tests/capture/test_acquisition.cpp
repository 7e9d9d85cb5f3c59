// The paper's acquisition step (capture/acquisition.hpp): the resize to the working size, or a copy.
#include "capture/acquisition.hpp"

#include <gtest/gtest.h>

namespace arwb {
namespace {

TEST(Acquire, ResizesOrCopies) {
  AcquisitionSettings s;
  cv::Mat big(720, 1280, CV_8UC3, cv::Scalar(1, 2, 3)), small(240, 320, CV_8UC3, cv::Scalar(4, 5, 6)), out;
  // By default 640 across, the height keeping the source's aspect: 16:9 stays 16:9, 4:3 stays 4:3.
  acquire(big, s, out);
  EXPECT_EQ(out.size(), cv::Size(640, 360));
  EXPECT_EQ(out.at<cv::Vec3b>(100, 100), cv::Vec3b(1, 2, 3));
  acquire(small, s, out);
  EXPECT_EQ(out.size(), cv::Size(640, 480));
  EXPECT_EQ(out.at<cv::Vec3b>(479, 639), cv::Vec3b(4, 5, 6));

  s.resize = false;
  acquire(big, s, out);
  EXPECT_EQ(out.size(), big.size());
  EXPECT_NE(out.data, big.data) << "a copy, not a view";
  EXPECT_EQ(cv::norm(out, big, cv::NORM_INF), 0);

  s.resize = true;
  s.size = {1280, 720};
  acquire(big, s, out);
  EXPECT_NE(out.data, big.data);
  EXPECT_EQ(cv::norm(out, big, cv::NORM_INF), 0);

  // Two sides: exactly that size, the aspect not kept (as in the paper's 640x480).
  s.size = {100, 100};
  acquire(big, s, out);
  EXPECT_EQ(out.size(), cv::Size(100, 100));

  acquire(cv::Mat(), s, out);
  EXPECT_TRUE(out.empty());
  // In place.
  cv::Mat m = big.clone();
  acquire(m, s, m);
  EXPECT_EQ(m.size(), cv::Size(100, 100));
}

}  // namespace
}  // namespace arwb
