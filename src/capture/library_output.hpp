// What libraries print on their own, kept off the terminal for the whole process: OpenCV's and FFmpeg's logs,
// cv::error's handler, and the lines decoder libraries write straight to stderr. Our own messages say what failed.
#pragma once

#include <functional>
#include <string>
#include <string_view>

namespace arwb {

// Keeps OpenCV's own text off the terminal: FFmpeg's log (unless OPENCV_FFMPEG_LOGLEVEL is set), OpenCV's log ("[ WARN:0@0.03] global cap_gstreamer.cpp ...", "[ERROR:0@0.03]
// ... raised OpenCV exception: ..." when a backend refuses a file) is silenced unless OPENCV_LOG_LEVEL asks for it,
// and cv::error's handler is one that prints nothing (the exception still carries the text, which we replace by
// our own). Our messages say what failed. Called once by load_image, VideoReader::open and arwb's main; idempotent.
void keep_opencv_quiet();

// Runs `work` with the lines that a library prints straight to stderr (where no log level reaches: libpng,
// libjpeg, OpenCV's own AVI reader) kept off the terminal: lines for which is_library_line is true are dropped,
// any other is passed on afterwards. Returns the first line dropped ("" if none), for a message of ours.
std::string without_library_lines(const std::function<void()>& work, bool (*is_library_line)(std::string_view));

}  // namespace arwb
