// contours' runs: a row's edge words and the joins to the row above, in plain C++ that plain.cpp builds as it is and
// avx2.cpp builds with POPCNT (x86-64's baseline has none, and the compiler's stand-in was several times slower).
// Included inside each of those files' anonymous namespace: no #include here, and every function has internal
// linkage, so no copy built with one level's flags is linked into another's callers.

[[gnu::always_inline]] inline int popcount64(uint64_t v) { return __builtin_popcountll(v); }

// The edges left of pixel x (0 <= x <= 64 * (words + 1) - 1) of a row whose edge words are `e`.
[[gnu::always_inline]] inline int rank(const EdgeWords& e, int x) {
  const uint64_t below = e.bits[x >> 6] & ((uint64_t(1) << (x & 63)) - 1);
  return e.before[x >> 6] + popcount64(below);
}

[[gnu::always_inline]] inline int find_edges_body(const uint64_t* mid, int words, EdgeWords out) {
  uint64_t carry = 0;   // the pixel before the current 64, as bit 0
  int n = 0;
  for (int c = 0; c <= words; ++c) {
    const uint64_t m = mid[c];
    const uint64_t e = m ^ ((m << 1) | carry);
    carry = m >> 63;
    out.bits[c] = e;
    out.before[c] = n;
    n += popcount64(e);
  }
  return n;
}

// Union-find over the runs: a run's parent is never after it, so a root is the first run of its region in raster
// order, which holds the region's top-left pixel.
inline int find_root(int* parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];   // path halving
    i = parent[i];
  }
  return i;
}

// [a0,a1) and [b0,b1) on neighbouring rows touch (8-connected) when a0 <= b1 and b0 <= a1. A row's edges go up in
// turn, a0 < a1 < the next a0: the runs above wholly before b (a1 < b0) are half the edges left of b0, rounded down,
// and those that begin by b's end (a0 <= b1) half the edges left of b1 + 1, rounded up. Each is a count of bits in
// the row above's edge words, with no walk and no branch on the data but the number touched.
[[gnu::always_inline]] inline void join_row_body(EdgeWords above, int above_begin, const int* ends, int begin, int n,
                                                 int* parent) {
  for (int k = 0; k < n; ++k) {
    const int first = rank(above, ends[2 * k]) / 2, last = (rank(above, ends[2 * k + 1] + 1) + 1) / 2;
    // A run that touches one run above (nearly every run of a large region) takes that run's parent, a run of
    // the same region and before it, without looking for the root: the final pass takes every run to its root. A
    // run that touches none is its own. The choice as a mask: as `first < last ? ... : self` GCC made it a branch,
    // which a noisy row mispredicts.
    const int self = begin + k, touches = -int(first < last);
    parent[self] = (parent[above_begin + first] & touches) | (self & ~touches);
    if (last - first < 2) continue;
    // It touches two or more: their regions are one, under the earliest root.
    int joined = find_root(parent, parent[self]);
    for (int a = above_begin + first + 1; a < above_begin + last; ++a) {
      const int r = find_root(parent, a);
      if (r < joined) {
        parent[joined] = r;
        joined = r;
      } else if (r > joined) {
        parent[r] = joined;
      }
    }
  }
}
