// Dictionaries: the paper's ARUCO_ORIGINAL built from its description equals OpenCV's bit for bit; the
// predefined tables, rotations, nearest-match search and custom YAML dictionaries.
#include "detect/dictionary.hpp"
#include "detect/kernels/simd.hpp"
#include "detect/params.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/aruco.hpp>

#include <bit>
#include <random>
#include <string>

using namespace arwb;

TEST(Dictionary, ArucoOriginalFromThePaperEqualsOpenCvBitForBit) {
  const Dictionary ours = make_aruco_original();
  const auto theirs = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_ARUCO_ORIGINAL);
  ASSERT_EQ(ours.size(), 1024);
  ASSERT_EQ(theirs->bytesList.rows, 1024);
  ASSERT_EQ(ours.marker_size(), theirs->markerSize);
  for (int id = 0; id < 1024; ++id) {
    const cv::Mat a = ours.bits(id);
    const cv::Mat b = cv::aruco::Dictionary::getBitsFromByteList(theirs->bytesList.row(id), 5);
    ASSERT_EQ(cv::countNonZero(a != b), 0) << "id " << id;
  }
}

TEST(Dictionary, ArucoOriginalRowsFollowThePaperCode) {
  // ID 0 is coded 10000 in every row (the inverted first parity bit keeps an all-black marker invalid).
  const Dictionary d = make_aruco_original();
  const cv::Mat zero = d.bits(0);
  for (int r = 0; r < 5; ++r) {
    EXPECT_EQ(zero.at<uint8_t>(r, 0), 1);
    for (int c = 1; c < 5; ++c) EXPECT_EQ(zero.at<uint8_t>(r, c), 0);
  }
  // Data bits are columns 2 and 4, most significant row first: id 1023 is 01110 in every row, id 1 ends 10111.
  const cv::Mat all = d.bits(1023);
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 5; ++c) EXPECT_EQ(all.at<uint8_t>(r, c), (c >= 1 && c <= 3) ? 1 : 0);
  const cv::Mat one = d.bits(1);
  EXPECT_EQ(one.at<uint8_t>(4, 0) * 16 + one.at<uint8_t>(4, 1) * 8 + one.at<uint8_t>(4, 2) * 4 + one.at<uint8_t>(4, 3) * 2 + one.at<uint8_t>(4, 4), 0b10111);
}

