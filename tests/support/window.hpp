// What the workbench window's tests share (tests/ui): the arguments that keep a run's files in its own folder, and
// where the live view is on the screen.
#pragma once

#include "support/support.hpp"

#include <opencv2/core.hpp>

#include <string>

namespace arwb::test {

// The live view's region in the Inspect workspace of a 1600x900 window: the top-left of the screen.
inline const cv::Rect kLiveView(0, 50, 730, 500);

// --config-dir and --snapshot-dir inside `tmp`, then `more`.
inline std::string window_args(const TempDir& tmp, const std::string& more) {
  return "--config-dir '" + tmp.str("config") + "' --snapshot-dir '" + tmp.str("snaps") + "' " + more;
}

}  // namespace arwb::test
