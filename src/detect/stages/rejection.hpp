// A stage's rejection of a candidate and its message. Internal to the stages.
#pragma once

#include "detect/trace.hpp"

#include <cstdio>
#include <string>
#include <string_view>

namespace arwb::stages {

// A message with two numbers.
inline std::string fmt(const char* f, double a, double b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

inline Rejection reject(Stage s, std::string_view param, double value, double limit, std::string message) {
  return Rejection{s, param, value, limit, std::move(message)};
}

}  // namespace arwb::stages
