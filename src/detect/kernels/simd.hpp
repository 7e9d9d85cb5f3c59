// The vector instruction sets the detector's kernels choose between at run time (kernels.hpp: one table of kernels
// per level). A test caps the level with SimdCap to run every level the processor has, and checks each against the
// plain one.
#pragma once

#include <atomic>
#include <vector>

namespace arwb {

// In order: each level includes the ones before it. The levels are the processor's: in WebAssembly, level 1 is its
// SIMD128 and the only one above none.
enum class Simd : int {
  none = 0,
  ssse3,         // SSSE3
  simd128 = ssse3,   // WebAssembly's SIMD128
  avx2,          // AVX2 and POPCNT
  avx512,        // AVX-512 F, BW and VL (Skylake-X and later)
  avx512_vbmi,   // and VBMI, VNNI and VPOPCNTDQ (Ice Lake and later, Zen 4): the grey conversion's byte permutes
                 // and dot products, identification's vector popcounts
};

namespace detail {
// simd()'s answer, set when the program starts and by SimdCap.
extern std::atomic<int> simd_level;
}  // namespace detail

// The widest level the processor has, below the cap when a SimdCap is alive. Inline, one load.
inline Simd simd() { return Simd(detail::simd_level.load(std::memory_order_relaxed)); }
// The processor's own level, whatever the cap; none in a build with only the plain kernels (ARWB_PLAIN_KERNELS).
Simd simd_of_cpu();
// "none", "ssse3", "avx2", "avx512", "avx512vbmi".
const char* simd_name(Simd level);
// none .. simd_of_cpu(): the levels a test can run here.
std::vector<Simd> simd_levels_here();

// Caps simd() at `most` while it lives (for every thread: tests run one path at a time), then puts the cap back.
class SimdCap {
 public:
  explicit SimdCap(Simd most);
  ~SimdCap();
  SimdCap(const SimdCap&) = delete;
  SimdCap& operator=(const SimdCap&) = delete;

 private:
  int previous_;
};

}  // namespace arwb
