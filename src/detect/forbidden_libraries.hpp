// The detector links OpenCV's core and imgproc only: every file of the detect target is compiled with this header
// first (-include, src/detect/CMakeLists.txt), which poisons a name each of the other libraries' headers declares.
// Their headers are on every include path (/usr/include, OpenCV's folder), so including one here, even through
// another header, fails with "attempt to use poisoned". tests/layering checks that it does.
#pragma once
#pragma GCC poison aruco              // OpenCV's aruco module (namespace cv::aruco): src/peers
#pragma GCC poison apriltag_detector  // AprilTag: src/peers
#pragma GCC poison nlohmann           // JSON: the trace's JSON is src/inspect
