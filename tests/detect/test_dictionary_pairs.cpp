// Dictionary explorer: the closest pairs of markers (and markers against their own rotations) agree with
// Dictionary::min_distance and with a brute-force count of differing cells on the unpacked bit matrices.
#include "detect/dictionary.hpp"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <algorithm>
#include <numeric>
#include <tuple>

using namespace arwb;

namespace {

Dictionary dict(const char* name) {
  std::string err;
  auto d = dictionary_by_name(name, &err);
  EXPECT_TRUE(d) << err;
  return d ? *d : Dictionary();
}

// Marker b turned `rotation` quarter-turns clockwise, from its bit matrix rather than its packed code, so the
// check does not share the code path under test.
cv::Mat turned(const Dictionary& d, int id, int rotation) {
  cv::Mat m = d.bits(id);
  for (int k = 0; k < rotation; ++k) cv::rotate(m, m, cv::ROTATE_90_CLOCKWISE);
  return m;
}

int cells_differing(const cv::Mat& x, const cv::Mat& y) { return cv::countNonZero(x != y); }

// The entry for (a, b) computed cell by cell: the lowest rotation reaching the smallest distance.
DictPair brute_pair(const Dictionary& d, int a, int b) {
  const cv::Mat ma = d.bits(a);
  DictPair best{a, b, -1, 1 << 30};
  for (int k = a == b ? 1 : 0; k < 4; ++k) {
    const int dist = cells_differing(ma, turned(d, b, k));
    if (dist < best.distance) best = {a, b, k, dist};
  }
  return best;
}

bool same(const DictPair& x, const DictPair& y) {
  return x.a == y.a && x.b == y.b && x.rotation == y.rotation && x.distance == y.distance;
}

const char* const kDicts[] = {"ARUCO_ORIGINAL", "4X4_50", "5X5_100", "6X6_250", "APRILTAG_16h5", "APRILTAG_36h11"};

}  // namespace

TEST(DictPairs, ClosestDistanceEqualsMinDistance) {
  for (const char* name : kDicts) {
    const Dictionary d = dict(name);
    const auto pairs = closest_pairs(d, 1);
    ASSERT_EQ(pairs.size(), 1u) << name;
    EXPECT_EQ(pairs[0].distance, d.min_distance()) << name;
  }
}

TEST(DictPairs, ReportedDistancesMatchBruteForceOnTheBits) {
  for (const char* name : kDicts) {
    const Dictionary d = dict(name);
    const auto pairs = closest_pairs(d, 200);
    ASSERT_EQ(pairs.size(), 200u) << name;
    for (size_t i = 0; i < pairs.size(); ++i) {
      const DictPair& p = pairs[i];
      ASSERT_TRUE(p.a >= 0 && p.a <= p.b && p.b < d.size()) << name << " entry " << i;
      if (p.a == p.b) {
        EXPECT_TRUE(p.rotation >= 1 && p.rotation <= 3) << name << " self entry " << p.a;
      }
      // The reported rotation really gives the reported distance, and no rotation does better.
      EXPECT_EQ(cells_differing(d.bits(p.a), turned(d, p.b, p.rotation)), p.distance) << name << " " << p.a << "," << p.b;
      EXPECT_TRUE(same(p, brute_pair(d, p.a, p.b))) << name << " " << p.a << "," << p.b;
      if (i > 0) {
        const DictPair& q = pairs[i - 1];
        EXPECT_LT(std::tie(q.distance, q.a, q.b), std::tie(p.distance, p.a, p.b)) << name << " order at " << i;
      }
    }
  }
}

TEST(DictPairs, EveryEntryOfSmallDictionariesAgreesWithBruteForce) {
  // Small enough to enumerate every entry cell by cell: checks the selection, ties at the cut included.
  for (const char* name : {"4X4_50", "APRILTAG_16h5"}) {
    const Dictionary d = dict(name);
    std::vector<DictPair> all;
    for (int a = 0; a < d.size(); ++a)
      for (int b = a; b < d.size(); ++b) all.push_back(brute_pair(d, a, b));
    std::stable_sort(all.begin(), all.end(), [](const DictPair& x, const DictPair& y) { return x.distance < y.distance; });
    const auto hist = distance_histogram(d);
    for (int k : {1, 7, 50, hist[size_t(d.min_distance())], hist[size_t(d.min_distance())] + 1, int(all.size()),
                  int(all.size()) + 10}) {
      const auto got = closest_pairs(d, k);
      ASSERT_EQ(got.size(), std::min(all.size(), size_t(k))) << name << " max_pairs " << k;
      for (size_t i = 0; i < got.size(); ++i)
        ASSERT_TRUE(same(got[i], all[i])) << name << " max_pairs " << k << " entry " << i << ": got (" << got[i].a
                                          << "," << got[i].b << " r" << got[i].rotation << " d" << got[i].distance
                                          << "), expected (" << all[i].a << "," << all[i].b << " r" << all[i].rotation
                                          << " d" << all[i].distance << ")";
    }
    // The histogram counts the same entries.
    std::vector<int> expected(size_t(d.bit_count()) + 1, 0);
    for (const auto& p : all) ++expected[size_t(p.distance)];
    EXPECT_EQ(hist, expected) << name;
  }
}

TEST(DictPairs, ArucoOriginal1023MatchesItselfUpsideDown) {
  // Every row of id 1023 is 01110: turned half a turn it is the same marker (see README, dictionaries).
  const Dictionary d = make_aruco_original();
  const auto pairs = closest_pairs(d, 3);
  ASSERT_FALSE(pairs.empty());
  EXPECT_TRUE(same(pairs[0], DictPair{1023, 1023, 2, 0}));
  EXPECT_EQ(distance_histogram(d)[0], 1);  // the only entry at distance 0
  EXPECT_EQ(cells_differing(d.bits(1023), turned(d, 1023, 2)), 0);
  EXPECT_GT(pairs[1].distance, 0);
}

TEST(DictPairs, HistogramStartsAtMinDistanceAndCountsEveryEntry) {
  for (const char* name : {"ARUCO_ORIGINAL", "4X4_1000", "6X6_250", "7X7_1000", "APRILTAG_36h11"}) {
    const Dictionary d = dict(name);
    const auto hist = distance_histogram(d);
    ASSERT_EQ(hist.size(), size_t(d.bit_count()) + 1) << name;
    const auto first = std::find_if(hist.begin(), hist.end(), [](int c) { return c > 0; });
    EXPECT_EQ(first - hist.begin(), d.min_distance()) << name;
    const long long n = d.size();
    EXPECT_EQ(std::accumulate(hist.begin(), hist.end(), 0LL), n * (n - 1) / 2 + n) << name;
    // Asking for exactly the entries at the minimum returns them all, and one more reaches beyond it.
    const int at_min = hist[size_t(d.min_distance())];
    const auto pairs = closest_pairs(d, at_min + 1);
    ASSERT_EQ(pairs.size(), size_t(at_min) + 1) << name;
    EXPECT_EQ(pairs[size_t(at_min) - 1].distance, d.min_distance()) << name;
    EXPECT_GT(pairs[size_t(at_min)].distance, d.min_distance()) << name;
  }
}

TEST(DictPairs, NoPairsAskedNoneGiven) {
  const Dictionary d = dict("4X4_50");
  EXPECT_TRUE(closest_pairs(d, 0).empty());
  EXPECT_TRUE(closest_pairs(d, -5).empty());
  EXPECT_TRUE(closest_pairs(Dictionary(), 10).empty());
}
