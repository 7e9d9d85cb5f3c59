// arwb bench --tracking's measure on a short run: the filter lowers a still marker's jitter and keeps the lag of
// a moving one small.
#include "cli/bench_tracking.hpp"

#include <gtest/gtest.h>

namespace arwb {
namespace {

TEST(BenchTracking, FilteredJitterBelowRawAndLagBounded) {
  TrackingBenchOptions o;
  o.frames = 40;
  const TrackingBench b = run_tracking_bench(o);
  ASSERT_TRUE(b.error.empty()) << b.error;
  EXPECT_GE(b.still_frames, 25);
  EXPECT_GE(b.moving_frames, 25);
  EXPECT_GT(b.raw.jitter_px, 0);
  EXPECT_LT(b.filtered.jitter_px, 0.6 * b.raw.jitter_px);
  EXPECT_LT(b.filtered.jitter_deg, b.raw.jitter_deg);
  // At 120 px/s (4 px a frame) the filtered corners trail by under a pixel; the raw ones do not trail.
  EXPECT_LT(b.filtered.lag_px, 1.0);
  EXPECT_LT(std::abs(b.raw.lag_px), 0.3);
}

}  // namespace
}  // namespace arwb
