// Row kernels written once with Highway's portable vectors (Debian's libhwy-dev), compiled for the including
// file's instruction set (static dispatch: that file's flags pick Highway's target). Kept where they measured at
// least as fast as the hand-written path of their level (the closing notes of issue 43 give the figures).
// Included inside the including file's anonymous namespace after <hwy/highway.h>.

namespace hn = hwy::HWY_NAMESPACE;

// blend_row's vertically blended means, 3 near + far, a vector of 16-bit lanes a step; returns how many it did.
inline int blend_row_hwy(const uint8_t* near, const uint8_t* far, uint16_t* v, int n) {
  const hn::ScalableTag<uint16_t> d16;
  const hn::Rebind<uint8_t, decltype(d16)> d8;   // as many bytes as d16 has lanes
  const int lanes = int(hn::Lanes(d16));
  int i = 0;
  for (; i + lanes <= n; i += lanes) {
    const auto a = hn::PromoteTo(d16, hn::LoadU(d8, near + i)), f = hn::PromoteTo(d16, hn::LoadU(d8, far + i));
    hn::StoreU(hn::Add(hn::Add(hn::ShiftLeft<1>(a), a), f), d16, v + i);
  }
  return i;
}
