// identification's scans of a dictionary's codes (codes[4 id + k]: marker id turned k quarter-turns), in plain C++
// that plain.cpp builds as it is and avx2.cpp builds with POPCNT. Included inside each of those files' anonymous
// namespace: no #include here, and every function has internal linkage.

// The first exact match, else the lowest id, then rotation, at the smallest distance.
[[gnu::always_inline]] inline CodeMatch scan_nearest(const uint64_t* codes, int n, uint64_t code) {
  CodeMatch best{-1, 0, 65};
  for (int id = 0; id < n; ++id)
    for (int k = 0; k < 4; ++k) {
      const int d = __builtin_popcountll(code ^ codes[4 * id + k]);
      if (d < best.hamming) {
        best = {id, k, d};
        if (d == 0) return best;   // nothing later replaces the first exact match (ties keep the lowest)
      }
    }
  return best;
}

[[gnu::always_inline]] inline void scan_per_rotation(const uint64_t* codes, int n, uint64_t code, CodeMatch* out4) {
  for (int k = 0; k < 4; ++k) out4[k] = {-1, 0, 65};
  for (int id = 0; id < n; ++id)
    for (int k = 0; k < 4; ++k) {
      const int d = __builtin_popcountll(code ^ codes[4 * id + k]);
      if (d < out4[k].hamming) out4[k] = {id, k, d};
    }
}
