// Marker dictionaries: sets of square binary codes, each known in its four rotations.
//
// A code packs the marker's inner bits (marker_size x marker_size, the black border excluded) row-major into a
// uint64, the top-left bit the most significant of the used bits; 1 is a white cell. codes[id][k] is the marker
// turned k quarter-turns clockwise, so a sampled grid that equals codes[id][k] shows the marker's own top-left
// corner at grid corner k (0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left).
#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace arwb {

struct DictMatch {
  int id = -1;        // -1: none within the budget
  int rotation = 0;   // quarter-turns clockwise of the marker in the sampled grid
  int hamming = 0;    // differing bits
};

class Dictionary {
 public:
  Dictionary() = default;
  Dictionary(std::string name, int marker_size, std::vector<uint64_t> codes_rot0, int max_correction_bits);

  const std::string& name() const { return name_; }
  int marker_size() const { return marker_size_; }
  int bit_count() const { return marker_size_ * marker_size_; }
  int size() const { return static_cast<int>(codes_.size()); }
  // Bits that may be wrong and still identify a marker; the largest safe value is (min_distance()-1)/2.
  int max_correction_bits() const { return max_correction_bits_; }
  uint64_t code(int id, int rotation = 0) const { return codes_[static_cast<size_t>(id)][static_cast<size_t>(rotation & 3)]; }

  // Inner bits of a marker as a marker_size x marker_size CV_8U matrix of 0 (black) and 1 (white).
  cv::Mat bits(int id) const;
  // The marker drawn with a one-cell black border, px_per_cell pixels a cell, black 0 and white 255.
  cv::Mat render(int id, int px_per_cell) const;

  // The nearest marker over all ids and rotations (ties: lowest id, then lowest rotation).
  DictMatch nearest(uint64_t code) const;
  // For each rotation k, the nearest id when the grid is read as the marker turned k quarter-turns.
  std::array<DictMatch, 4> nearest_per_rotation(uint64_t code) const;
  // The smallest Hamming distance between two markers, or between a marker and a rotation of itself or of another.
  int min_distance() const;

  // Helpers on packed codes.
  static uint64_t pack(const cv::Mat& bits01);
  static cv::Mat unpack(uint64_t code, int marker_size);
  static uint64_t rotate_cw(uint64_t code, int marker_size);

 private:
  std::string name_;
  int marker_size_ = 0;
  int max_correction_bits_ = 0;
  std::vector<std::array<uint64_t, 4>> codes_;
};

// The paper's dictionary, built from its description (Avola et al. 2016, section 3.3): 5x5 inner bits, each row
// two data bits (columns 2 and 4) and three parity bits of a Hamming code whose first bit is inverted; 1024 ids.
Dictionary make_aruco_original();

// Every predefined dictionary by OpenCV's name without "DICT_" (ARUCO_ORIGINAL, 4X4_50 ... 7X7_1000,
// APRILTAG_16h5, APRILTAG_25h9, APRILTAG_36h10, APRILTAG_36h11).
const std::vector<std::string>& dictionary_names();
// Looks a name up case-insensitively ("DICT_" prefix allowed). nullopt and a message naming it when unknown.
std::optional<Dictionary> dictionary_by_name(std::string_view name, std::string* error = nullptr);
// A custom dictionary in OpenCV's YAML format (nmarkers, markersize, maxCorrectionBits, marker_0 ...), up to
// 100,000 markers, loaded in time linear in them. maxCorrectionBits is refused when it is more than the markers'
// smallest distance allows, (d - 1) / 2 with rotations included as OpenCV counts them, naming the largest allowed.
std::optional<Dictionary> load_dictionary_yaml(const std::string& path, std::string* error = nullptr);
// The largest correction (at most up_to) that never reads one marker as another, (min_distance() - 1) / 2 capped
// at up_to, found without comparing every pair (multi-index hashing): near linear in the markers for real
// dictionaries, where min_distance() is quadratic.
int largest_safe_correction(const Dictionary& d, int up_to);

// [SECTION] dictionary explorer: which markers are hardest to tell apart.

// One entry of the explorer: markers a and b (a < b), or a marker against its own rotations (a == b). distance is
// the smallest Hamming distance over rotations, reached with b turned `rotation` quarter-turns clockwise
// (code(a, 0) against code(b, rotation); lowest rotation on ties, 1..3 when a == b).
struct DictPair {
  int a = -1, b = -1;
  int rotation = 0;
  int distance = 0;
};

// The max_pairs entries with the smallest distance, sorted by distance, then a, then b. Entries are every pair
// a < b and every marker against itself turned (rotation 1..3). The first entry's distance is min_distance().
std::vector<DictPair> closest_pairs(const Dictionary& d, int max_pairs);
// Over the same entries: element k counts those at distance k (size bit_count() + 1). The first non-zero
// element is at min_distance(); the counts sum to n (n - 1) / 2 + n.
std::vector<int> distance_histogram(const Dictionary& d);

// "NAME[,NAME...]" of dictionaries: predefined names (case-insensitive) or YAML files (ending .yml/.yaml).
std::optional<std::vector<Dictionary>> parse_dictionaries(const std::string& list, std::string* error);

}  // namespace arwb
