// What the stage tests share: a crafted canvas with one marker on it.
#pragma once

#include "detect/dictionary.hpp"
#include "synth/synth.hpp"

#include <opencv2/core.hpp>

namespace arwb::test {

// A white canvas with one marker drawn axis-aligned, its outer corners at (x0,y0)..(x0+side,y0+side).
inline cv::Mat canvas_with_marker(const Dictionary& d, int id, float x0, float y0, float side,
                                  cv::Size size = {200, 200}) {
  cv::Mat img(size, CV_8UC1, cv::Scalar(255));
  draw_marker(img, d, id, Quad{cv::Point2f(x0, y0), {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}});
  return img;
}

}  // namespace arwb::test
