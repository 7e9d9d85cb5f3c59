#include "detect/dictionary.hpp"

#include "base/files.hpp"
#include "base/text.hpp"
#include "detect/kernels/kernels.hpp"
#include "detect/yaml_file.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cstdlib>
#include <bit>
#include <cctype>
#include <map>
#include <mutex>
#include <sstream>

namespace arwb {

Dictionary::Dictionary(std::string name, int marker_size, std::vector<uint64_t> codes_rot0, int max_correction_bits)
    : name_(std::move(name)), marker_size_(marker_size), max_correction_bits_(max_correction_bits) {
  CV_Assert(marker_size >= 2 && marker_size * marker_size <= 64);
  codes_.reserve(codes_rot0.size());
  for (uint64_t c : codes_rot0) {
    std::array<uint64_t, 4> r{};
    r[0] = c;
    for (int k = 1; k < 4; ++k) r[static_cast<size_t>(k)] = rotate_cw(r[static_cast<size_t>(k - 1)], marker_size);
    codes_.push_back(r);
  }
}

uint64_t Dictionary::pack(const cv::Mat& bits01) {
  CV_Assert(bits01.type() == CV_8UC1 && bits01.rows == bits01.cols && bits01.rows * bits01.cols <= 64);
  uint64_t code = 0;
  for (int r = 0; r < bits01.rows; ++r)
    for (int c = 0; c < bits01.cols; ++c) code = (code << 1) | (bits01.at<uint8_t>(r, c) ? 1u : 0u);
  return code;
}

cv::Mat Dictionary::unpack(uint64_t code, int n) {
  cv::Mat bits(n, n, CV_8UC1);
  const int total = n * n;
  for (int i = 0; i < total; ++i) bits.at<uint8_t>(i / n, i % n) = static_cast<uint8_t>((code >> (total - 1 - i)) & 1u);
  return bits;
}

uint64_t Dictionary::rotate_cw(uint64_t code, int n) {
  // Turning the grid clockwise: the new cell (r, c) comes from the old cell (n-1-c, r).
  const int total = n * n;
  uint64_t out = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const int src = (n - 1 - c) * n + r;
      out = (out << 1) | ((code >> (total - 1 - src)) & 1u);
    }
  return out;
}

cv::Mat Dictionary::bits(int id) const { return unpack(code(id), marker_size_); }

cv::Mat Dictionary::render(int id, int px_per_cell) const {
  const int cells = marker_size_ + 2;
  cv::Mat img(cells * px_per_cell, cells * px_per_cell, CV_8UC1, cv::Scalar(0));
  const cv::Mat b = bits(id);
  for (int r = 0; r < marker_size_; ++r)
    for (int c = 0; c < marker_size_; ++c)
      if (b.at<uint8_t>(r, c))
        img(cv::Rect((c + 1) * px_per_cell, (r + 1) * px_per_cell, px_per_cell, px_per_cell)).setTo(255);
  return img;
}

namespace {

// codes_ as one array, codes[4 id + k] (an array of four has no padding).
const uint64_t* flat(const std::vector<std::array<uint64_t, 4>>& codes) {
  static_assert(sizeof(std::array<uint64_t, 4>) == 4 * sizeof(uint64_t));
  return reinterpret_cast<const uint64_t*>(codes.data());
}

DictMatch to_match(kernels::CodeMatch m) { return {m.id, m.rotation, m.hamming}; }

}  // namespace

// Every marker in its 4 rotations, once per candidate that reaches identification: the level's kernel (a popcount
// instruction where the processor has one; x86-64's baseline has none, and the compiler's stand-in is several times
// slower).
DictMatch Dictionary::nearest(uint64_t code) const {
  return to_match(kernels::kernels().nearest_code(flat(codes_), int(codes_.size()), code));
}

std::array<DictMatch, 4> Dictionary::nearest_per_rotation(uint64_t code) const {
  kernels::CodeMatch m[4];
  kernels::kernels().nearest_per_rotation(flat(codes_), int(codes_.size()), code, m);
  return {to_match(m[0]), to_match(m[1]), to_match(m[2]), to_match(m[3])};
}