TEST(Dictionary, EveryPredefinedDictionaryMatchesOpenCv) {
  const std::pair<const char*, cv::aruco::PREDEFINED_DICTIONARY_NAME> cases[] = {
      {"4X4_50", cv::aruco::DICT_4X4_50}, {"5x5_1000", cv::aruco::DICT_5X5_1000},
      {"DICT_6X6_250", cv::aruco::DICT_6X6_250}, {"7X7_1000", cv::aruco::DICT_7X7_1000},
      {"apriltag_16h5", cv::aruco::DICT_APRILTAG_16h5}, {"APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11}};
  for (const auto& [name, which] : cases) {
    std::string err;
    auto d = dictionary_by_name(name, &err);
    ASSERT_TRUE(d) << err;
    const auto cvd = cv::aruco::getPredefinedDictionary(which);
    ASSERT_EQ(d->size(), cvd->bytesList.rows) << name;
    // OpenCV's budget, except for the AprilTag families, to which OpenCV gives none: theirs is half their
    // minimum distance (16h5: 2 bits, 36h11: 5), the most that stays unambiguous.
    if (std::string(name).find("16h5") != std::string::npos)
      EXPECT_EQ(d->max_correction_bits(), 2) << name;
    else if (std::string(name).find("36h11") != std::string::npos)
      EXPECT_EQ(d->max_correction_bits(), 5) << name;
    else
      EXPECT_EQ(d->max_correction_bits(), cvd->maxCorrectionBits) << name;
    for (int id = 0; id < d->size(); id += 7) {
      const cv::Mat b = cv::aruco::Dictionary::getBitsFromByteList(cvd->bytesList.row(id), cvd->markerSize);
      ASSERT_EQ(cv::countNonZero(d->bits(id) != b), 0) << name << " id " << id;
    }
  }
  EXPECT_EQ(dictionary_names().size(), 21u);
}

TEST(Dictionary, UnknownNameIsRefusedWithTheNameInTheMessage) {
  std::string err;
  EXPECT_FALSE(dictionary_by_name("8X8_42", &err));
  EXPECT_NE(err.find("8X8_42"), std::string::npos);
  EXPECT_NE(err.find("ARUCO_ORIGINAL"), std::string::npos);  // lists what is known
}

TEST(Dictionary, RotationsAreQuarterTurnsClockwise) {
  // A single white bit at the top-left moves to the top-right after one clockwise quarter-turn.
  cv::Mat bits = cv::Mat::zeros(4, 4, CV_8UC1);
  bits.at<uint8_t>(0, 0) = 1;
  const uint64_t turned = Dictionary::rotate_cw(Dictionary::pack(bits), 4);
  EXPECT_EQ(Dictionary::unpack(turned, 4).at<uint8_t>(0, 3), 1);
  EXPECT_EQ(cv::countNonZero(Dictionary::unpack(turned, 4)), 1);
  const Dictionary d = *dictionary_by_name("4X4_50");
  for (int k = 0; k < 4; ++k) {
    const DictMatch m = d.nearest(d.code(17, k));
    EXPECT_EQ(m.id, 17);
    EXPECT_EQ(m.rotation, k);
    EXPECT_EQ(m.hamming, 0);
  }
}

TEST(Dictionary, NearestCountsFlippedBits) {
  const Dictionary d = *dictionary_by_name("6X6_250");
  const uint64_t code = d.code(100, 2) ^ 0b1001;  // two bits flipped
  const DictMatch m = d.nearest(code);
  EXPECT_EQ(m.id, 100);
  EXPECT_EQ(m.rotation, 2);
  EXPECT_EQ(m.hamming, 2);
  const auto per = d.nearest_per_rotation(code);
  EXPECT_EQ(per[2].id, 100);
  EXPECT_GT(per[0].hamming, 2);
}

// The nearest code is the first of the nearest in id order, then rotation order, on every path the processor has
// (AVX-512 eight codes a step, POPCNT, plain C++ at level none): random codes and codes near the dictionary's own, whose exact
// matches tie in ARUCO_ORIGINAL (some ids are others turned) and in APRILTAG_16h5's rotations.
TEST(Dictionary, NearestIsTheFirstOfTheNearestOnEveryPath) {
  cv::RNG rng(5);
  for (const char* name : {"ARUCO_ORIGINAL", "4X4_50", "6X6_250", "APRILTAG_16h5", "APRILTAG_36h11"}) {
    const Dictionary d = *dictionary_by_name(name);
    const int bits = d.bit_count();
    for (int t = 0; t < 300; ++t) {
      uint64_t code = t % 2 ? d.code(rng.uniform(0, d.size()), rng.uniform(0, 4))
                            : uint64_t(rng.next()) << 32 | uint64_t(rng.next());
      for (int f = rng.uniform(0, 4); f > 0; --f) code ^= uint64_t(1) << rng.uniform(0, bits);
      code &= bits == 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
      DictMatch want{-1, 0, 65};
      for (int id = 0; id < d.size(); ++id)
        for (int k = 0; k < 4; ++k) {
          const int h = std::popcount(code ^ d.code(id, k));
          if (h < want.hamming) want = {id, k, h};
        }
      for (const Simd level : simd_levels_here()) {
        SimdCap cap(level);
        const DictMatch got = d.nearest(code);
        ASSERT_EQ(got.id, want.id) << name << " " << t << " " << simd_name(level);
        ASSERT_EQ(got.rotation, want.rotation) << name << " " << t << " " << simd_name(level);
        ASSERT_EQ(got.hamming, want.hamming) << name << " " << t << " " << simd_name(level);
      }
    }
  }
}

TEST(Dictionary, MinimumDistanceOfTheSmallTables) {
  EXPECT_EQ(dictionary_by_name("4X4_50")->min_distance(), 4);
  EXPECT_EQ(make_aruco_original().min_distance(), 0);  // some ids equal others turned: why OpenCV corrects 0 bits
}

TEST(Dictionary, CustomYamlInOpenCvFormat) {
  test::TempDir dir;
  test::write_file(dir.str("mine.yml"),
                   "%YAML:1.0\nnmarkers: 2\nmarkersize: 3\nmaxCorrectionBits: 0\n"
                   "marker_0: \"101010101\"\nmarker_1: \"111000111\"\n");
  std::string err;
  auto d = load_dictionary_yaml(dir.str("mine.yml"), &err);
  ASSERT_TRUE(d) << err;
  EXPECT_EQ(d->size(), 2);
  EXPECT_EQ(d->marker_size(), 3);
  EXPECT_EQ(d->code(1), 0b111000111u);

  test::write_file(dir.str("bad.yml"), "%YAML:1.0\nnmarkers: 2\nmarkersize: 3\nmarker_0: \"10101\"\n");
  EXPECT_FALSE(load_dictionary_yaml(dir.str("bad.yml"), &err));
  EXPECT_NE(err.find("bad.yml"), std::string::npos);
  EXPECT_NE(err.find("marker_0"), std::string::npos);
}

namespace {

// A dictionary file in OpenCV's format, with the markers' codes written as bit strings.
std::string dictionary_yaml(int marker_size, int max_correction_bits, const std::vector<uint64_t>& codes) {
  std::string y = "%YAML:1.0\nnmarkers: " + std::to_string(codes.size()) + "\nmarkersize: " +
                  std::to_string(marker_size) + "\nmaxCorrectionBits: " + std::to_string(max_correction_bits) + "\n";
  const int bits = marker_size * marker_size;
  for (size_t i = 0; i < codes.size(); ++i) {
    y += "marker_" + std::to_string(i) + ": \"";
    for (int b = bits - 1; b >= 0; --b) y += (codes[i] >> b) & 1u ? '1' : '0';
    y += "\"\n";
  }
  return y;
}

std::vector<uint64_t> codes_of(const Dictionary& d) {
  std::vector<uint64_t> c;
  for (int id = 0; id < d.size(); ++id) c.push_back(d.code(id));
  return c;
}

}  // namespace

// The documented maximum, 100,000 markers of 8x8 bits: looked up marker by marker in OpenCV's map, loading took
// minutes (quadratic); one pass over the map makes it linear. The bound is generous: it was over two minutes.
// (Its time is not asserted: a unit test's clock measures the machine's load as much as the code. The load is
// near linear in the markers by construction, largest_safe_correction's multi-index hashing.)
TEST(Dictionary, TheDocumentedMaximumOf100000MarkersLoads) {
  test::TempDir dir;
  std::mt19937_64 rng(7);
  std::vector<uint64_t> codes(100000);
  for (auto& c : codes) c = rng();
  // Random 64-bit codes are at least 7 bits apart, rotations included (checked by the load): 3 bits are safe.
  test::write_file(dir.str("big.yml"), dictionary_yaml(8, 3, codes));
  std::string err;
  const auto d = load_dictionary_yaml(dir.str("big.yml"), &err);
  ASSERT_TRUE(d) << err;
  EXPECT_EQ(d->size(), 100000);
  EXPECT_EQ(d->code(99999), codes[99999]);
}

// More correction than the markers' distance allows reads one marker as another: refused, naming the largest.
TEST(Dictionary, MaxCorrectionBitsAboveWhatTheDistanceAllowsIsRefusedWithTheLargestAllowed) {
  test::TempDir dir;
  const Dictionary d4 = *dictionary_by_name("4X4_50");  // min distance 4, rotations included: 1 bit is safe
  test::write_file(dir.str("mine.yml"), dictionary_yaml(4, 1, codes_of(d4)));
  std::string err;
  EXPECT_TRUE(load_dictionary_yaml(dir.str("mine.yml"), &err)) << err;
  test::write_file(dir.str("mine.yml"), dictionary_yaml(4, 2, codes_of(d4)));
  EXPECT_FALSE(load_dictionary_yaml(dir.str("mine.yml"), &err));
  EXPECT_EQ(err, dir.str("mine.yml") +
                     ": maxCorrectionBits 2 is more than the markers' distance allows (rotations included); the "
                     "largest allowed is 1");
  // A marker that looks the same turned (101/010/101) leaves no room at all.
  test::write_file(dir.str("sym.yml"), dictionary_yaml(3, 1, {0b101010101, 0b111000111}));
  EXPECT_FALSE(load_dictionary_yaml(dir.str("sym.yml"), &err));
  EXPECT_NE(err.find("the largest allowed is 0"), std::string::npos) << err;
}

// The multi-index search agrees with the quadratic minimum distance on every predefined table.
TEST(Dictionary, LargestSafeCorrectionIsHalfTheMinimumDistanceOnEveryTable) {
  for (const std::string& name : dictionary_names()) {
    const Dictionary d = *dictionary_by_name(name);
    EXPECT_EQ(largest_safe_correction(d, d.bit_count()), std::max(0, (d.min_distance() - 1) / 2)) << name;
    EXPECT_LE(d.max_correction_bits(), largest_safe_correction(d, d.bit_count())) << name << ": OpenCV's own budget";
  }
}

TEST(Dictionary, DeeplyNestedYamlIsRefusedBeforeOpenCvParsesIt) {
  test::TempDir dir;
  test::write_file(dir.str("deep.yml"), "nmarkers: 1\nmarkersize: 4\nmarker_0: " + std::string(40000, '[') + "\n");
  std::string err;
  EXPECT_FALSE(load_dictionary_yaml(dir.str("deep.yml"), &err));
  EXPECT_EQ(err, dir.str("deep.yml") + ":3: nested deeper than 32 levels");
}

// Found by the yaml_params and dictionary fuzz targets: OpenCV 4.6's YAML reader loops forever on a '-' where it
// expects the next document's "---", and throws std::length_error on an empty flow-map key. Both are refused (or
// caught) with the file named; before the fix the first hung (ctest's timeout) and the second aborted.
TEST(YamlFile, TextThatStopsOpenCvsParserIsRefusedWithItsLine) {
  test::TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"%YAML:1.0\n---e:1\n-1\n-\n", ":2: text after the document start '---'"},
      {"%YAML:1.0\n---\na: 1\n---\n-\n", ":4: a second YAML document (one per file)"},
      {"%YAML:1.\n-----0\nma--\n", ":2: text after the document start '---'"},
      {"a: 1\n-1\n", ":2: a list at the top level"},
      {"a: 1\n...\n", ":2: a YAML document end marker"},
      {"       i~e: 0\n    ?   -%-1warp_cell_pxNclas2\nn", ":2: indented less than the file's first line"},
      {"a: 1\n? b\n: 2\n", ":2: an explicit YAML key ('?')"},
  };
  for (const auto& [text, expected] : cases) {
    test::write_file(dir.str("p.yml"), text);
    DetectorParams p;
    std::vector<std::string> errors;
    EXPECT_FALSE(load_params_yaml(dir.str("p.yml"), p, &errors)) << text;
    ASSERT_EQ(errors.size(), 1u) << text;
    EXPECT_EQ(errors[0].rfind(dir.str("p.yml") + expected, 0), 0u) << errors[0];
    std::string err;
    EXPECT_FALSE(load_dictionary_yaml(dir.str("p.yml"), &err)) << text;
    EXPECT_EQ(err.rfind(dir.str("p.yml") + expected, 0), 0u) << err;
  }
}

