// marker()'s ids: one id, a list, a range written as one, ids(...), and the old two-id range said as such.
#include "scene_test_util.hpp"

namespace arwb::script::test {
namespace {

TEST(SceneLua, RangesAndIdListsCoverExactlyTheirIds) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker({from = 100, to = 199}, { media = text "range" })
marker(ids(1, 5, 9), { media = text "list" })
marker(5, { media = text "five" })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto ov = s.update({track(1, 50, 50), track(4, 150, 50), track(5, 250, 50), track(99, 350, 50),
                            track(100, 50, 250), track(199, 150, 250), track(200, 250, 250)});
  EXPECT_EQ(count_overlays(ov, 1), 1);
  EXPECT_EQ(count_overlays(ov, 4), 0);
  EXPECT_EQ(count_overlays(ov, 99), 0);
  EXPECT_EQ(count_overlays(ov, 100), 1);
  EXPECT_EQ(count_overlays(ov, 199), 1);
  EXPECT_EQ(count_overlays(ov, 200), 0);
  // Several marker() calls on one id all apply, in declaration order.
  ASSERT_EQ(count_overlays(ov, 5), 2);
  std::vector<std::string> five;
  for (const auto& o : ov)
    if (o.marker_id == 5) five.push_back(o.media.text);
  EXPECT_EQ(five, (std::vector<std::string>{"list", "five"}));
  EXPECT_EQ(s.runtime.status().mappings[1].ids, "1, 5, 9");
}

// A list of ids is a table of the ids; a range says so ({from = a, to = b}); the old {a, b} still means the range
// a to b, with a warning naming its line, since it reads like the two ids.
TEST(SceneLua, AListIsItsIdsAndTheOldTwoIdRangeIsSaid) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker({3, 7, 12}, { media = text "list" })
marker({0, 2}, { media = text "old range" })
marker({}, { media = text "none" })
marker({from = 5}, { media = text "half" })
marker({1, "x"}, { media = text "bad" })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto ov = s.update({track(1, 50, 50), track(3, 150, 50), track(7, 250, 50), track(8, 350, 50),
                            track(12, 50, 250)});
  EXPECT_EQ(count_overlays(ov, 3), 1);
  EXPECT_EQ(count_overlays(ov, 7), 1);
  EXPECT_EQ(count_overlays(ov, 12), 1);
  EXPECT_EQ(count_overlays(ov, 8), 0) << "a list is not a range";
  EXPECT_EQ(count_overlays(ov, 1), 1) << "the old form is still the range 0 to 2";
  EXPECT_EQ(s.runtime.status().mappings[0].ids, "3, 7, 12");
  ASSERT_TRUE(s.has("scene.lua:3: marker: {0, 2} is read as the range 0 to 2; write {from = 0, to = 2} for the "
                    "range, or ids(0, 2) for the two ids")) << s.console();
  EXPECT_EQ(s.lines("is read as the range")[0].level, 1) << "a warning";
  EXPECT_TRUE(s.has("scene.lua:4: marker: an empty table has no ids")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:5: marker: an id range is {from = first, to = last} with two integers")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:6: marker: an id list holds integers only")) << s.console();
}

}  // namespace
}  // namespace arwb::script::test