int Dictionary::min_distance() const {
  int best = bit_count();
  for (size_t i = 0; i < codes_.size(); ++i) {
    // A marker must not look like itself turned.
    for (int k = 1; k < 4; ++k) best = std::min(best, std::popcount(codes_[i][0] ^ codes_[i][static_cast<size_t>(k)]));
    for (size_t j = i + 1; j < codes_.size(); ++j)
      for (int k = 0; k < 4; ++k) best = std::min(best, std::popcount(codes_[i][0] ^ codes_[j][static_cast<size_t>(k)]));
  }
  return best;
}

Dictionary make_aruco_original() {
  // Each row carries two data bits in columns 2 and 4; columns 1, 3 and 5 are parity bits of a Hamming code
  // whose first bit is inverted, so that an all-black marker is no valid code. The four row words, for the data
  // values 00, 01, 10 and 11 read from (column 2, column 4):
  constexpr uint64_t kRowWord[4] = {0b10000, 0b10111, 0b01001, 0b01110};
  std::vector<uint64_t> codes;
  codes.reserve(1024);
  for (uint64_t id = 0; id < 1024; ++id) {
    uint64_t code = 0;
    for (int row = 0; row < 5; ++row) {
      const uint64_t data = (id >> (2 * (4 - row))) & 3u;  // the first row carries the most significant bits
      code = (code << 5) | kRowWord[data];
    }
    codes.push_back(code);
  }
  // The budget OpenCV gives this dictionary; its rotations leave no room for safe correction.
  return Dictionary("ARUCO_ORIGINAL", 5, std::move(codes), 0);
}

namespace {

std::string upper(std::string_view s) {
  std::string out(s);
  for (auto& ch : out) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return out;
}

// OpenCV's predefined dictionaries, as its aruco module has them: written at build time into a table
// (generate/dictionary_tables.cpp), so that the detector needs no aruco module.
struct PredefinedCodes {
  const char* name;
  int marker_size;
  int max_correction_bits;
  int count;
  const uint64_t* codes;
};
#include "predefined_dictionaries.inc"

Dictionary from_table(const PredefinedCodes& t) {
  const std::string name = t.name;
  int correction = t.max_correction_bits;
  // OpenCV gives the AprilTag families no correction at all, yet each is named for the smallest Hamming distance
  // between its codes in any rotation (36h11: 11 bits), which lets (h - 1) / 2 bits be corrected unambiguously;
  // AprilTag 3 itself corrects 2 by default. error_correction_rate takes its share of that, as for every
  // dictionary: 3 bits of a blurred 20 px 36h11 tag's 36 may be read wrong and it is still found.
  if (const size_t h = name.rfind('h'); correction == 0 && name.rfind("APRILTAG_", 0) == 0 && h != std::string::npos)
    correction = (std::atoi(name.c_str() + h + 1) - 1) / 2;
  return Dictionary(name, t.marker_size, std::vector<uint64_t>(t.codes, t.codes + t.count), correction);
}

}  // namespace

const std::vector<std::string>& dictionary_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n{"ARUCO_ORIGINAL"};
    for (const PredefinedCodes& t : kPredefined) n.push_back(t.name);
    return n;
  }();
  return names;
}

std::optional<Dictionary> dictionary_by_name(std::string_view name, std::string* error) {
  std::string key = upper(name);
  if (key.rfind("DICT_", 0) == 0) key = key.substr(5);
  // Built once per name: the code tables are immutable and cheap to copy.
  static std::mutex mutex;
  static std::map<std::string, Dictionary> cache;
  std::lock_guard lock(mutex);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  if (key == "ARUCO_ORIGINAL") return cache[key] = make_aruco_original();
  for (const PredefinedCodes& t : kPredefined)
    if (upper(t.name) == key) return cache[key] = from_table(t);
  if (error) {
    std::string all;
    for (const auto& n : dictionary_names()) all += (all.empty() ? "" : ", ") + n;
    *error = "unknown dictionary '" + std::string(name) + "' (known: " + all + ")";
  }
  return std::nullopt;
}

