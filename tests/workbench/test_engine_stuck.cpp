// The safety net under the scene limits: a worker stuck in a library call that never returns (simulated by a
// test-only C function; no scene can reach one) does not keep the workbench from quitting. Engine::stop gives up
// after its timeout and the Engine can be destroyed at once; the worker finishes later on its own state.
#include "script/lua_host.hpp"
#include "support/support.hpp"
#include "workbench/engine.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace arwb {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::atomic<bool> g_stalled{false};
std::atomic<bool> g_release{false};

// A "library call" that returns only when the test says so.
int stall(lua_State*) {
  g_stalled = true;
  while (!g_release) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  return 0;
}

struct Messages {
  std::mutex mutex;
  std::vector<std::string> lines;
  bool has(const std::string& needle) {
    std::lock_guard lock(mutex);
    for (const auto& l : lines)
      if (l.find(needle) != std::string::npos) return true;
    return false;
  }
};

template <typename Pred>
bool wait_until(Pred ok, double seconds) {
  const auto t0 = Clock::now();
  while (!ok()) {
    if (seconds_since(t0) > seconds) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

TEST(EngineStuck, StoppingGivesUpOnAWorkerStuckInAScriptAndTheEngineGoesAtOnce) {
  script::set_test_global("stall", stall);
  test::TempDir dir;
  const std::string scene = dir.str("scene.lua");
  test::write_file(scene, "stall()\nmarker(0, { media = text \"zero\" })\n");
  EngineConfig c;
  c.scene_file = scene;
  // The log outlives the Engine: the detached worker may still write to it.
  auto messages = std::make_shared<Messages>();
  Clock::time_point t0;
  {
    Engine engine(c, [messages](int, const std::string& m) {
      std::lock_guard lock(messages->mutex);
      messages->lines.push_back(m);
    });
    engine.start();
    ASSERT_TRUE(wait_until([] { return g_stalled.load(); }, 20)) << "the scene never started";
    t0 = Clock::now();
    EXPECT_FALSE(engine.stop(0.5));
    EXPECT_LT(seconds_since(t0), 2.0);
  }
  EXPECT_LT(seconds_since(t0), 2.0);   // destroying it did not wait either
  EXPECT_TRUE(messages->has("the worker did not stop within 0.5 s (it was loading the scene's script); quitting without it"));

  // Let the worker finish, so the test leaves nothing running: the call returns past its time, so the load fails
  // with the limit's message, the worker sees it should stop and ends.
  g_release = true;
  EXPECT_TRUE(wait_until([&] { return messages->has("ran longer than 250 ms while loading the scene"); },
                         20)) << [&] {
    std::lock_guard lock(messages->mutex);
    std::string all;
    for (const auto& l : messages->lines) all += l + "\n";
    return all;
  }();
  // The worker's state holds the log function and so a copy of `messages`: the count falls to ours alone when the
  // thread has let go of it. Leaving before then lets process exit tear down OpenCV's thread-local storage under a
  // worker still using it (seen under the sanitizers on a loaded machine).
  EXPECT_TRUE(wait_until([&] { return messages.use_count() == 1; }, 60))
      << "the detached worker never ended";
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  script::set_test_global(nullptr, nullptr);
}

}  // namespace
}  // namespace arwb
