// The plain data the detector's vector kernels take and give. The kernel files are compiled with their own
// instruction-set flags, so they see only these types and raw pointers: no OpenCV and no standard container, whose
// inline functions a kernel file would otherwise compile with its flags for the whole program to link (a plain
// caller could then run an AVX2 copy of std::vector's code on a processor without AVX2).
#pragma once

#include <cstddef>
#include <cstdint>

namespace arwb::kernels {

// cvtColor's BGR to grey, exactly: (kGreyB B + kGreyG G + kGreyR R + 2^(kGreyShift - 1)) >> kGreyShift (checked
// against it over all 2^24 colours by the tests).
inline constexpr int kGreyB = 3735, kGreyG = 19235, kGreyR = 9798, kGreyShift = 15;

// cv::Point's layout (x, then y), checked where the stages pass their points.
struct Point {
  int x, y;
};

// quad_fit's search: the first of the points farthest from a point or a line, and how far (-1 and -1: no point).
struct Farthest {
  int64_t measure = -1;
  int at = -1;
};

// identification: the nearest code of a dictionary, as DictMatch.
struct CodeMatch {
  int id = -1;
  int rotation = 0;
  int hamming = 65;
};

// contours: a binary image as bit masks, row y's `words` words at row(y), bit k of word c the pixel 64c + k. Rows
// of nothing above and below it and a word of nothing at each end of a row let the neighbours of any pixel be read
// unchecked. Read as one array from the first row's first word (its left end's), the rows and their ends follow one
// another `stride` apart: a pass along that array does every row at once, and for a word at a row's end it takes
// the pixels beside the image, which are off.
struct BitRows {
  static constexpr int kPad = 3;   // rows of nothing above and below
  uint64_t* base;
  int words, h;
  ptrdiff_t stride() const { return ptrdiff_t(words) + 2; }
  // and three words more, for a pass four words a step that ends past the padding below
  size_t size() const { return size_t(stride()) * size_t(h + 2 * kPad) + 3; }
  uint64_t* row(int y) const { return base + stride() * (y + kPad) + 1; }
  uint64_t* first() const { return row(0) - 1; }   // the array of the image's rows, with their ends
  size_t length() const { return size_t(stride()) * size_t(h); }
  void clear_padding() const {
    for (uint64_t* p = base; p < first(); ++p) *p = 0;
    for (uint64_t* p = first() + length(); p < base + size(); ++p) *p = 0;
  }
};

// contours: a row's edges. Bit k of edge word c is set where pixel 64c + k differs from the one before it, where a
// run of the row begins or ends; before[c] is the number of edges in the words before c.
struct EdgeWords {
  uint64_t* bits;
  int* before;
};

}  // namespace arwb::kernels
