// ARWB_SIMD_CAP=LEVEL (none, ssse3, avx2, avx512 or avx512vbmi) caps the kernels' level for a whole run of the
// detector's tests: `ARWB_SIMD_CAP=none ctest -L detect` runs the detector end to end on its plain kernels, as on a
// processor without x86 extensions (.ci/run does). A name it does not know stops the run, naming it.
#include "detect/kernels/simd.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

namespace arwb {
namespace {

class SimdCapFromEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    const char* wanted = std::getenv("ARWB_SIMD_CAP");
    if (!wanted) return;
    for (int level = int(Simd::none); level <= int(Simd::avx512_vbmi); ++level)
      if (std::string(wanted) == simd_name(Simd(level))) {
        cap_ = std::make_unique<SimdCap>(Simd(level));
        return;
      }
    // Not FAIL(): a failure in an environment's SetUp skips every test, and ctest counts skipped tests as passed.
    std::fprintf(stderr, "ARWB_SIMD_CAP=%s: not a level (none, ssse3, avx2, avx512, avx512vbmi)\n", wanted);
    std::exit(2);
  }
  void TearDown() override { cap_.reset(); }

 private:
  std::unique_ptr<SimdCap> cap_;
};

// gtest_main runs RUN_ALL_TESTS after every file's statics: the environment is registered by then.
[[maybe_unused]] ::testing::Environment* const registered =
    ::testing::AddGlobalTestEnvironment(new SimdCapFromEnvironment);

}  // namespace
}  // namespace arwb
