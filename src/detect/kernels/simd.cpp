// The processor's level, the cap and the names (simd.hpp).
#include "detect/kernels/simd.hpp"

#include <algorithm>
#include <atomic>

namespace arwb {
namespace {

Simd detect_cpu() {
#if defined(ARWB_PLAIN_KERNELS)
  return Simd::none;
#elif defined(__wasm_simd128__)
  return Simd::simd128;   // a module with SIMD instructions does not load where there is none
#elif defined(__x86_64__)
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("ssse3")) return Simd::none;
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("popcnt")) return Simd::ssse3;
  if (!__builtin_cpu_supports("avx512f") || !__builtin_cpu_supports("avx512bw") ||
      !__builtin_cpu_supports("avx512vl"))
    return Simd::avx2;
  if (!__builtin_cpu_supports("avx512vbmi") || !__builtin_cpu_supports("avx512vnni") ||
      !__builtin_cpu_supports("avx512vpopcntdq"))
    return Simd::avx512;
  return Simd::avx512_vbmi;
#else
  return Simd::none;
#endif
}

std::atomic<int> cap{int(Simd::avx512_vbmi)};

}  // namespace

Simd simd_of_cpu() {
  static const Simd cpu = detect_cpu();
  return cpu;
}

// (Before this is set, while other files' statics start, simd() says none: the plain paths, never a wrong one. A
// SimdCap made then is kept: the cap is set before any file's statics start.)
std::atomic<int> detail::simd_level{std::min(int(simd_of_cpu()), cap.load())};

const char* simd_name(Simd level) {
  switch (level) {
    case Simd::none: return "none";
#if defined(__wasm_simd128__)
    case Simd::simd128: return "simd128";
#else
    case Simd::ssse3: return "ssse3";
#endif
    case Simd::avx2: return "avx2";
    case Simd::avx512: return "avx512";
    case Simd::avx512_vbmi: return "avx512vbmi";
  }
  return "?";
}

std::vector<Simd> simd_levels_here() {
  std::vector<Simd> levels;
  for (int l = 0; l <= int(simd_of_cpu()); ++l) levels.push_back(Simd(l));
  return levels;
}

SimdCap::SimdCap(Simd most) : previous_(cap.exchange(int(most))) {
  detail::simd_level.store(std::min(int(simd_of_cpu()), int(most)));
}
SimdCap::~SimdCap() {
  cap.store(previous_);
  detail::simd_level.store(std::min(int(simd_of_cpu()), previous_));
}

}  // namespace arwb
