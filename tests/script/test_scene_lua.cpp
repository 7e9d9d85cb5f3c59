// Tests for src/script: Lua scenes through SceneRuntime. Media are made on the fly (cv::imwrite, an MJPG AVI),
// markers are hand-made tracks, and update() is called directly, so no detector or window is involved.
#include "scene_test_util.hpp"

#include <cmath>

namespace arwb::script::test {
namespace {

// The issue's example, with the video as an MJPG AVI (what OpenCV can write everywhere).
const char* kExample = R"(dictionary "ARUCO_ORIGINAL"
marker(7,  { media = image "media/painting.png", place = on_marker() })
marker(8,  { media = video("media/clip.avi", { loop = true }), place = beside { side = "right", gap = 0.25, size = 1.5 } })
marker(20, { media = web "https://opencv.org", place = beside { side = "top" } })
marker({from = 100, to = 199}, { media = text(function(m) return "ID " .. m.id end), place = billboard() })
marker(30, { on_enter = function(m) print("enter", m.id) end,
             on_update = function(m, dt) print("update", m.id, dt) end,
             on_leave = function(m) print("leave", m.id) end })
)";

struct ExampleScene : SceneFixture {
  ExampleScene() {
    make_png(dir.path() / "media/painting.png", 80, 40);
    make_avi(dir.path() / "media/clip.avi");
    path = write("scene.lua", kExample);
  }
  std::string path;
};

TEST(SceneLua, ApiExampleGivesTheOverlays) {
  ExampleScene s;
  ASSERT_TRUE(s.runtime.load(s.path)) << s.runtime.status().error << "\n" << s.console();
  EXPECT_TRUE(s.runtime.status().ok);
  EXPECT_EQ(s.runtime.dictionary(), "ARUCO_ORIGINAL");
  ASSERT_EQ(s.runtime.status().mappings.size(), 5u) << s.console();
  EXPECT_EQ(s.runtime.status().mappings[3].ids, "100-199");
  EXPECT_EQ(s.runtime.status().mappings[0].line, 2);
  EXPECT_EQ(s.runtime.status().mappings[4].media, "callbacks only");

  const auto ov = s.update({track(7, 100, 100), track(8, 300, 100), track(20, 100, 300), track(150, 300, 300),
                            track(30, 500, 300)},
                           enters({7, 8, 20, 30, 150}));
  ASSERT_EQ(ov.size(), 4u) << s.console();

  const Overlay* o7 = find_overlay(ov, 7);
  ASSERT_TRUE(o7);
  EXPECT_EQ(o7->media.kind, MediaKind::image);
  EXPECT_EQ(o7->place.kind, PlaceKind::on_marker);
  ASSERT_TRUE(o7->content);
  EXPECT_EQ(o7->content->size(), cv::Size(80, 40));
  // Fit keeps the 2:1 aspect inside the marker: as wide as the marker, half as tall, centred on it.
  const double w7 = cv::norm(o7->quad.corners[1] - o7->quad.corners[0]);
  const double h7 = cv::norm(o7->quad.corners[3] - o7->quad.corners[0]);
  EXPECT_NEAR(w7, 60, 1.0);
  EXPECT_NEAR(h7, 30, 1.0);

  const Overlay* o8 = find_overlay(ov, 8);
  ASSERT_TRUE(o8);
  EXPECT_EQ(o8->media.kind, MediaKind::video);
  EXPECT_TRUE(o8->media.loop);
  EXPECT_EQ(o8->place.kind, PlaceKind::beside);
  EXPECT_EQ(o8->place.side, Side::right);
  EXPECT_DOUBLE_EQ(o8->place.size, 1.5);
  ASSERT_TRUE(o8->content);
  EXPECT_EQ(o8->content->size(), cv::Size(64, 48));
  // Right of the marker (its right edge is at x = 330), by the gap.
  for (const auto& c : o8->quad.corners) EXPECT_GT(c.x, 330.0);

  const Overlay* o20 = find_overlay(ov, 20);
  ASSERT_TRUE(o20);
  EXPECT_EQ(o20->media.kind, MediaKind::web);
  EXPECT_EQ(o20->media.url, "https://opencv.org");
  EXPECT_EQ(o20->media.title, "opencv.org");
  EXPECT_EQ(o20->place.side, Side::top);
  for (const auto& c : o20->quad.corners) EXPECT_LT(c.y, 270.0);   // above the marker's top edge (y = 270)
  ASSERT_TRUE(o20->content);

  const Overlay* o150 = find_overlay(ov, 150);
  ASSERT_TRUE(o150);
  EXPECT_EQ(o150->media.kind, MediaKind::text);
  EXPECT_EQ(o150->media.text, "ID 150");
  EXPECT_EQ(o150->place.kind, PlaceKind::billboard);
  EXPECT_EQ(o150->mapping, 3);
  ASSERT_TRUE(o150->content);

  EXPECT_FALSE(find_overlay(ov, 30));   // callbacks only
  EXPECT_TRUE(s.has("enter\t30")) << s.console();
  EXPECT_TRUE(s.has("update\t30\t0.1")) << s.console();

  // 30 leaves: on_leave; the others are still tracked.
  s.update({track(7, 100, 100), track(8, 300, 100), track(20, 100, 300), track(150, 300, 300)},
           {leave_event(30)});
  EXPECT_TRUE(s.has("leave\t30")) << s.console();
  const auto& rows = s.runtime.status().mappings;
  EXPECT_EQ(rows[4].state, "waiting");
  EXPECT_EQ(rows[0].state.rfind("visible", 0), 0u) << rows[0].state;
}

TEST(SceneLua, ComputedTextFollowsEachMarkerEveryFrame) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker({from = 100, to = 199}, { media = text(function(m) return string.format("%d %.1f", m.id, m.seconds) end) })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  auto ov = s.update({track(100, 100, 100, 60, true, 0.5), track(199, 300, 100, 60, true, 2.0)});
  ASSERT_EQ(ov.size(), 2u) << s.console();
  EXPECT_EQ(find_overlay(ov, 100)->media.text, "100 0.5");
  EXPECT_EQ(find_overlay(ov, 199)->media.text, "199 2.0");
  ov = s.update({track(100, 100, 100, 60, true, 0.6)});
  ASSERT_EQ(ov.size(), 1u);
  EXPECT_EQ(ov[0].media.text, "100 0.6");
}

