// Whether the test binary is the sanitizer tree's (.ci/run), and skipping there what repeats itself.
#pragma once
#include <gtest/gtest.h>

namespace arwb::test {

// True in the sanitizer tree (clang's AddressSanitizer, or GCC's).
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif
#else
inline constexpr bool kSanitized = false;
#endif

// Skips, in the sanitizer tree only, a test that repeats many times over what other tests there run once (a
// statistic over seeds): the sanitizers look for memory and undefined-behaviour faults, which one run finds as well
// as ten, and the repeats cost minutes there. The plain tree runs it in full.
#define ARWB_SKIP_WHEN_SANITIZED(why) \
  if (::arwb::test::kSanitized) GTEST_SKIP() << "not in the sanitizer tree: " << (why)

}  // namespace arwb::test