namespace {

// A custom dictionary is at most 100,000 markers of up to 64 bits: about 7 MB of YAML.
constexpr FileLimit kDictionaryFile{"a dictionary", 16u << 20};

// Whether two codes of the dictionary, or a code and a turn of itself, differ in at most `within` bits.
// Multi-index hashing: the bits are cut into within + 2 blocks. Two codes within that distance differ in at most
// `within` blocks, so they agree exactly on at least two (with within + 1 blocks, on at least one). For each pair
// of blocks, codes are grouped by the value of those two blocks together and only codes in the same group are
// compared. The key is twice as wide as one block's, so for codes that are not close a group holds about
// 4n / 2^(2 bits / (within + 2)) codes, one or two for 100,000 markers of 64 bits: the work is linear in n
// (times the (within + 2)(within + 1) / 2 pairs of blocks), where comparing all pairs is quadratic.
bool any_pair_within(const std::vector<std::array<uint64_t, 4>>& rot, int bits, int within) {
  const int blocks = within + 2;
  const size_t n = rot.size();
  std::vector<uint32_t> order(n);
  std::vector<uint64_t> codes(n);  // the rotation-0 codes in key order, contiguous for the comparisons
  std::vector<uint32_t> start;     // per key, where its codes begin in `codes`
  std::vector<uint32_t> scratch;
  const auto block_bits = [&](int b, int* lo, uint64_t* mask) {  // block b: bits [lo, hi), bit 0 the lowest
    *lo = bits * b / blocks;
    const int width = bits * (b + 1) / blocks - *lo;
    *mask = width >= 64 ? ~uint64_t{0} : (uint64_t{1} << width) - 1;
    return width;
  };
  for (int a = 0; a < blocks; ++a)
    for (int b = a + 1; b < blocks; ++b) {
      int lo_a = 0, lo_b = 0;
      uint64_t mask_a = 0, mask_b = 0;
      const int width_a = block_bits(a, &lo_a, &mask_a), width = width_a + block_bits(b, &lo_b, &mask_b);
      const auto key = [&](uint64_t c) { return ((c >> lo_a) & mask_a) | ((c >> lo_b) & mask_b) << width_a; };
      // Codes in key order, with a table of where each key starts (a counting sort) when keys are up to 20 bits;
      // sorted and searched otherwise.
      const bool table = width <= 20;
      if (table) {
        start.assign((size_t{1} << width) + 1, 0);
        for (size_t i = 0; i < n; ++i) ++start[key(rot[i][0]) + 1];
        for (size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
        std::vector<uint32_t>& next = scratch;
        next.assign(start.begin(), start.end() - 1);
        for (size_t i = 0; i < n; ++i) order[next[key(rot[i][0])]++] = static_cast<uint32_t>(i);
      } else {
        for (size_t i = 0; i < n; ++i) order[i] = static_cast<uint32_t>(i);
        std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return key(rot[x][0]) < key(rot[y][0]); });
      }
      for (size_t i = 0; i < n; ++i) codes[i] = rot[order[i]][0];
      // Every code turned k quarter-turns against the rotation-0 codes in its group.
      for (size_t j = 0; j < n; ++j)
        for (size_t k = 0; k < 4; ++k) {
          const uint64_t c = rot[j][k], v = key(c);
          size_t first = 0, last = 0;
          if (table) {
            first = start[v];
            last = start[v + 1];
          } else {
            const auto by_key = [&](uint64_t code, uint64_t value) { return key(code) < value; };
            first = size_t(std::lower_bound(codes.begin(), codes.end(), v, by_key) - codes.begin());
            for (last = first; last < n && key(codes[last]) == v;) ++last;
          }
          for (size_t x = first; x < last; ++x)
            if (std::popcount(codes[x] ^ c) <= within && !(k == 0 && order[x] == j)) return true;  // not itself
        }
    }
  return false;
}

}  // namespace