TEST(SceneLua, CallbackReturnsChangeMediaAndPlacementOfThatMarkerOnly) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker({from = 1, to = 2}, {
  media = text "start",
  on_enter = function(m)
    if m.id == 1 then return { media = text "entered", place = beside { side = "left" } } end
  end,
  on_update = function(m, dt)
    if m.seconds > 5 then return { media = text("late " .. m.id), place = "screen" } end
  end,
})
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  auto ov = s.update({track(1, 200, 200), track(2, 400, 200)}, enters({1, 2}));
  ASSERT_EQ(ov.size(), 2u) << s.console();
  EXPECT_EQ(find_overlay(ov, 1)->media.text, "entered");
  EXPECT_EQ(find_overlay(ov, 1)->place.kind, PlaceKind::beside);
  EXPECT_EQ(find_overlay(ov, 1)->place.side, Side::left);
  EXPECT_EQ(find_overlay(ov, 2)->media.text, "start");
  EXPECT_EQ(find_overlay(ov, 2)->place.kind, PlaceKind::on_marker);

  // The change sticks while the callbacks return nothing.
  ov = s.update({track(1, 200, 200), track(2, 400, 200)});
  EXPECT_EQ(find_overlay(ov, 1)->media.text, "entered");
  EXPECT_EQ(find_overlay(ov, 2)->media.text, "start");

  // A later return replaces it; a placement by name gives that kind's defaults.
  ov = s.update({track(1, 200, 200, 60, true, 6.0), track(2, 400, 200)});
  EXPECT_EQ(find_overlay(ov, 1)->media.text, "late 1");
  EXPECT_EQ(find_overlay(ov, 1)->place.kind, PlaceKind::screen);
  EXPECT_EQ(find_overlay(ov, 2)->media.text, "start");

  // Still after leaving and coming back (overrides belong to the id until the scene reloads).
  s.update({track(2, 400, 200)}, {leave_event(1)});
  ov = s.update({track(1, 200, 200), track(2, 400, 200)}, enters({1}));
  EXPECT_EQ(find_overlay(ov, 1)->media.text, "entered");   // on_enter ran again

  // A reload starts afresh.
  ASSERT_TRUE(s.runtime.load(p));
  ov = s.update({track(2, 400, 200)});
  EXPECT_EQ(find_overlay(ov, 2)->media.text, "start");
}

