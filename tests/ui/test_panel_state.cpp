// Panels keep their own view state in the View (ui/context.hpp panel_state), not in function statics: each View
// has its own, and a new View starts afresh.
#include "ui/context.hpp"

#include <gtest/gtest.h>

using namespace arwb::ui;

namespace {
struct Counter : PanelState {
  int n = 0;
};
struct Other : PanelState {
  std::string text = "fresh";
};
}  // namespace

TEST(PanelState, EachViewHasItsOwnAndKeepsItBetweenFrames) {
  View a, b;
  panel_state<Counter>(a, Panel::log).n = 3;
  EXPECT_EQ(panel_state<Counter>(a, Panel::log).n, 3);   // the same state on the next draw
  EXPECT_EQ(panel_state<Counter>(b, Panel::log).n, 0);   // another window's is its own
  EXPECT_EQ(panel_state<Counter>(a, Panel::console).n, 0);   // and another panel's
  a = View();                                           // a reset
  EXPECT_EQ(panel_state<Counter>(a, Panel::log).n, 0);
}

TEST(PanelState, AnotherTypeInTheSameSlotStartsAfresh) {
  View v;
  panel_state<Counter>(v, Panel::scene).n = 5;
  EXPECT_EQ(panel_state<Other>(v, Panel::scene).text, "fresh");
  EXPECT_EQ(panel_state<Counter>(v, Panel::scene).n, 0);
}
