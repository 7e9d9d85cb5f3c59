// Markers over time: enter once, held briefly when missed, leave after the hold.
#include "track/tracker.hpp"

#include <gtest/gtest.h>

namespace arwb {
namespace {

Marker at(int id, float x, float s = 50) {
  Marker m;
  m.id = id;
  m.dict = "ARUCO_ORIGINAL";
  m.corners = {{{x, 100}, {x + s, 100}, {x + s, 100 + s}, {x, 100 + s}}};
  return m;
}

TEST(Tracker, EntersHoldsAndLeaves) {
  Tracker t({0.25});
  auto ev = t.update({at(7, 10), at(3, 200)}, 0.0);
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].id, 3);
  EXPECT_EQ(ev[0].kind, TrackEvent::Kind::enter);
  EXPECT_EQ(ev[1].id, 7);
  ASSERT_EQ(t.tracks().size(), 2u);
  EXPECT_EQ(t.tracks()[0].id, 3);

  ev = t.update({at(7, 12)}, 0.1);   // 3 missed: held, no event
  EXPECT_TRUE(ev.empty());
  ASSERT_EQ(t.tracks().size(), 2u);
  EXPECT_FALSE(t.tracks()[0].detected);
  EXPECT_FLOAT_EQ(t.tracks()[0].corners[0].x, 200);   // its last corners
  EXPECT_TRUE(t.tracks()[1].detected);
  EXPECT_NEAR(t.tracks()[1].visible_s, 0.1, 1e-12);
  EXPECT_FLOAT_EQ(t.tracks()[1].corners[0].x, 12);

  ev = t.update({at(7, 14)}, 0.4);   // 3 missed for 0.4 s > hold: leaves
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, TrackEvent::Kind::leave);
  EXPECT_EQ(ev[0].id, 3);
  ASSERT_EQ(t.tracks().size(), 1u);

  ev = t.update({at(7, 14), at(3, 200)}, 0.5);   // back: a new visit starts at 0 s
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, TrackEvent::Kind::enter);
  EXPECT_NEAR(t.tracks()[0].visible_s, 0.0, 1e-12);
  EXPECT_NEAR(t.tracks()[1].visible_s, 0.5, 1e-12);
}

TEST(Tracker, CentreSideAndDuplicates) {
  Tracker t;
  t.update({at(5, 0, 20), at(5, 300, 80)}, 0);   // the same id twice: the larger one is tracked
  ASSERT_EQ(t.tracks().size(), 1u);
  EXPECT_NEAR(t.tracks()[0].side_px, 80, 1e-9);
  EXPECT_NEAR(t.tracks()[0].centre.x, 340, 1e-9);
  EXPECT_NEAR(t.tracks()[0].centre.y, 140, 1e-9);
}

}  // namespace
}  // namespace arwb