TEST(SceneLua, ReturningMediaFalseHidesAndBadReturnsAreReported) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker(1, { media = text "shown", on_update = function(m) if m.seconds > 1 then return { media = false } end end })
marker(2, { media = text "two", on_update = function(m) return { media = 5, plac = on_marker() } end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  auto ov = s.update({track(1, 100, 100), track(2, 300, 100)});
  EXPECT_TRUE(find_overlay(ov, 1));
  EXPECT_EQ(find_overlay(ov, 2)->media.text, "two");   // the bad return changed nothing
  EXPECT_TRUE(s.has("scene.lua:3: on_update of marker 2 returned media that is not a media value")) << s.console();
  EXPECT_TRUE(s.has("returned unknown field 'plac' (did you mean 'place'?)")) << s.console();
  ov = s.update({track(1, 100, 100, 60, true, 2.0), track(2, 300, 100)});
  EXPECT_FALSE(find_overlay(ov, 1));
}

TEST(SceneLua, EnterAndLeaveRunInEventOrderThenDeclarationOrder) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
local function log(what) return function(m) print(what, m.id) end end
marker({from = 1, to = 9}, { on_enter = log("A enter"), on_leave = log("A leave") })
marker(2, { on_enter = log("B enter"), on_leave = log("B leave"), on_update = log("B update") })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  s.update({track(1, 100, 100), track(2, 300, 100)}, enters({1, 2}));
  s.update({track(2, 300, 100)}, {leave_event(1)});
  s.update({}, {leave_event(2)});
  const std::vector<std::string> want = {"A enter\t1", "A enter\t2", "B enter\t2", "B update\t2",
                                         "A leave\t1", "B update\t2", "A leave\t2", "B leave\t2"};
  EXPECT_EQ(s.printed(), want) << s.console();
}

