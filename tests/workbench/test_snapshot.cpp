// write_snapshot: a new folder per snapshot with the frame, the stage images, candidate views and trace.json.
#include "workbench/snapshot.hpp"
#include "detect/detector.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>

using namespace arwb;
namespace fs = std::filesystem;

namespace {

struct TracedFrame {
  cv::Mat image;
  FrameTrace trace;
};

TracedFrame traced_frame() {
  const Dictionary d = make_aruco_original();
  TracedFrame f;
  f.image = cv::Mat(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
  draw_marker(f.image, d, 12, project_square({160, 120}, 80, 10, 0, 0, 800));
  Detector({d}).detect(f.image, &f.trace, TraceLevel::full);
  return f;
}

bool listed(const SnapshotResult& r, const std::string& name) {
  return std::find(r.files.begin(), r.files.end(), name) != r.files.end();
}

}  // namespace

TEST(Snapshot, WritesFrameStageImagesCandidatesAndTrace) {
  test::TempDir tmp;
  const TracedFrame f = traced_frame();
  ASSERT_EQ(f.trace.markers.size(), 1u);
  const std::string parent = tmp.str("snaps/nested");  // made when missing
  const SnapshotResult r = write_snapshot(parent, f.image, f.trace);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.error.empty());
  const fs::path dir(r.dir);
  EXPECT_EQ(dir.parent_path(), fs::path(parent));
  EXPECT_EQ(dir.filename().string().rfind("snapshot-", 0), 0u) << dir;
  EXPECT_EQ(dir.filename().string().size(), std::string("snapshot-YYYYMMDD-HHMMSS").size()) << dir;

  for (const auto& name : r.files) EXPECT_TRUE(fs::is_regular_file(dir / name)) << name;
  EXPECT_TRUE(listed(r, "frame.png"));
  EXPECT_TRUE(listed(r, "trace.json"));
  // Stage images: acquisition (grey), decimation (the search image) and adaptive_threshold (binary) carry images
  // at full level.
  int stage_files = 0;
  for (const auto& s : f.trace.stages) {
    if (s.image.empty()) continue;
    char name[64];
    std::snprintf(name, sizeof name, "%02d_%s.png", int(s.stage), std::string(stage_name(s.stage)).c_str());
    EXPECT_TRUE(listed(r, name)) << name;
    const cv::Mat back = cv::imread((dir / name).string(), cv::IMREAD_UNCHANGED);
    EXPECT_EQ(back.size(), s.image.size()) << name;
    ++stage_files;
  }
  EXPECT_GE(stage_files, 2);
  EXPECT_TRUE(listed(r, "03_adaptive_threshold.png"));
  // The accepted candidate's frontal view and bit grid.
  const int accepted = [&] {
    for (int i = 0; i < int(f.trace.candidates.size()); ++i)
      if (f.trace.candidates[size_t(i)].fate.stage == Stage::accepted) return i;
    return -1;
  }();
  ASSERT_GE(accepted, 0);
  char warp[64], bits[64];
  std::snprintf(warp, sizeof warp, "candidates/%03d_warp.png", accepted);
  std::snprintf(bits, sizeof bits, "candidates/%03d_bits.png", accepted);
  EXPECT_TRUE(listed(r, warp)) << warp;
  EXPECT_TRUE(listed(r, bits)) << bits;
  EXPECT_EQ(cv::imread((dir / warp).string(), cv::IMREAD_UNCHANGED).size(), f.trace.candidates[size_t(accepted)].warp.size());

  const cv::Mat frame = cv::imread((dir / "frame.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(frame.size(), f.image.size());
  EXPECT_EQ(cv::norm(frame, f.image, cv::NORM_INF), 0);
  const auto json = nlohmann::json::parse(test::read_file((dir / "trace.json").string()), nullptr, false);
  ASSERT_TRUE(json.is_object());
  ASSERT_FALSE(json["markers"].empty());
  EXPECT_EQ(json["markers"][0]["id"], 12);
  EXPECT_TRUE(std::any_of(json["stages"].begin(), json["stages"].end(),
                          [](const nlohmann::json& s) { return s["name"] == "corner_refinement"; }));
}

TEST(Snapshot, EverySnapshotGetsANewFolder) {
  test::TempDir tmp;
  const TracedFrame f = traced_frame();
  const SnapshotResult a = write_snapshot(tmp.str(), f.image, f.trace);
  const SnapshotResult b = write_snapshot(tmp.str(), f.image, f.trace);
  const SnapshotResult c = write_snapshot(tmp.str(), f.image, f.trace);
  ASSERT_TRUE(a.ok && b.ok && c.ok) << a.error << b.error << c.error;
  EXPECT_NE(a.dir, b.dir);
  EXPECT_NE(b.dir, c.dir);
  EXPECT_NE(a.dir, c.dir);
  // Each folder has its own complete set: nothing was written into an earlier one.
  for (const auto* r : {&a, &b, &c}) {
    size_t n = 0;
    for (const auto& e : fs::recursive_directory_iterator(r->dir))
      if (e.is_regular_file()) ++n;
    EXPECT_EQ(n, r->files.size()) << r->dir;
  }
}

TEST(Snapshot, AnUnwritableParentIsAnErrorNamingThePath) {
  test::TempDir tmp;
  const TracedFrame f = traced_frame();
  test::write_file(tmp.str("plain_file"), "not a folder");
  const std::string parent = tmp.str("plain_file") + "/snaps";
  const SnapshotResult r = write_snapshot(parent, f.image, f.trace);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find(parent), std::string::npos) << r.error;
  EXPECT_TRUE(r.files.empty());
}

TEST(Snapshot, ASummaryTraceWritesTheFrameAndTraceOnly) {
  test::TempDir tmp;
  const TracedFrame f = traced_frame();
  FrameTrace summary;
  Detector({make_aruco_original()}).detect(f.image, &summary, TraceLevel::summary);
  const SnapshotResult r = write_snapshot(tmp.str(), f.image, summary);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.files, (std::vector<std::string>{"frame.png", "trace.json"}));
}
