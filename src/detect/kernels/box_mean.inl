// box_mean written once for a level with vectors of 16-bit words: the k x k mean (k odd, border replicated),
// rounded to the nearest as cv::boxFilter's (a k x k sum over an odd count is never halfway). Each row's sums of k
// along it (k shifted loads a vector, from the row widened to 16 bits once, so that the loads are plain loads, not
// k widening shuffles: those were the bottleneck), then a running sum of k rows down each column, divided by a
// 16-bit multiply-high and a shift. Windows up to 15 (the sums fit 16 bits); false leaves it to cv::boxFilter.
//
// Included inside a level file's anonymous namespace; `W` gives that level's vectors:
//   using V; static constexpr int kLanes;              16-bit words a vector
//   V load(const uint16_t*); void store(uint16_t*, V); V add(V, V); V sub(V, V); V splat(uint16_t);
//   void widen(const uint8_t* in, uint16_t* out);      kLanes levels to words
//   void means(V sum, V half, V mul, int shift, uint8_t* out);   kLanes ((sum + half) * mul) >> (16 + shift)

// One row's sums of K along it from its widened, padded row, in two chains of additions.
template <class W, int K>
int row_sums_k(const uint16_t* pad, int w, uint16_t* out) {
  int x = 0;
  for (; x + W::kLanes <= w; x += W::kLanes) {
    typename W::V even = W::load(pad + x), odd = W::load(pad + x + 1);
    for (int j = 2; j + 1 < K; j += 2) {
      even = W::add(even, W::load(pad + x + j));
      odd = W::add(odd, W::load(pad + x + j + 1));
    }
    if (K % 2) even = W::add(even, W::load(pad + x + K - 1));
    W::store(out + x, W::add(even, odd));
  }
  return x;
}

// One row's sums of k along it (border replicated), through `pad` (w + k - 1 words).
template <class W>
void row_sums(const uint8_t* in, int w, int k, uint16_t* pad, uint16_t* out) {
  const int r = k / 2;
  for (int j = 0; j < r; ++j) pad[j] = in[0];
  int x = 0;
  for (; x + W::kLanes <= w; x += W::kLanes) W::widen(in + x, pad + r + x);
  for (; x < w; ++x) pad[r + x] = in[x];
  for (int j = 0; j < r; ++j) pad[r + w + j] = in[w - 1];
  switch (k) {   // the window's loads unrolled for the sizes the threshold uses (5 to 15)
    case 5: x = row_sums_k<W, 5>(pad, w, out); break;
    case 7: x = row_sums_k<W, 7>(pad, w, out); break;
    case 9: x = row_sums_k<W, 9>(pad, w, out); break;
    case 11: x = row_sums_k<W, 11>(pad, w, out); break;
    case 13: x = row_sums_k<W, 13>(pad, w, out); break;
    case 15: x = row_sums_k<W, 15>(pad, w, out); break;
    default: x = 0;
  }
  for (; x < w; ++x) {
    int sum = 0;
    for (int j = 0; j < k; ++j) sum += pad[x + j];
    out[x] = uint16_t(sum);
  }
}

template <class W>
bool box_mean_words(const uint8_t* src, size_t src_step, int w, int h, int k, uint8_t* dst, size_t dst_step,
                    uint16_t* scratch) {
  const int r = k / 2, d = k * k;
  if (k % 2 == 0 || k > 15 || w < W::kLanes || h < 1) return false;
  // (sum + d / 2) / d as (x * m) >> (16 + shift), m = ceil(2^(16 + shift) / d) below 2^16. With e = m d - 2^(16 +
  // shift), x m / 2^(16 + shift) = x / d + x e / (d 2^(16 + shift)): the floor is x / d's for every x up to the
  // largest sum when that largest x times e is below 2^(16 + shift) (x / d's fraction is at most (d - 1) / d).
  const int shift = 31 - __builtin_clz(unsigned(d));   // bit_width(d) - 1
  const uint64_t power = uint64_t(1) << (16 + shift);
  const uint32_t m = uint32_t((power + uint64_t(d) - 1) / uint64_t(d));
  const uint64_t largest = 255 * uint64_t(d) + uint64_t(d / 2);
  if (m > 0xFFFF || largest * (uint64_t(m) * uint64_t(d) - power) >= power) return false;
  const size_t stride = size_t(w);
  // The row sums in a ring of k + 1 rows (the window's k and the one coming in), made as the window reaches them:
  // all of them were 150 KB at 640x480, written and read back through the cache.
  const int ring = k + 1;
  uint16_t* const rows = scratch;                              // ring rows of w
  uint16_t* const column = rows + stride * size_t(ring);       // w
  uint16_t* const pad = column + stride;                       // w + k - 1
  int made = -1;   // the last row whose sums are in the ring
  auto row = [&](int y) {
    y = y < 0 ? 0 : y > h - 1 ? h - 1 : y;
    uint16_t* out = rows + size_t(y % ring) * stride;
    for (; made < y;) {   // rows come in order: the next one
      const int next = ++made;
      row_sums<W>(src + size_t(next) * src_step, w, k, pad, rows + size_t(next % ring) * stride);
    }
    return static_cast<const uint16_t*>(out);
  };
  for (int x = 0; x < w; ++x) column[x] = 0;
  for (int y = -r; y <= r; ++y) {
    const uint16_t* in = row(y);
    for (int x = 0; x < w; ++x) column[x] = uint16_t(column[x] + in[x]);
  }
  const typename W::V mul = W::splat(uint16_t(m)), half = W::splat(uint16_t(d / 2));
  for (int y = 0; y < h; ++y) {
    uint8_t* out = dst + size_t(y) * dst_step;
    const uint16_t* drop = row(y - r);   // before the row coming in, which may take its place in the ring
    const uint16_t* add = row(y + r + 1);
    uint16_t* c = column;
    int x = 0;
    for (; x + W::kLanes <= w; x += W::kLanes) {
      const typename W::V sum = W::load(c + x);
      W::means(sum, half, mul, shift, out + x);
      W::store(c + x, W::sub(W::add(sum, W::load(add + x)), W::load(drop + x)));
    }
    for (; x < w; ++x) {
      out[x] = uint8_t(((uint32_t(c[x]) + uint32_t(d / 2)) * m) >> (16 + shift));
      c[x] = uint16_t(c[x] + add[x] - drop[x]);
    }
  }
  return true;
}