TEST(SceneLua, MarkerStateTable) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker(7, { on_update = function(m, dt)
  print(m.id, m.dict, #m.corners, m.corners[1].x, m.corners[1].y, m.corners[3].x, m.centre.x, m.centre.y,
        m.side, m.seconds, m.held, dt)
end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  s.update({track(7, 100, 200, 40, true, 1.5)}, enters({7}), 0.25);
  s.update({track(7, 100, 200, 40, false, 1.75)}, {}, 0.25);
  const std::vector<std::string> want = {"7\tARUCO_ORIGINAL\t4\t80.0\t180.0\t120.0\t100.0\t200.0\t40.0\t1.5\tfalse\t0.25",
                                         "7\tARUCO_ORIGINAL\t4\t80.0\t180.0\t120.0\t100.0\t200.0\t40.0\t1.75\ttrue\t0.25"};
  EXPECT_EQ(s.printed(), want) << s.console();
  EXPECT_EQ(s.runtime.status().mappings[0].state, "held");
}

TEST(SceneLua, SyntaxErrorNamesFileAndLine) {
  SceneFixture s;
  const auto p = s.write("scene.lua", "marker(1, { media = text \"a\" })\n\nmarker(2, { media = = })\n");
  EXPECT_FALSE(s.runtime.load(p));
  const auto& st = s.runtime.status();
  EXPECT_FALSE(st.ok);
  EXPECT_NE(st.error.find("scene.lua:3:"), std::string::npos) << st.error;
  EXPECT_EQ(st.error_line, 3);
  EXPECT_TRUE(s.has("scene.lua:3:"));
  EXPECT_EQ(s.lines("scene.lua:3:").at(0).level, 2);
}

TEST(SceneLua, RuntimeErrorsInCallbacksHaveTheirLineAndCollapse) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(marker(7, {
  media = text "still here",
  on_update = function(m, dt)
    local t = nil
    return t.field
  end,
})
marker(8, { on_enter = function(m) error("custom failure") end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  for (int i = 0; i < 2; ++i) {
    const auto ov = s.update({track(7, 100, 100)});
    EXPECT_TRUE(find_overlay(ov, 7)) << "frame " << i;   // an error does not stop the media
  }
  const auto l = s.lines("scene.lua:5: attempt to index a nil value");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_EQ(l[0].repeats, 2);
  EXPECT_EQ(l[0].level, 2);
  EXPECT_NE(l[0].text.find("on_update of marker 7"), std::string::npos) << l[0].text;
  EXPECT_EQ(l[0].text.find("traceback"), std::string::npos);
  EXPECT_EQ(s.runtime.status().mappings[0].state.rfind("error: ", 0), 0u);

  s.update({track(7, 100, 100), track(8, 300, 100)}, enters({8}));
  EXPECT_TRUE(s.has("scene.lua:8: custom failure (in on_enter of marker 8)")) << s.console();
}

TEST(SceneLua, AMappingWithAMissingMediaFileKeepsItsRowSkippedAndNothingRuns) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(marker(7, { media = text "fine" })
marker({from = 8, to = 9}, { media = image "logo.png", on_enter = function(m) print("entered", m.id) end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  const auto ov = s.update({track(7, 100, 100), track(8, 300, 100)}, enters({7, 8}));
  ASSERT_EQ(ov.size(), 1u);
  EXPECT_EQ(ov[0].marker_id, 7);
  EXPECT_EQ(s.count_printed("entered\t8"), 0) << s.console();
  const auto& rows = s.runtime.status().mappings;
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].health, MappingHealth::ok);
  EXPECT_EQ(rows[1].health, MappingHealth::skipped);
  EXPECT_EQ(rows[1].ids, "8-9");
  EXPECT_EQ(rows[1].reason_line, 2);
  EXPECT_NE(rows[1].reason.find("logo.png: no such file"), std::string::npos) << rows[1].reason;
  // The error reaches the workbench's log once, however many frames follow.
  s.update({track(7, 100, 100), track(8, 300, 100)});
  const auto errors = s.runtime.take_errors();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0], rows[1].reason);
  EXPECT_TRUE(s.runtime.take_errors().empty());
}

// An error in on_enter or on_leave marks its row and line as one in on_update does, and keeps it marked after the
// frame it happened on (they run once per visit; on_leave with the marker gone), until one of them runs cleanly.
TEST(SceneLua, AnEnterOrLeaveErrorMarksItsRowWithItsLine) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(marker(7, { media = text "seven",
  on_enter = function(m) error("enter failed") end })
marker(8, { media = text "eight",
  on_leave = function(m) error("leave failed") end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  s.update({track(7, 100, 100), track(8, 300, 100)}, enters({7, 8}));
  s.update({track(7, 100, 100), track(8, 300, 100)});
  const auto& rows = s.runtime.status().mappings;
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].health, MappingHealth::error) << "still marked on the next frame";
  EXPECT_EQ(rows[0].reason_line, 2);
  EXPECT_NE(rows[0].reason.find("enter failed"), std::string::npos) << rows[0].reason;
  EXPECT_EQ(rows[1].health, MappingHealth::ok);
  s.update({track(7, 100, 100)}, {leave_event(8)});
  s.update({track(7, 100, 100)});
  EXPECT_EQ(rows[1].health, MappingHealth::error) << "marked with the marker gone";
  EXPECT_EQ(rows[1].reason_line, 4);
  EXPECT_NE(rows[1].reason.find("leave failed"), std::string::npos) << rows[1].reason;
}

TEST(SceneLua, ARuntimeErrorMarksItsRowWithTheFailingLineThenDisabled) {
  ScriptLimits limits;
  limits.failures_in_a_row = 3;
  SceneFixture s(limits);
  const auto p = s.write("scene.lua", R"(marker(7, { media = text "seven" })
marker(8, {
  media = text "eight",
  on_update = function(m, dt)
    local t = nil
    return t.field
  end,
})
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  s.update({track(7, 100, 100), track(8, 300, 100)});
  const auto& rows = s.runtime.status().mappings;
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].health, MappingHealth::ok);
  EXPECT_EQ(rows[1].health, MappingHealth::error);
  EXPECT_EQ(rows[1].line, 2);          // declared here
  EXPECT_EQ(rows[1].reason_line, 6);   // failed here
  EXPECT_NE(rows[1].reason.find("attempt to index a nil value"), std::string::npos) << rows[1].reason;
  for (int i = 0; i < 3; ++i) s.update({track(7, 100, 100), track(8, 300, 100)});
  EXPECT_EQ(rows[1].health, MappingHealth::disabled);
  EXPECT_EQ(rows[1].reason_line, 6);
  EXPECT_NE(rows[1].reason.find("disabled"), std::string::npos) << rows[1].reason;
  // The marker gone, the row still says so.
  s.update({track(7, 100, 100)});
  EXPECT_EQ(rows[1].health, MappingHealth::disabled);
  // The log hears of the error and of the disabling, once each.
  const auto errors = s.runtime.take_errors();
  ASSERT_EQ(errors.size(), 2u) << s.console();
  EXPECT_NE(errors[0].find("scene.lua:6: attempt to index a nil value"), std::string::npos) << errors[0];
  EXPECT_NE(errors[1].find("disabled"), std::string::npos) << errors[1];
}