int largest_safe_correction(const Dictionary& d, int up_to) {
  std::vector<std::array<uint64_t, 4>> rot(static_cast<size_t>(d.size()));
  for (int id = 0; id < d.size(); ++id)
    for (int k = 0; k < 4; ++k) rot[size_t(id)][size_t(k)] = d.code(id, k);
  // c bits can be corrected safely when no two codes are within 2c of each other (min distance > 2c).
  for (int c = std::max(0, up_to); c > 0; --c)
    if (!any_pair_within(rot, d.bit_count(), 2 * c)) return c;
  return 0;
}

std::optional<Dictionary> load_dictionary_yaml(const std::string& path, std::string* error) {
  auto fail = [&](const std::string& why) -> std::optional<Dictionary> {
    if (error) *error = path + ": " + why;
    return std::nullopt;
  };
  cv::FileStorage fs;
  if (Status opened = open_yaml_file(path, kDictionaryFile, &fs); !opened) {
    if (error) *error = opened.error();
    return std::nullopt;
  }
  try {
    const cv::FileNode root = fs.root();
    if (!root.isMap()) return fail("not a dictionary (expected a map of nmarkers, markersize, marker_0 ...)");
    // One pass over the map: looking each marker_<i> up by name would scan the map each time (OpenCV's
    // FileNode::operator[] is a linear search), which is quadratic in the markers: minutes for 100,000.
    cv::FileNode nmarkers, markersize, correction;
    std::vector<cv::FileNode> markers;
    for (const cv::FileNode& node : root) {
      const std::string key = node.name();
      if (key == "nmarkers") nmarkers = node;
      else if (key == "markersize") markersize = node;
      else if (key == "maxCorrectionBits") correction = node;
      else if (key.rfind("marker_", 0) == 0 && key.size() > 7 && key.size() <= 13 &&
               key.find_first_not_of("0123456789", 7) == std::string::npos && (key[7] != '0' || key.size() == 8)) {
        const size_t i = std::stoul(key.substr(7));
        if (i < 100000) {
          if (markers.size() <= i) markers.resize(i + 1);
          markers[i] = node;
        }
      }
    }
    if (nmarkers.empty() || markersize.empty()) return fail("needs nmarkers and markersize");
    if (!nmarkers.isInt() || !markersize.isInt() || (!correction.empty() && !correction.isInt()))
      return fail("nmarkers, markersize and maxCorrectionBits must be whole numbers");
    const int n = int(nmarkers), size = int(markersize), corr = correction.empty() ? 0 : int(correction);
    if (size < 2 || size > 8) return fail("markersize " + std::to_string(size) + " outside 2..8");
    if (n < 1 || n > 100000) return fail("nmarkers " + std::to_string(n) + " outside 1..100000");
    if (corr < 0 || corr > size * size) return fail("maxCorrectionBits " + std::to_string(corr) + " out of range");
    std::vector<uint64_t> codes;
    codes.reserve(size_t(n));
    for (int i = 0; i < n; ++i) {
      const std::string key = "marker_" + std::to_string(i);
      if (size_t(i) >= markers.size() || markers[size_t(i)].empty()) return fail("missing " + key);
      if (!markers[size_t(i)].isString()) return fail(key + " is not a string of 0 and 1");
      const std::string bits = markers[size_t(i)].string();
      if (static_cast<int>(bits.size()) != size * size) return fail(key + " has " + std::to_string(bits.size()) +
                                                                   " bits, expected " + std::to_string(size * size));
      uint64_t code = 0;
      for (char ch : bits) {
        if (ch != '0' && ch != '1') return fail(key + " has a character other than 0 and 1");
        code = (code << 1) | (ch == '1' ? 1u : 0u);
      }
      codes.push_back(code);
    }
    std::string stem = path.substr(path.find_last_of('/') + 1);
    Dictionary d(stem, size, std::move(codes), corr);
    // More correction than the markers' distance allows makes one marker read as another: false detections.
    if (corr > 0) {
      const int safe = largest_safe_correction(d, corr);
      if (safe < corr)
        return fail("maxCorrectionBits " + std::to_string(corr) + " is more than the markers' distance allows "
                    "(rotations included); the largest allowed is " + std::to_string(safe));
    }
    return d;
  } catch (const std::exception&) {
    // cv::Exception from reading a node of the wrong type (its text names OpenCV's own source), std::length_error
    // and the like from OpenCV's parser (found by fuzzing): ours names the file.
    return fail("malformed YAML");
  }
}

