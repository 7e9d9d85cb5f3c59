// One line for an exception, whatever threw it: cv::Exception's what() is several lines naming OpenCV's own
// source file, function and line, which is not a message for a user.
#pragma once

#include <opencv2/core.hpp>

#include <exception>
#include <string>

namespace arwb {

inline std::string one_line_reason(const std::exception& e) {
  if (const auto* cv_error = dynamic_cast<const cv::Exception*>(&e)) return "OpenCV failed (" + cv_error->err + ")";
  return e.what();
}

}  // namespace arwb
