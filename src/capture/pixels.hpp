// Pixels as the rest of the house wants them: 8 bits a channel, BGR. Cameras, video and image files may give
// grey, grey and alpha, BGRA, 16-bit or float pictures; this is the one place that says how each becomes 8-bit.
#pragma once

#include <opencv2/core.hpp>

namespace arwb {

// 8 bits a channel, channels unchanged: 16-bit scales by 1/257 (65535 -> 255), float and double are taken as
// 0..1 and scale by 255, signed types saturate. An 8-bit picture is returned as is (shared, not copied).
cv::Mat to_8bit(const cv::Mat& in);

enum class Alpha { drop, keep };

// 8-bit BGR (to_8bit first): grey becomes BGR; BGRA loses its alpha, or keeps it with Alpha::keep (CV_8UC4, and
// grey and alpha becomes BGRA); more channels than four keep the first three. May share `in`'s pixels when
// nothing needs converting; empty in, empty out.
cv::Mat to_bgr8(const cv::Mat& in, Alpha alpha = Alpha::drop);

}  // namespace arwb