// [SECTION] dictionary explorer

namespace {

// Calls f(a, b, rotation, distance) for every explorer entry, a ascending, then b ascending from a (itself first).
// The four rotations of all codes sit in one flat array so the inner loop is four XOR-popcounts on adjacent words.
template <class F>
void for_each_pair(const Dictionary& d, F&& f) {
  const int n = d.size();
  std::vector<uint64_t> rot(size_t(n) * 4);
  for (int id = 0; id < n; ++id)
    for (int k = 0; k < 4; ++k) rot[size_t(id) * 4 + size_t(k)] = d.code(id, k);
  for (int a = 0; a < n; ++a) {
    const uint64_t ca = rot[size_t(a) * 4];
    int best = 65, best_k = 1;
    for (int k = 1; k < 4; ++k) {
      const int dist = std::popcount(ca ^ rot[size_t(a) * 4 + size_t(k)]);
      if (dist < best) {
        best = dist;
        best_k = k;
      }
    }
    f(a, a, best_k, best);
    for (int b = a + 1; b < n; ++b) {
      const uint64_t* rb = &rot[size_t(b) * 4];
      best = std::popcount(ca ^ rb[0]);
      best_k = 0;
      for (int k = 1; k < 4; ++k) {
        const int dist = std::popcount(ca ^ rb[k]);
        if (dist < best) {
          best = dist;
          best_k = k;
        }
      }
      f(a, b, best_k, best);
    }
  }
}

}  // namespace

std::vector<int> distance_histogram(const Dictionary& d) {
  std::vector<int> hist(size_t(d.bit_count()) + 1, 0);
  for_each_pair(d, [&](int, int, int, int dist) { ++hist[size_t(dist)]; });
  return hist;
}

std::vector<DictPair> closest_pairs(const Dictionary& d, int max_pairs) {
  std::vector<DictPair> out;
  if (max_pairs <= 0 || d.size() == 0) return out;
  // Two passes instead of keeping every entry (500 000 for 1000 ids): the histogram gives the distance at which
  // the list fills up; the second pass keeps everything closer and, at that distance, the first entries in (a, b)
  // order, which is the order the visit produces.
  const std::vector<int> hist = distance_histogram(d);
  int cutoff = 0;
  long long below = 0;  // entries closer than cutoff
  while (cutoff < int(hist.size()) - 1 && below + hist[size_t(cutoff)] < max_pairs) below += hist[size_t(cutoff++)];
  long long room_at_cutoff = max_pairs - below;
  out.reserve(size_t(std::min<long long>(max_pairs, below + hist[size_t(cutoff)])));
  for_each_pair(d, [&](int a, int b, int rotation, int dist) {
    if (dist < cutoff || (dist == cutoff && room_at_cutoff-- > 0)) out.push_back({a, b, rotation, dist});
  });
  std::sort(out.begin(), out.end(), [](const DictPair& x, const DictPair& y) {
    if (x.distance != y.distance) return x.distance < y.distance;
    if (x.a != y.a) return x.a < y.a;
    return x.b < y.b;
  });
  return out;
}

std::optional<std::vector<Dictionary>> parse_dictionaries(const std::string& list, std::string* error) {
  std::vector<Dictionary> out;
  for (const std::string& name : split_list(list)) {
    const bool file = name.size() > 4 && (name.ends_with(".yml") || name.ends_with(".yaml"));
    auto d = file ? load_dictionary_yaml(name, error) : dictionary_by_name(name, error);
    if (!d) return std::nullopt;
    out.push_back(std::move(*d));
  }
  if (out.empty()) {
    if (error) *error = "no dictionary named";
    return std::nullopt;
  }
  return out;
}

}  // namespace arwb
