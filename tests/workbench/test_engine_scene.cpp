// Scenes in the workbench's worker, without a window: media placed on the synthetic source's markers, the file
// reloaded when it changes on disk (a broken edit keeps the last good scene), and a runaway callback or a
// memory bomb stopped with a message while frames keep coming.
#include "workbench/engine.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <filesystem>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace arwb {
namespace {

using test::TempDir;
using test::write_file;

EngineConfig config_with_scene(const std::string& scene) {
  EngineConfig c;
  c.acquisition.fps_cap = 40;
  c.scene_file = scene;
  return c;
}

// Waits (up to `seconds`) for a frame satisfying `ok`.
template <typename Pred>
std::shared_ptr<const Frame> wait_for(Engine& e, Pred ok, double seconds = 10) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  uint64_t seen = 0;
  while (std::chrono::steady_clock::now() < end) {
    auto f = e.wait_newer(seen, 0.5);
    if (!f) continue;
    seen = f->index;
    if (ok(*f)) return f;
  }
  return nullptr;
}

bool console_has(const Frame& f, const std::string& part) {
  for (const auto& l : f.scene.console)
    if (l.text.find(part) != std::string::npos) return true;
  return false;
}

TEST(EngineScene, PlacesMediaOnTheSyntheticMarkers) {
  TempDir d;
  cv::imwrite(d.str("red.png"), cv::Mat(20, 20, CV_8UC3, cv::Scalar(0, 0, 255)));
  write_file(d.str("scene.lua"), "marker({from = 0, to = 1023}, { media = image \"red.png\", place = on_marker() })\n");
  Engine e(config_with_scene(d.str("scene.lua")), [](int, const std::string&) {});
  e.start();
  auto f = wait_for(e, [](const Frame& fr) { return !fr.overlays.empty(); });
  ASSERT_TRUE(f) << "no overlay on any frame";
  EXPECT_TRUE(f->scene.ok);
  EXPECT_EQ(f->overlays.size(), f->tracks.size());
  for (const Overlay& o : f->overlays) {
    ASSERT_TRUE(o.content);
    EXPECT_EQ(o.content->size(), cv::Size(20, 20));
  }
  ASSERT_FALSE(f->scene.mappings.empty());
  EXPECT_EQ(f->scene.mappings[0].ids, "0-1023");
}

TEST(EngineScene, SkippedMappingsAndRuntimeErrorsReachTheLogAndTheFrame) {
  TempDir d;
  write_file(d.str("scene.lua"), R"(marker({from = 0, to = 1023}, { media = image "missing.png" })
marker({from = 0, to = 1023}, {
  on_update = function(m, dt)
    local t = nil
    return t.field
  end,
})
)");
  std::mutex mu;
  std::vector<std::pair<int, std::string>> log;
  Engine e(config_with_scene(d.str("scene.lua")), [&](int level, const std::string& m) {
    std::lock_guard lock(mu);
    log.emplace_back(level, m);
  });
  e.start();
  auto f = wait_for(e, [](const Frame& fr) {
    return fr.scene.mappings.size() == 2 && fr.scene.mappings[1].health == MappingHealth::disabled;
  });
  ASSERT_TRUE(f) << "the failing on_update was never disabled";
  const MappingRow& skipped = f->scene.mappings[0];
  EXPECT_EQ(skipped.health, MappingHealth::skipped);
  EXPECT_EQ(skipped.reason_line, 1);
  EXPECT_NE(skipped.reason.find("missing.png: no such file"), std::string::npos) << skipped.reason;
  EXPECT_EQ(f->scene.mappings[1].reason_line, 5);
  e.stop(2.0);
  std::lock_guard lock(mu);
  int missing = 0, runtime = 0, disabled = 0;
  for (const auto& [level, m] : log) {
    if (level != 2) continue;
    missing += m.find("missing.png: no such file") != std::string::npos;
    runtime += m.find("scene.lua:5: attempt to index a nil value") != std::string::npos;
    disabled += m.find("disabled") != std::string::npos;
  }
  EXPECT_EQ(missing, 1);   // once, not once a frame
  EXPECT_GE(runtime, 1);
  EXPECT_GE(disabled, 1);
}

TEST(EngineScene, ReloadsWhenTheFileChangesAndKeepsTheLastGoodScene) {
  TempDir d;
  cv::imwrite(d.str("a.png"), cv::Mat(20, 40, CV_8UC3, cv::Scalar(0, 0, 255)));
  write_file(d.str("scene.lua"), "marker({from = 0, to = 1023}, { media = image \"a.png\" })\n");
  Engine e(config_with_scene(d.str("scene.lua")), [](int, const std::string&) {});
  e.start();
  auto f = wait_for(e, [](const Frame& fr) { return fr.scene.ok && !fr.overlays.empty(); });
  ASSERT_TRUE(f);
  const uint64_t first = f->scene.generation;

  // A broken edit: reported with its line, the scene in use stays.
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));   // a new modification time
  write_file(d.str("scene.lua"), "marker({from = 0, to = 1023}, { media = image \"a.png\" })\nthis is not lua\n");
  f = wait_for(e, [](const Frame& fr) { return !fr.scene.error.empty(); });
  ASSERT_TRUE(f) << "the broken edit was not noticed";
  EXPECT_NE(f->scene.error.find("scene.lua:2:"), std::string::npos) << f->scene.error;
  EXPECT_EQ(f->scene.error_line, 2);
  EXPECT_TRUE(f->scene.ok);
  EXPECT_EQ(f->scene.generation, first);
  f = wait_for(e, [](const Frame& fr) { return !fr.overlays.empty(); });
  EXPECT_TRUE(f) << "the last good scene stopped placing media";

  // The fix is picked up by itself.
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  write_file(d.str("scene.lua"), "marker({from = 0, to = 1023}, { media = text \"fixed\", place = billboard() })\n");
  f = wait_for(e, [&](const Frame& fr) { return fr.scene.generation > first && fr.scene.error.empty(); });
  ASSERT_TRUE(f) << "the fixed file was not reloaded";
  f = wait_for(e, [](const Frame& fr) { return !fr.overlays.empty(); });
  ASSERT_TRUE(f);
  EXPECT_EQ(f->overlays[0].media.kind, MediaKind::text);
  EXPECT_EQ(f->overlays[0].media.text, "fixed");
}

TEST(EngineScene, RunawayCallbackAndMemoryBombAreStoppedWhileFramesKeepComing) {
  TempDir d;
  cv::imwrite(d.str("a.png"), cv::Mat(20, 20, CV_8UC3, cv::Scalar(0, 255, 0)));
  write_file(d.str("scene.lua"),
             "marker({from = 0, to = 1023}, { media = image \"a.png\" })\n"
             "marker({from = 0, to = 1023}, { on_update = function(m, dt) while true do end end })\n"
             "marker({from = 0, to = 1023}, { on_enter = function(m) local s = string.rep(\"x\", 1e9) end })\n");
  Engine e(config_with_scene(d.str("scene.lua")), [](int, const std::string&) {});
  e.start();
  auto f = wait_for(e, [](const Frame& fr) {
    return console_has(fr, "instruction budget") && console_has(fr, "not enough memory");
  });
  ASSERT_TRUE(f) << "the runaway callback or the memory bomb went unreported";
  const uint64_t at = f->index;
  // Frames keep coming, with the image media still placed.
  f = wait_for(e, [&](const Frame& fr) { return fr.index >= at + 10 && !fr.overlays.empty(); });
  EXPECT_TRUE(f);
}

}  // namespace
}  // namespace arwb
