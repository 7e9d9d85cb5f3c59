// File > Export... and File > Play bundle...: the dialog's state and the players started (ui/export_requests.cpp).
#pragma once

#include "base/result.hpp"
#include "bundle/bundle.hpp"
#include "serve/bundle_server.hpp"
#include "ui/file_browser.hpp"
#include "workbench/log.hpp"

#include <future>
#include <opencv2/core/mat.hpp>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace arwb {

// The scene loaded, as a bundle. Check and Export run plan_export (and write_export) on a thread of their own; the
// dialog shows the last check's self-test.
struct ExportDialog {
  bool opening = false;
  char title[256] = "";
  double size_mm = 50;
  bool use_calibration = true;      // the calibration loaded with --calib, when there is one
  bool force = false;               // replace an existing bundle at `out`
  bool web = false;                 // add the phone player's web page (arwb export --web)
  bool convert_for_phones = false;  // with web: copies phones play (--convert-for-phones)
  char out[1024] = "";
  ui::FileBrowser browser;
  std::future<Result<bundle::ExportPlan>> checking;   // Check, or the check before writing
  bool write_after = false;         // the check running is Export's: write when it passes
  std::future<Status> writing;
  std::shared_ptr<const bundle::ExportPlan> plan;     // the last check that passed
  std::string error;                // the last check's or write's failure, one line
  std::string written;              // where the last export went
  bool written_web = false;         // ... with the phone page (the Serve section shows)
  // Serve: the bundle written, on 127.0.0.1 for a browser or a phone over USB (ui/serve_requests.cpp).
  std::future<Result<serve::BundleServer>> serve_starting;
  std::optional<serve::BundleServer> server;
  cv::Mat server_qr;                // the server's address as a QR code, 1 byte a pixel, made as it started
  std::string serve_error;          // why the last start failed, one line
  bool serve_stale = false;         // the start running verifies a bundle written over since: its server is dropped
};

// Each player started runs as a process of its own; a thread per player verifies the bundle first, starts it and
// waits for it, and leaves its messages here for the UI thread's log.
struct Players {
  std::mutex mutex;
  std::vector<std::pair<LogLevel, std::string>> messages;
  int running = 0;                  // verifying, or started and not yet ended
  int started = 0, ended = 0, refused = 0;
  std::vector<int> exit_codes;      // of the players that ended, in the order they ended
};

// An export message (bundle/bundle.hpp words it for `arwb export`: --out, --calib, --force) in the Export dialog's
// words (the path, the calibration, the 'replace an existing bundle there' checkbox).
std::string export_window_wording(std::string text);

}  // namespace arwb
