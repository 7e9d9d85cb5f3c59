// Text and web cards of neighbouring markers do not cover each other (place_apart): a card that would cover one
// placed before it goes to another side of its marker and stays there while that side is free; overlap = true
// keeps it where it was asked.
#include "scene_test_util.hpp"

namespace arwb::script::test {
namespace {

cv::Rect2d box_of(const Overlay& o) {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const cv::Point2d& c : o.quad.corners) {
    x0 = std::min(x0, c.x), y0 = std::min(y0, c.y);
    x1 = std::max(x1, c.x), y1 = std::max(y1, c.y);
  }
  return {x0, y0, x1 - x0, y1 - y0};
}

const Overlay& card_of(const std::vector<Overlay>& ov, int id) {
  for (const Overlay& o : ov)
    if (o.marker_id == id) return o;
  throw std::runtime_error("no card for marker " + std::to_string(id));
}

TEST(SceneCards, NeighboursCardsGoToSidesWhereTheyCoverNoneAndStayThere) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker(ids(1, 2), { media = text "a label long enough to reach the neighbour", place = billboard() })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  // Two markers 70 px apart: their cards above them, each wider than that, would overlap.
  auto ov = s.update({track(1, 200, 240), track(2, 270, 240)});
  ASSERT_EQ(ov.size(), 2u);
  EXPECT_EQ(card_of(ov, 1).place.side, Side::top) << "the first card placed keeps its side";
  EXPECT_NE(card_of(ov, 2).place.side, Side::top);
  EXPECT_EQ((box_of(card_of(ov, 1)) & box_of(card_of(ov, 2))).area(), 0.0);
  const Side moved = card_of(ov, 2).place.side;
  // Marker 2 moves away: its card stays on the side it was put on (it does not hop back to the top).
  ov = s.update({track(1, 200, 240), track(2, 480, 240)});
  EXPECT_EQ(card_of(ov, 2).place.side, moved);
}

TEST(SceneCards, OverlapTrueKeepsACardOnItsSide) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker(ids(1, 2), { media = text "a label long enough to reach the neighbour", place = billboard { overlap = true } })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto ov = s.update({track(1, 200, 240), track(2, 270, 240)});
  ASSERT_EQ(ov.size(), 2u);
  EXPECT_EQ(card_of(ov, 2).place.side, Side::top);
  EXPECT_GT((box_of(card_of(ov, 1)) & box_of(card_of(ov, 2))).area(), 0.0) << "they cover each other, as asked";
  EXPECT_EQ(s.runtime.status().mappings[0].placement, "billboard top size 0.6 overlap");
}

// Pictures are not cards: an image beside a marker stays where it was asked, whatever it covers.
TEST(SceneCards, ImagesStayWhereTheyWereAsked) {
  SceneFixture s;
  make_png(s.dir.path() / "media" / "a.png", 200, 50);
  const auto p = s.write("scene.lua", R"(
marker(ids(1, 2), { media = image "media/a.png", place = billboard() })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto ov = s.update({track(1, 200, 240), track(2, 270, 240)});
  ASSERT_EQ(ov.size(), 2u);
  EXPECT_EQ(card_of(ov, 2).place.side, Side::top);
}

}  // namespace
}  // namespace arwb::script::test
