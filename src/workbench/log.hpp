// The workbench's log: thread-safe messages for the log panel, the status bar and stderr. The worker and the UI
// thread add to it; the UI copies the entries when they changed.
#pragma once

#include "base/text.hpp"

#include <chrono>
#include <cstdio>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace arwb {

enum class LogLevel { info, warning, error };
struct LogEntry {
  double time_s = 0;   // since the workbench started
  LogLevel level = LogLevel::info;
  std::string text;
};

class Log {
 public:
  explicit Log(std::chrono::steady_clock::time_point t0) : t0_(t0) {}
  bool verbose = false;   // info lines to stderr too
  // The one way messages reach the log panel and stderr, so control characters in them (a file name holding
  // "\x1B[31m" or a newline) are escaped here, once.
  void add(LogLevel level, const std::string& raw) {
    const std::string text = printable(raw);
    const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    std::lock_guard lock(mutex_);
    entries_.push_back({t, level, text});
    if (entries_.size() > 5000) entries_.erase(entries_.begin(), entries_.begin() + 1000);
    ++version_;
    if (level != LogLevel::info) ++problems_;
    if (level != LogLevel::info || verbose) {
      std::fprintf(stderr, "arwb: %s%s\n",
                   level == LogLevel::error ? "error: " : (level == LogLevel::warning ? "warning: " : ""),
                   text.c_str());
    }
  }
  // Copies the entries when they changed since the last call (the UI thread's copy).
  void sync(std::vector<LogEntry>& out, uint64_t& seen) {
    std::lock_guard lock(mutex_);
    if (seen == version_) return;
    out = entries_;
    seen = version_;
  }
  int problems() const {
    std::lock_guard lock(mutex_);
    return problems_;
  }

 private:
  std::chrono::steady_clock::time_point t0_;
  mutable std::mutex mutex_;
  std::vector<LogEntry> entries_;
  uint64_t version_ = 0;
  int problems_ = 0;
};

}  // namespace arwb
