// The vector levels: the cap, and the kernel table of each level.
#include "detect/detector.hpp"
#include "detect/params.hpp"
#include "detect/pipeline.hpp"
#include "detect/kernels/simd.hpp"
#include "synth/synth.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <string>

using namespace arwb;

TEST(Kernels, SimdCapLowersTheLevelAndPutsItBack) {
  const Simd cpu = simd_of_cpu();
  // The processor's level, or the run's cap (ARWB_SIMD_CAP: kernels/simd_cap_from_environment.cpp).
  const Simd start = simd();
  EXPECT_LE(int(start), int(cpu));
  if (const char* cap = std::getenv("ARWB_SIMD_CAP"))
    EXPECT_TRUE(start == cpu || simd_name(start) == std::string(cap)) << simd_name(start) << " under " << cap;
  else
    EXPECT_EQ(start, cpu);
  {
    SimdCap none(Simd::none);
    EXPECT_EQ(simd(), Simd::none);
    {
      SimdCap all(Simd::avx512_vbmi);
      EXPECT_EQ(simd(), cpu);   // never above the processor's
    }
    EXPECT_EQ(simd(), Simd::none);
  }
  EXPECT_EQ(simd(), start);
  EXPECT_EQ(simd_levels_here().back(), cpu);
  EXPECT_STREQ(simd_name(Simd::avx2), "avx2");
  EXPECT_STREQ(simd_name(Simd::avx512_vbmi), "avx512vbmi");
}

// The grey levels are cvtColor's to the level for every colour (the stages' own conversion is vectorised apart from
// OpenCV's), in a whole frame and in tiles whose rows end off the vector width.