TEST(SceneLua, ErrorsAlternatingBetweenTwoMarkersStillCollapse) {
  ScriptLimits patient;
  patient.failures_in_a_row = 1000;   // collapsing alone, not the disabling of ErrorsOnEveryFrameDisableTheCallback
  SceneFixture s(patient);
  const auto p = s.write("scene.lua", R"(
marker({from = 1, to = 2}, { on_update = function(m) error("bad " .. m.id) end })
)");
  ASSERT_TRUE(s.runtime.load(p));
  for (int i = 0; i < 5; ++i) s.update({track(1, 100, 100), track(2, 300, 100)});
  EXPECT_EQ(s.runtime.status().console.size(), 2u) << s.console();
  EXPECT_EQ(s.lines("bad 1").at(0).repeats, 5);
  EXPECT_EQ(s.lines("bad 2").at(0).repeats, 5);
}

TEST(SceneLua, FailedReloadKeepsTheLastGoodScene) {
  SceneFixture s;
  const auto p = s.write("scene.lua", "marker(7, { media = text \"good\" })\n");
  ASSERT_TRUE(s.runtime.load(p));
  const uint64_t gen = s.runtime.status().generation;
  ASSERT_EQ(s.update({track(7, 100, 100)}).size(), 1u);

  s.write("scene.lua", "marker(7, { media = text \"new\" })\nerror('half way')\n");
  EXPECT_FALSE(s.runtime.load(p));
  const auto& st = s.runtime.status();
  EXPECT_TRUE(st.ok);
  EXPECT_EQ(st.generation, gen);
  EXPECT_NE(st.error.find("scene.lua:2: half way"), std::string::npos) << st.error;
  EXPECT_EQ(st.error_line, 2);
  const auto ov = s.update({track(7, 100, 100)});
  ASSERT_EQ(ov.size(), 1u);
  EXPECT_EQ(ov[0].media.text, "good");
  ASSERT_EQ(st.mappings.size(), 1u);

  // Fixed: the new scene replaces it and the error clears.
  s.write("scene.lua", "marker(7, { media = text \"fixed\" })\n");
  ASSERT_TRUE(s.runtime.load(p));
  EXPECT_TRUE(st.error.empty());
  EXPECT_EQ(st.error_line, 0);
  EXPECT_EQ(st.generation, gen + 1);
  EXPECT_EQ(s.update({track(7, 100, 100)}).at(0).media.text, "fixed");
}

TEST(SceneLua, BadValuesAreReportedWithTheirLineAndSkipped) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(marker(-1, { media = text "minus" })
marker(7, { media = text "nan", place = beside { size = 0/0 } })
marker(8, { media = text "corner", place = "corner" })
marker(9, { media = text "diagonal", place = beside { side = "diagonal" } })
marker(1024, { media = text "too big" })
marker(10, { media = "painting.png" })
marker(11, { media = text "zero", place = on_marker { scale = 0 } })
marker({from = 5, to = 3}, { media = text "empty range" })
marker(12, { media = text "fine" })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  auto expect_line = [&](const std::string& prefix, const std::string& word) {
    bool found = false;
    for (const auto& l : s.lines(prefix)) found = found || (l.text.find(word) != std::string::npos && l.level == 2);
    EXPECT_TRUE(found) << prefix << " ... " << word << "\n" << s.console();
  };
  expect_line("scene.lua:1: ", "id -1");
  expect_line("scene.lua:2: ", "size must be a finite number > 0");
  expect_line("scene.lua:3: ", "unknown placement 'corner'");
  expect_line("scene.lua:4: ", "unknown side 'diagonal'");
  expect_line("scene.lua:5: ", "id 1024 is not a marker of ARUCO_ORIGINAL");
  expect_line("scene.lua:6: ", "media must be a media value");
  expect_line("scene.lua:7: ", "scale");
  expect_line("scene.lua:8: ", "empty");
  // Every refused call keeps its row, skipped, with the reason and its line; only the last one runs.
  const auto& rows = s.runtime.status().mappings;
  ASSERT_EQ(rows.size(), 9u) << s.console();
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(rows[size_t(i)].health, MappingHealth::skipped) << i;
    EXPECT_EQ(rows[size_t(i)].line, i + 1);
    EXPECT_EQ(rows[size_t(i)].reason_line, i + 1);
    EXPECT_NE(rows[size_t(i)].reason.find("scene.lua:" + std::to_string(i + 1) + ": "), std::string::npos)
        << rows[size_t(i)].reason;
    EXPECT_EQ(rows[size_t(i)].state.rfind("skipped: ", 0), 0u) << rows[size_t(i)].state;
  }
  EXPECT_EQ(rows[0].ids, "?");   // refused for its id
  EXPECT_EQ(rows[8].health, MappingHealth::ok);
  const auto ov = s.update({track(7, 100, 100), track(8, 200, 100), track(9, 300, 100), track(12, 400, 100)});
  ASSERT_EQ(ov.size(), 1u);
  EXPECT_EQ(ov[0].marker_id, 12);
  EXPECT_EQ(ov[0].media.text, "fine");
}

