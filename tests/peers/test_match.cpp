// The one matching rule (detect/match.hpp): id and dictionary must agree, corners within max(3 px, a tenth of the
// reference's side) on average, each reference marker taken once, the closest first.
#include "peers/match.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace arwb;

namespace {
Marker square(int id, float x, float y, float side, const std::string& dict = "ARUCO_ORIGINAL") {
  Marker m;
  m.id = id;
  m.dict = dict;
  m.corners = {cv::Point2f(x, y), cv::Point2f(x + side, y), cv::Point2f(x + side, y + side), cv::Point2f(x, y + side)};
  return m;
}
Marker shifted(Marker m, float dx, float dy) {
  for (auto& c : m.corners) c += cv::Point2f(dx, dy);
  return m;
}
}  // namespace

TEST(Match, SideAndCornerDistance) {
  const Marker a = square(1, 10, 20, 40);
  EXPECT_DOUBLE_EQ(mean_side(a.corners), 40.0);
  EXPECT_DOUBLE_EQ(mean_corner_distance(a.corners, shifted(a, 3, 4).corners), 5.0);
  EXPECT_DOUBLE_EQ(match_tolerance_px(a.corners), 4.0);                  // a tenth of 40
  EXPECT_DOUBLE_EQ(match_tolerance_px(square(1, 0, 0, 20).corners), 3.0);  // the floor
}

TEST(Match, ToleranceIsATenthOfTheReferenceSideWithAThreePixelFloor) {
  const Marker big = square(7, 100, 100, 200);   // tolerance 20 px
  EXPECT_EQ(match_markers({big}, {shifted(big, 19.5f, 0)}).pairs.size(), 1u);
  EXPECT_EQ(match_markers({big}, {shifted(big, 20.5f, 0)}).pairs.size(), 0u);
  const Marker small = square(7, 100, 100, 24);   // a tenth would be 2.4 px: the floor of 3 applies
  EXPECT_EQ(match_markers({small}, {shifted(small, 2.9f, 0)}).pairs.size(), 1u);
  EXPECT_EQ(match_markers({small}, {shifted(small, 3.1f, 0)}).pairs.size(), 0u);
  // The reference's side counts, not the found marker's: a found marker twice as large is not forgiven more.
  Marker large_found = square(7, 100, 100, 48);
  EXPECT_EQ(match_markers({small}, {large_found}).pairs.size(), 0u);
}

TEST(Match, IdAndDictionaryMustAgree) {
  const Marker r = square(3, 0, 0, 50);
  Marker other_id = r;
  other_id.id = 4;
  Marker other_dict = r;
  other_dict.dict = "APRILTAG_36h11";
  const MarkerMatching m = match_markers({r}, {other_id, other_dict});
  EXPECT_TRUE(m.pairs.empty());
  EXPECT_EQ(m.only_reference, std::vector<size_t>({0}));
  EXPECT_EQ(m.only_found, std::vector<size_t>({0, 1}));
}

TEST(Match, PairsTheClosestAndUsesEachReferenceOnce) {
  // Two reference markers with the same id, 6 px apart (both within tolerance of a found marker between them).
  const Marker r0 = square(5, 100, 100, 100), r1 = shifted(r0, 6, 0);
  const Marker f = shifted(r0, 4, 0);      // closer to r1 (2 px) than to r0 (4 px)
  const Marker g = shifted(r0, 1, 0);      // then r0 is left for this one
  const MarkerMatching m = match_markers({r0, r1}, {f, g, f});
  ASSERT_EQ(m.pairs.size(), 2u);
  EXPECT_EQ(m.pairs[0].reference, 1u);
  EXPECT_EQ(m.pairs[0].found, 0u);
  EXPECT_NEAR(m.pairs[0].corner_px, 2.0, 1e-6);
  EXPECT_EQ(m.pairs[1].reference, 0u);
  EXPECT_EQ(m.pairs[1].found, 1u);
  EXPECT_NEAR(m.pairs[1].corner_px, 1.0, 1e-6);
  EXPECT_NEAR(m.mean_corner_px(), 1.5, 1e-6);
  EXPECT_TRUE(m.only_reference.empty());
  EXPECT_EQ(m.only_found, std::vector<size_t>({2}));   // the second copy of f: both references are taken
}

TEST(Match, CornerOrderMatters) {
  // The same square with its corners started elsewhere is a different reading (a wrong rotation).
  const Marker r = square(9, 0, 0, 60);
  Marker turned = r;
  std::rotate(turned.corners.begin(), turned.corners.begin() + 1, turned.corners.end());
  EXPECT_TRUE(match_markers({r}, {turned}).pairs.empty());
}

TEST(Match, EmptyLists) {
  const MarkerMatching none = match_markers({}, {});
  EXPECT_TRUE(none.pairs.empty());
  EXPECT_EQ(none.mean_corner_px(), 0.0);
  const MarkerMatching only = match_markers({square(1, 0, 0, 30), square(2, 50, 0, 30)}, {});
  EXPECT_EQ(only.only_reference, std::vector<size_t>({0, 1}));
}
