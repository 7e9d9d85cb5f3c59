#include "workbench/snapshot.hpp"

#include "capture/opencv_error.hpp"

#include "inspect/trace_json.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>

namespace arwb {
namespace {

namespace fs = std::filesystem;

std::string timestamp() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
  return buf;
}

// cv::imwrite may throw as well as return false; both become a message naming the file.
bool write_png(const fs::path& path, const cv::Mat& img, std::string* error) {
  try {
    if (cv::imwrite(path.string(), img)) return true;
    *error = path.string() + ": cannot write image";
  } catch (const cv::Exception& e) {
    *error = path.string() + ": cannot write image (" + e.msg + ")";
  }
  return false;
}

}  // namespace

SnapshotResult write_snapshot(const std::string& parent_dir, const cv::Mat& frame, const FrameTrace& trace,
                              const std::array<cv::Mat, kStageCount>* views) {
  SnapshotResult res;
  try {
    const fs::path parent(parent_dir.empty() ? "." : parent_dir);
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec || !fs::is_directory(parent)) {
      res.error = parent.string() + ": cannot create folder" + (ec ? " (" + ec.message() + ")" : std::string());
      return res;
    }
    // create_directory reports whether it made the folder, so two snapshots in one second never share one.
    const std::string base = "snapshot-" + timestamp();
    fs::path dir;
    for (int n = 1; n <= 1000 && dir.empty(); ++n) {
      const fs::path candidate = parent / (n == 1 ? base : base + "-" + std::to_string(n));
      if (fs::create_directory(candidate, ec)) dir = candidate;
      else if (ec) {
        res.error = candidate.string() + ": cannot create folder (" + ec.message() + ")";
        return res;
      }
    }
    if (dir.empty()) {
      res.error = (parent / base).string() + ": too many snapshots in one second";
      return res;
    }
    res.dir = dir.string();

    auto png = [&](const std::string& name, const cv::Mat& img) {
      if (!write_png(dir / name, img, &res.error)) return false;
      res.files.push_back(name);
      return true;
    };
    if (!frame.empty() && !png("frame.png", frame)) return res;
    for (const StageRecord& s : trace.stages) {
      // The stage's picture (trace_view.hpp) when given, else the image the pipeline kept, if any.
      const cv::Mat* img = &s.image;
      if (views && !(*views)[static_cast<size_t>(s.stage)].empty()) img = &(*views)[static_cast<size_t>(s.stage)];
      if (img->empty()) continue;
      char name[64];
      std::snprintf(name, sizeof name, "%02d_%s.png", static_cast<int>(s.stage), std::string(stage_name(s.stage)).c_str());
      if (!png(name, *img)) return res;
    }
    bool made_candidates = false;
    for (size_t i = 0; i < trace.candidates.size(); ++i) {
      const CandidateRecord& c = trace.candidates[i];
      if (c.warp.empty()) continue;
      if (!made_candidates) {
        fs::create_directory(dir / "candidates", ec);
        if (ec) {
          res.error = (dir / "candidates").string() + ": cannot create folder (" + ec.message() + ")";
          return res;
        }
        made_candidates = true;
      }
      char stem[32];
      std::snprintf(stem, sizeof stem, "candidates/%03zu", i);
      if (!png(std::string(stem) + "_warp.png", c.warp)) return res;
      if (!c.bits.empty()) {
        // Cells of 0/1 as 8x8 black/white squares, so the grid is visible at a glance.
        cv::Mat grid;
        cv::resize(c.bits * 255, grid, c.bits.size() * 8, 0, 0, cv::INTER_NEAREST);
        if (!png(std::string(stem) + "_bits.png", grid)) return res;
      }
    }
    const fs::path json = dir / "trace.json";
    std::ofstream out(json, std::ios::binary);
    out << trace_to_json(trace) << "\n";
    out.close();
    if (!out) {
      res.error = json.string() + ": cannot write";
      return res;
    }
    res.files.push_back("trace.json");
    res.ok = true;
  } catch (const std::exception& e) {
    // Allocation or filesystem failures not reported through error codes.
    res.error = (res.dir.empty() ? parent_dir : res.dir) + ": " + one_line_reason(e);
    res.ok = false;
  }
  return res;
}

}  // namespace arwb
