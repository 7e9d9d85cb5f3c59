// contours' small regions: passes over a binary image's bit masks (BitRows) that take out its specks and its small
// regions, in plain C++ over words of the type W: one uint64_t at a time (plain.cpp's Scalar) or N in the
// compiler's vector extension (VectorWords<N>: four in avx2.cpp, one AVX2 instruction each; two in simd128.cpp).
// Each W has load, store, left<S>, right<S> and bits (a popcount), and the operators |, &, ^, ~.
// Included inside each of those files' anonymous namespace after <cstring>: every function has internal linkage,
// so no copy built with one level's flags is linked into another's callers.

// (GCC drops vector_size on a typedef whose size depends on a template parameter: one type per N, spelled out.)
template <int N> struct WordVector;
template <> struct WordVector<2> { typedef uint64_t V __attribute__((vector_size(16))); };
template <> struct WordVector<4> { typedef uint64_t V __attribute__((vector_size(32))); };

template <int N>
struct VectorWords {
  using V = typename WordVector<N>::V;
  static constexpr int kWords = N;
  [[gnu::always_inline]] static V load(const uint64_t* at) {
    V v;
    std::memcpy(&v, at, sizeof v);
    return v;
  }
  [[gnu::always_inline]] static void store(uint64_t* at, V v) { std::memcpy(at, &v, sizeof v); }
  template <int S> [[gnu::always_inline]] static V left(V v) { return v << S; }
  template <int S> [[gnu::always_inline]] static V right(V v) { return v >> S; }
  [[gnu::always_inline]] static int bits(V v) {
    int n = 0;
    for (int i = 0; i < N; ++i) n += __builtin_popcountll(v[i]);
    return n;
  }
};

// Bit x of the result: pixel x - S (S > 0, from the left) or x + |S| (S < 0) of the word(s) at `at`, with the
// word before or after.
template <typename W, int S>
[[gnu::always_inline]] inline typename W::V moved(const uint64_t* at) {
  if constexpr (S > 0) return W::template left<S>(W::load(at)) | W::template right<64 - S>(W::load(at - 1));
  else return W::template right<-S>(W::load(at)) | W::template left<64 + S>(W::load(at + 1));
}

// Each pixel set where a pixel within R of it along the row is.
template <typename W, int R>
[[gnu::always_inline]] inline typename W::V spread_along(const uint64_t* at) {
  if constexpr (R == 0) return W::load(at);
  else return spread_along<W, R - 1>(at) | moved<W, R>(at) | moved<W, -R>(at);
}

// The pixels of rows y - R .. y + R, at the word(s) of row y at `at`.
template <typename W, int R>
[[gnu::always_inline]] inline typename W::V rows_around(const uint64_t* at, ptrdiff_t stride) {
  typename W::V v = W::load(at);
  for (int dy = 1; dy <= R; ++dy) v = v | W::load(at - dy * stride) | W::load(at + dy * stride);
  return v;
}

// Takes the specks out of `bits`, the pixels on with none of their eight neighbours on (each a region of its own),
// and returns how many it took when Count (else 0): in one pass, each pixel kept where a neighbour is on (into
// `scratch`, then back). On a noisy threshold the specks sit in the rings drop_small_regions_body reads, and would
// keep the small regions they ring from being taken: so they go first.
template <typename W, bool Count>
[[gnu::always_inline]] inline int drop_specks_body(const BitRows& bits, uint64_t* scratch) {
  const ptrdiff_t s = bits.stride(), n = ptrdiff_t(bits.length());
  uint64_t* on = bits.first();
  uint64_t* near = scratch + (on - bits.base);
  for (ptrdiff_t i = 0; i < n; i += W::kWords)
    W::store(near + i, spread_along<W, 1>(on + i - s) | spread_along<W, 1>(on + i + s) | moved<W, 1>(on + i) |
                           moved<W, -1>(on + i));
  int count = 0;
  for (ptrdiff_t i = 0; i < n; i += W::kWords) {
    const typename W::V m = W::load(on + i), kept = m & W::load(near + i);
    if constexpr (Count) count += W::bits(m & ~kept);
    W::store(on + i, kept);
  }
  return count;
}

