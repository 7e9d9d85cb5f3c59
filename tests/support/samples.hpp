// The shipped sample image the tests give arwb (assets/samples), found through ARWB_SOURCE_DIR, which every test
// binary is compiled with (support's own files are not: they do not include this).
#pragma once

#include <string>

namespace arwb::test {

// 640x480; ARUCO_ORIGINAL markers, 843 and 950 among them.
inline const std::string kSample = std::string(ARWB_SOURCE_DIR) + "/assets/samples/markers_640x480.png";

}  // namespace arwb::test
