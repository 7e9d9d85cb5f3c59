// What libraries print on their own (library_output.hpp): a process-wide policy, set once.
#include "capture/library_output.hpp"

#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include <cstdio>
#include <cstdlib>
#include <mutex>

#include <sys/mman.h>
#include <unistd.h>

namespace arwb {

void keep_opencv_quiet() {
  static std::once_flag once;
  std::call_once(once, [] {
    // FFmpeg's own lines ("moov atom not found") would duplicate ours; read by OpenCV when FFmpeg starts.
    setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
    if (!std::getenv("OPENCV_LOG_LEVEL")) cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    cv::redirectError([](int, const char*, const char*, const char*, int, void*) { return 0; });
  });
}

// While `work` runs, file descriptor 2 points to an anonymous in-memory file, as the libraries give no way to
// hand them a handler of ours; afterwards their lines are dropped and any other line, which another thread wrote
// meanwhile, is passed on to the real stderr: delayed, never lost. One such run at a time.
std::string without_library_lines(const std::function<void()>& work, bool (*is_library_line)(std::string_view)) {
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  std::fflush(stderr);
  const int saved = ::dup(2);
  const int capture = ::memfd_create("arwb-library-messages", MFD_CLOEXEC);
  const bool redirected = saved >= 0 && capture >= 0 && ::dup2(capture, 2) >= 0;
  work();
  std::fflush(stderr);
  if (redirected) ::dup2(saved, 2);
  if (saved >= 0) ::close(saved);
  if (capture < 0) return "";
  std::string text(64 * 1024, '\0');
  const ssize_t n = redirected ? ::pread(capture, text.data(), text.size(), 0) : 0;
  ::close(capture);
  text.resize(n > 0 ? static_cast<size_t>(n) : 0);
  std::string others, first;
  for (size_t start = 0; start < text.size();) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    const std::string_view line(text.data() + start, end - start);
    if (!is_library_line(line)) others.append(line).append("\n");
    else if (first.empty()) first = std::string(line);
    start = end + 1;
  }
  if (!others.empty()) (void)!::write(2, others.data(), others.size());
  return first;
}

}  // namespace arwb