// Takes out of `bits` every region that fits in a K x K window (K odd) with no pixel on in the ring of pixels just
// outside it, and returns how many it took when Count (else 0). Such a region is a whole region (a step out of the
// window lands on the ring), and nearly every region that fits in K x K pixels has such a window: those go, without
// labelling a pixel. Per window centre the ring is read as whole words: its rows
// above and below, spread along the row, and its columns at each side, from the rows beside the centre's. The
// pixels within r = K / 2 of a centre whose ring is empty are the ones taken. A centre beside the image is as good
// as one in it (the pixels there are off). Each pass runs along the whole array of rows, W::kWords words a step
// (the arrays' padding takes the last step's overrun). A region with another region's pixel in every ring around
// it stays, and is counted and left untraced as before.
// The count, for K = 3: Gray's bit-quad Euler number of the pixels taken (for
// 8-connected regions: the number of 2x2 blocks with one pixel on, less those with three, less twice the diagonal
// pairs, over 4) is their regions less their holes, and a region in 3x3 pixels has a hole only at its centre, an off
// pixel with its four neighbours on.
template <typename W, int K, bool Count>
[[gnu::always_inline]] inline int drop_small_regions_body(const BitRows& bits, uint64_t* scratch) {
  static_assert(K % 2 == 1 && K >= 3 && K / 2 + 1 <= BitRows::kPad,
                "the ring's rows must lie within the masks' padding (and specks have drop_specks_body)");
  static_assert(K <= 3 || !Count, "the count knows the holes of regions in 3x3 pixels only");
  constexpr int r = K / 2, d = r + 1, step = W::kWords;
  const ptrdiff_t s = bits.stride(), n = ptrdiff_t(bits.length());
  const BitRows spread{scratch, bits.words, bits.h}, column{scratch + bits.size(), bits.words, bits.h},
      empty_ring{scratch + 2 * bits.size(), bits.words, bits.h};
  spread.clear_padding();
  column.clear_padding();
  empty_ring.clear_padding();
  uint64_t* on = bits.first();
  uint64_t *sp = spread.first(), *v = column.first(), *f = empty_ring.first();
  for (ptrdiff_t i = 0; i < n; i += step) {
    W::store(sp + i, spread_along<W, d>(on + i));    // the ring's rows above and below
    W::store(v + i, rows_around<W, r>(on + i, s));   // its columns, before they are moved aside
  }
  for (ptrdiff_t i = 0; i < n; i += step)
    W::store(f + i, ~(W::load(sp + i - d * s) | W::load(sp + i + d * s) | moved<W, d>(v + i) | moved<W, -d>(v + i)));
  // A last step past the rows found centres below the image whose ring's columns it could not read (the word after
  // it was never written): they certify nothing. Every other word the passes read past the rows is zero, as the
  // pixels there are (`Stages.SmallRegionsLeaveALongBarOnTheLastRowWhole`).
  for (uint64_t* p = f + n; p < empty_ring.base + empty_ring.size(); ++p) *p = 0;
  // The pixels near a centre whose ring is empty: those centres spread along their rows (into `spread`, its rings'
  // rows no longer needed) and over the rows around.
  for (ptrdiff_t i = 0; i < n; i += step) W::store(sp + i, spread_along<W, r>(f + i));
  uint64_t* taken = v;   // the pixels taken, for the count (`column` no longer needed)
  int count = 0;
  for (ptrdiff_t i = 0; i < n; i += step) {
    const typename W::V m = W::load(on + i), t = m & rows_around<W, r>(sp + i, s);
    W::store(on + i, m & ~t);
    if constexpr (Count) W::store(taken + i, t);
  }
  if constexpr (Count) {
    // The last step's overrun wrote past the rows: the count reads the padding below them.
    for (uint64_t* p = taken + n; p < column.base + column.size(); ++p) *p = 0;
    int one = 0, three = 0, diagonal = 0, holes = 0;
    // The 2x2 blocks of pixels x - 1 and x of rows y and y + 1, from y = -1.
    for (ptrdiff_t i = -s; i < n; i += step) {
      const typename W::V tl = moved<W, 1>(taken + i), tr = W::load(taken + i), bl = moved<W, 1>(taken + i + s),
                          br = W::load(taken + i + s);
      const typename W::V odd = tl ^ tr ^ bl ^ br, two = (tl & tr) | (bl & br) | ((tl | tr) & (bl | br));
      one += W::bits(odd & ~two);
      three += W::bits(odd & two);
      diagonal += W::bits((tl & br & ~tr & ~bl) | (tr & bl & ~tl & ~br));
    }
    for (ptrdiff_t i = 0; i < n; i += step)
      holes += W::bits(~W::load(taken + i) & W::load(taken + i - s) & W::load(taken + i + s) &
                       moved<W, 1>(taken + i) & moved<W, -1>(taken + i));
    count = (one - three - 2 * diagonal) / 4 + holes;
  }
  return count;
}

// The kernels' entries (kernels.hpp's drop_specks and drop_small_regions) over words of W.
template <typename W>
int drop_specks_of(const BitRows& bits, uint64_t* scratch, bool count) {
  return count ? drop_specks_body<W, true>(bits, scratch) : drop_specks_body<W, false>(bits, scratch);
}
template <typename W>
int drop_small_regions_of(const BitRows& bits, int k, bool count, uint64_t* scratch) {
  if (k == 5) return drop_small_regions_body<W, 5, false>(bits, scratch);
  return count ? drop_small_regions_body<W, 3, true>(bits, scratch)
               : drop_small_regions_body<W, 3, false>(bits, scratch);
}