TEST(YamlFile, AnEmptyFlowMapKeyIsMalformedYamlNotAnAbort) {
  test::TempDir dir;
  test::write_file(dir.str("p.yml"), "%YAML:1.0\n---\na: { : 1}\n");
  DetectorParams p;
  std::vector<std::string> errors;
  EXPECT_FALSE(load_params_yaml(dir.str("p.yml"), p, &errors));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].rfind(dir.str("p.yml") + ":", 0), 0u) << errors[0];
  EXPECT_NE(errors[0].find("malformed YAML"), std::string::npos) << errors[0];
  std::string err;
  EXPECT_FALSE(load_dictionary_yaml(dir.str("p.yml"), &err));
  EXPECT_NE(err.find("malformed YAML"), std::string::npos) << err;
}

// What OpenCV writes (and the docs show) still loads: the document marker, and list items indented under a key.
TEST(YamlFile, OpenCvsOwnOutputStillLoads) {
  test::TempDir dir;
  DetectorParams p;
  p.threshold_window_px = 9;
  std::string error;
  ASSERT_TRUE(save_params_yaml(dir.str("saved.yml"), p, &error)) << error;
  DetectorParams back;
  std::vector<std::string> errors;
  EXPECT_TRUE(load_params_yaml(dir.str("saved.yml"), back, &errors)) << (errors.empty() ? "" : errors[0]);
  EXPECT_EQ(back.threshold_window_px, 9);
}