TEST(SceneLua, UnknownFieldsAreWarningsWithASuggestion) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker(7, { media = text "x", plac = beside() })
marker(8, { media = text "y", place = beside { sid = "left" } })
)");
  ASSERT_TRUE(s.runtime.load(p));
  const auto l = s.lines("scene.lua:2: unknown field 'plac' (did you mean 'place'?)");
  ASSERT_EQ(l.size(), 1u) << s.console();
  EXPECT_EQ(l[0].level, 1);
  EXPECT_TRUE(s.has("scene.lua:3: beside: unknown field 'sid' (did you mean 'side'?)")) << s.console();
  EXPECT_EQ(s.runtime.status().mappings.size(), 2u);   // warnings do not skip
}

TEST(SceneLua, MediaPathsStayInsideTheScenesFolder) {
  SceneFixture s;
  make_png(s.dir.path() / "scenes/inside.png");
  make_png(s.dir.path() / "outside.png");
  std::filesystem::create_directories(s.dir.path() / "scenes");
  const auto p = s.write("scenes/scene.lua", R"(marker(1, { media = image "../outside.png" })
marker(2, { media = image "/etc/passwd" })
marker(3, { media = image "missing.png" })
marker(4, { media = web "ftp://example.org/x" })
marker(5, { media = video "inside.png" })
marker(6, { media = image "inside.png" })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_TRUE(s.has("scene.lua:1: ../outside.png: leaves the scene's folder")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:2: /etc/passwd: absolute paths are not allowed")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:3: missing.png: no such file")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:4: ")) << s.console();
  EXPECT_TRUE(s.has("scene.lua:5: inside.png: an image, not a video")) << s.console();
  ASSERT_EQ(s.runtime.status().mappings.size(), 6u);
  for (size_t i = 0; i < 5; ++i) EXPECT_EQ(s.runtime.status().mappings[i].health, MappingHealth::skipped) << i;
  const auto ov = s.update({track(1, 100, 100), track(2, 200, 100), track(6, 300, 100)});
  ASSERT_EQ(ov.size(), 1u);
  EXPECT_EQ(ov[0].marker_id, 6);
  EXPECT_EQ(ov[0].media.source, "inside.png");
}

TEST(SceneLua, ReloadIfChangedPicksUpAnEdit) {
  SceneFixture s;
  EXPECT_FALSE(s.runtime.reload_if_changed());   // nothing loaded yet
  const auto p = s.write("scene.lua", "marker(7, { media = text \"one\" })\n");
  ASSERT_TRUE(s.runtime.load(p));
  EXPECT_FALSE(s.runtime.reload_if_changed());
  s.write("scene.lua", "marker(7, { media = text \"two, longer\" })\n");
  EXPECT_TRUE(s.runtime.reload_if_changed());
  EXPECT_FALSE(s.runtime.reload_if_changed());
  EXPECT_EQ(s.update({track(7, 100, 100)}).at(0).media.text, "two, longer");
  // A broken edit is tried once, reported, and the good scene stays.
  s.write("scene.lua", "marker(7, { media = text \"three\" \n");
  EXPECT_TRUE(s.runtime.reload_if_changed());
  EXPECT_FALSE(s.runtime.reload_if_changed());
  EXPECT_FALSE(s.runtime.status().error.empty());
  EXPECT_EQ(s.update({track(7, 100, 100)}).at(0).media.text, "two, longer");
}

TEST(SceneLua, DictionaryNamesAndIdRanges) {
  SceneFixture s;
  auto p = s.write("a.lua", "dictionary \"4X4_50\"\nmarker(49, { media = text \"ok\" })\nmarker(50, { media = text \"no\" })\n");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  EXPECT_EQ(s.runtime.dictionary(), "4X4_50");
  EXPECT_EQ(s.runtime.status().dictionary, "4X4_50");
  EXPECT_TRUE(s.has("a.lua:3: marker: id 50 is not a marker of 4X4_50 (ids 0 to 49)")) << s.console();
  ASSERT_EQ(s.runtime.status().mappings.size(), 2u);
  EXPECT_EQ(s.runtime.status().mappings[1].health, MappingHealth::skipped);
  // Tracks of another dictionary are not this scene's markers.
  auto t49 = track(49, 100, 100);
  t49.dict = "ARUCO_ORIGINAL";
  EXPECT_TRUE(s.update({t49}).empty());
  t49.dict = "4X4_50";
  EXPECT_EQ(s.update({t49}).size(), 1u);

  p = s.write("b.lua", "\ndictionary \"NOPE_99\"\n");
  EXPECT_FALSE(s.runtime.load(p));
  EXPECT_NE(s.runtime.status().error.find("b.lua:2: dictionary: unknown dictionary 'NOPE_99'"), std::string::npos)
      << s.runtime.status().error;
  EXPECT_EQ(s.runtime.status().error_line, 2);

  p = s.write("c.lua", "marker(1, { media = text \"x\" })\ndictionary \"4X4_50\"\n");
  EXPECT_FALSE(s.runtime.load(p));
  EXPECT_NE(s.runtime.status().error.find("c.lua:2: dictionary must be declared before the first marker()"),
            std::string::npos)
      << s.runtime.status().error;
}

TEST(SceneLua, StageMediaShowTheFramesStagePicture) {
  SceneFixture s;
  std::array<cv::Mat, kStageCount> views;
  views[static_cast<size_t>(Stage::adaptive_threshold)] = cv::Mat(120, 160, CV_8UC1, cv::Scalar(255));
  s.views = &views;
  const auto p = s.write("scene.lua", R"(
marker(3, { media = stage "adaptive_threshold", place = screen { corner = "bottom_left", size = 0.5 } })
marker(4, { media = stage "no_such_stage" })
)");
  ASSERT_TRUE(s.runtime.load(p));
  EXPECT_TRUE(s.has("scene.lua:3: stage: unknown stage 'no_such_stage'")) << s.console();
  const auto ov = s.update({track(3, 300, 200)});
  ASSERT_EQ(ov.size(), 1u) << s.console();
  EXPECT_EQ(ov[0].media.kind, MediaKind::stage);
  ASSERT_TRUE(ov[0].content);
  EXPECT_EQ(ov[0].content->size(), cv::Size(160, 120));
  uint64_t version = 0;
  const auto img = ov[0].content->current(&version);
  ASSERT_TRUE(img);
  EXPECT_EQ(version, s.frame_index);
  EXPECT_EQ(img->type(), CV_8UC3);
  // Pinned to the bottom-left corner, half the frame wide.
  double min_x = 1e9, max_x = -1e9, max_y = -1e9;
  for (const auto& c : ov[0].quad.corners) {
    min_x = std::min(min_x, c.x);
    max_x = std::max(max_x, c.x);
    max_y = std::max(max_y, c.y);
  }
  EXPECT_LT(min_x, 100);
  EXPECT_NEAR(max_x - min_x, 320, 2);
  EXPECT_GT(max_y, 380);
}

TEST(SceneLua, EachMarkerHasItsOwnVideoPlayerKeptWhileAway) {
  SceneFixture s;
  make_avi(s.dir.path() / "clip.avi");
  const auto p = s.write("scene.lua", "marker({from = 1, to = 2}, { media = video(\"clip.avi\", { loop = true }) })\n");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error << s.console();
  auto ov = s.update({track(1, 100, 100), track(2, 300, 100)}, enters({1, 2}));
  ASSERT_EQ(ov.size(), 2u) << s.console();
  const auto player1 = find_overlay(ov, 1)->content;
  EXPECT_NE(player1, find_overlay(ov, 2)->content);
  s.update({track(2, 300, 100)}, {leave_event(1)});
  ov = s.update({track(1, 100, 100), track(2, 300, 100)}, enters({1}));
  EXPECT_EQ(find_overlay(ov, 1)->content, player1);   // the same player resumes
}

TEST(SceneLua, TwoPrintsOfOneIdEachHaveTheirOverlayAndCallbacks) {
  SceneFixture s;
  make_avi(s.dir.path() / "clip.avi");
  const auto p = s.write("scene.lua", R"(
marker(5, { media = video("clip.avi", { loop = true }),
  on_enter = function(m) print("enter", m.id, m.instance) end,
  on_leave = function(m) print("leave", m.id, m.instance) end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error << s.console();
  const TrackedMarker a = track(5, 100, 100, 60, true, 0, 0), b = track(5, 400, 300, 60, true, 0, 1);
  auto ov = s.update({a, b}, {{TrackEvent::Kind::enter, 5, a.track_id}, {TrackEvent::Kind::enter, 5, b.track_id}});
  ASSERT_EQ(count_overlays(ov, 5), 2) << s.console();
  // Each drawn on its own print, each with its own player.
  auto mid_x = [](const Overlay& o) {
    double x = 0;
    for (const auto& c : o.quad.corners) x += c.x / 4;
    return x;
  };
  EXPECT_NEAR(mid_x(ov[0]), 100, 1) << "the first print's media";
  EXPECT_NEAR(mid_x(ov[1]), 400, 1) << "the second print's media";
  EXPECT_NE(ov[0].content, ov[1].content);
  // Each overlay says which print it belongs to.
  EXPECT_EQ(ov[0].track_id, a.track_id);
  EXPECT_EQ(ov[1].track_id, b.track_id);
  EXPECT_EQ(s.runtime.status().mappings[0].state, "visible 0.0 s (2 markers)");
  // The first leaves: only its on_leave runs, the other keeps its media.
  TrackedMarker b0 = b;
  b0.instance = 0;
  ov = s.update({b0}, {leave_event(5, 0)});
  ASSERT_EQ(count_overlays(ov, 5), 1);
  EXPECT_NEAR(mid_x(ov[0]), 400, 1);
  const std::vector<std::string> want = {"enter\t5\t0", "enter\t5\t1", "leave\t5\t0"};
  EXPECT_EQ(s.printed(), want) << s.console();
}

TEST(SceneLua, PrintIsTabSeparatedAndNamesAreShown) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
print("a", 1, nil, true, 2.5)
print("two\nlines")
marker(7, { name = "painting", media = text "x" })
)");
  ASSERT_TRUE(s.runtime.load(p));
  EXPECT_EQ(s.printed(), (std::vector<std::string>{"a\t1\tnil\ttrue\t2.5", "two", "lines"}));
  const auto& row = s.runtime.status().mappings.at(0);
  // MappingRow may carry the name in a field of its own; else it is shown with the ids.
  const auto shown_name = [](const auto& r) -> std::string {
    if constexpr (requires { r.name; }) return r.name;
    else return r.ids;
  };
  EXPECT_NE(shown_name(row).find("painting"), std::string::npos);
}

TEST(SceneLua, CallbacksCannotDeclareMarkersAfterLoading) {
  SceneFixture s;
  const auto p = s.write("scene.lua", "marker(7, { on_enter = function() marker(8, {}) end })\n");
  ASSERT_TRUE(s.runtime.load(p));
  s.update({track(7, 100, 100)}, enters({7}));
  EXPECT_TRUE(s.has("marker() can only be used while the scene loads")) << s.console();
  EXPECT_EQ(s.runtime.status().mappings.size(), 1u);
}

TEST(SceneLua, UnloadDropsTheScene) {
  SceneFixture s;
  const auto p = s.write("scene.lua", "marker(7, { media = text \"x\" })\n");
  ASSERT_TRUE(s.runtime.load(p));
  s.runtime.unload();
  EXPECT_FALSE(s.runtime.status().ok);
  EXPECT_TRUE(s.runtime.status().file.empty());
  EXPECT_TRUE(s.update({track(7, 100, 100)}).empty());
  EXPECT_FALSE(s.runtime.reload_if_changed());
}


// A marker's pose reaches the callbacks: "show the label when closer than 30 cm" needs m.pose.distance.
TEST(SceneLua, CallbacksSeeTheMarkersPoseWhenItHasOne) {
  SceneFixture s;
  const auto p = s.write("scene.lua", R"(
marker(1, { on_update = function(m)
  if m.pose then print(string.format("%.2f %.1f %.2f %s %s %g", m.pose.distance, m.pose.tilt, m.pose.z,
                                     tostring(m.pose.assumed), m.pose.unit, m.pose.side))
  else print("no pose") end
end })
)");
  ASSERT_TRUE(s.runtime.load(p)) << s.runtime.status().error;
  TrackedMarker with = track(1, 100, 100);
  MarkerPose pose;
  pose.pose.rvec = cv::Vec3d(CV_PI, 0, 0);   // facing the camera, upright
  pose.pose.tvec = cv::Vec3d(0, 3, 4);
  pose.assumed_camera = true;
  with.pose = pose;
  s.update({with}, enters({1}));
  s.update({track(1, 100, 100)}, {});
  // Poses of a printed size: the unit says mm, and z / side is in marker sides.
  s.marker_side = 50;
  s.pose_unit = "mm";
  pose.pose.tvec = cv::Vec3d(0, 150, 200);
  with.pose = pose;
  s.update({with}, {});
  const std::vector<std::string> want = {"5.00 36.9 4.00 true marker sides 1", "no pose", "250.00 36.9 200.00 true mm 50"};
  EXPECT_EQ(s.printed(), want) << s.console();
}

}  // namespace
}  // namespace arwb::script::test
