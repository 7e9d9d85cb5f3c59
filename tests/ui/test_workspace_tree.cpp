// The workspace tree without a window (ui/workspace_tree.hpp): the shipped layouts, panels moved, closed and
// opened where they belong, the tree folding when a region empties, what the View asks for followed, and
// workspaces.json written and read back or refused with the reason.
#include "ui/workspace_tree.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

namespace arwb::ui {
namespace {

// Every panel in the layout's regions, in drawing order.
std::vector<Panel> panels_of(const Layout& l) {
  std::vector<Panel> out;
  for (int r : regions(l)) out.insert(out.end(), at(l, r).tabs.begin(), at(l, r).tabs.end());
  return out;
}

TEST(WorkspaceTree, ShippedLayoutsShowTheLiveViewAndEachPanelOnce) {
  const std::vector<Workspace> shipped = shipped_workspaces();
  ASSERT_EQ(shipped.size(), 5u);
  for (const Workspace& w : shipped) {
    for (const bool present : {false, true}) {
      const Layout& l = w.layout(present);
      std::vector<Panel> all = panels_of(l);
      EXPECT_NE(std::find(all.begin(), all.end(), Panel::live_view), all.end()) << w.name;
      std::sort(all.begin(), all.end());
      EXPECT_EQ(std::adjacent_find(all.begin(), all.end()), all.end()) << w.name << ": a panel twice";
      for (int s : splits(l)) {
        EXPECT_GE(at(l, s).first, 0) << w.name;
        EXPECT_GE(at(l, s).second, 0) << w.name;
      }
    }
  }
}

TEST(WorkspaceTree, MovingARegionsLastPanelFoldsTheRegionAway) {
  Layout l = make_layout(columns(0.5f, tabs({Panel::live_view}), tabs({Panel::log, Panel::source})));
  ASSERT_EQ(regions(l).size(), 2u);
  const int right = region_of(l, Panel::log);
  move_panel(l, Panel::live_view, right);
  ASSERT_EQ(regions(l).size(), 1u);
  const LayoutNode& only = at(l, regions(l)[0]);
  EXPECT_EQ(only.tabs, (std::vector<Panel>{Panel::log, Panel::source, Panel::live_view}));
  EXPECT_EQ(only.active, 2) << "the moved panel is in front";
  EXPECT_TRUE(splits(l).empty());
}

TEST(WorkspaceTree, ClosingPanelsFoldsRegionsAndLeavesTheRootEmpty) {
  Layout l = make_layout(rows(0.5f, tabs({Panel::live_view}), tabs({Panel::console})));
  remove_panel(l, Panel::console);
  ASSERT_EQ(regions(l).size(), 1u);
  EXPECT_EQ(region_of(l, Panel::console), -1);
  remove_panel(l, Panel::live_view);
  ASSERT_EQ(regions(l).size(), 1u) << "the root region stays";
  EXPECT_TRUE(at(l, regions(l)[0]).tabs.empty());
}

TEST(WorkspaceTree, APanelOpenedGoesBesideTheOneItSitsWithInTheShippedLayout) {
  const Workspace inspect = shipped_workspaces()[0];
  ASSERT_EQ(inspect.name, "Inspect");
  Layout l = inspect.normal;
  remove_panel(l, Panel::why);
  ASSERT_EQ(region_of(l, Panel::why), -1);
  bring_to_front(l, &inspect.normal, Panel::why);
  EXPECT_EQ(region_of(l, Panel::why), region_of(l, Panel::inspector));
  const LayoutNode& r = at(l, region_of(l, Panel::why));
  EXPECT_EQ(r.tabs[static_cast<size_t>(r.active)], Panel::why);
  // Without a shipped layout to go by: the largest region that does not show the live view.
  Layout lone = make_layout(columns(0.5f, tabs({Panel::live_view}), tabs({Panel::log})));
  bring_to_front(lone, nullptr, Panel::pose);
  EXPECT_EQ(region_of(lone, Panel::pose), region_of(lone, Panel::log));
}

TEST(WorkspaceTree, WhatTheViewAsksForIsFollowedAndMirrored) {
  Workspaces ws;
  View view;
  switch_workspace(ws, ws.find("Script"), view);
  EXPECT_EQ(ws.now().name, "Script");
  EXPECT_TRUE(view.open[static_cast<size_t>(Panel::script)]);
  EXPECT_FALSE(view.open[static_cast<size_t>(Panel::pipeline)]);
  view.open[static_cast<size_t>(Panel::console)] = false;   // closed from a menu
  view.front = Panel::pipeline;                             // brought up by a panel
  follow_view(ws, view);
  EXPECT_EQ(region_of(ws.now().normal, Panel::console), -1);
  EXPECT_GE(region_of(ws.now().normal, Panel::pipeline), 0);
  EXPECT_TRUE(view.open[static_cast<size_t>(Panel::pipeline)]);
  EXPECT_EQ(view.front, Panel::count);
}

TEST(WorkspaceTree, TheFileIsReadBackAsWrittenAndABadOneIsRefusedWithItsReason) {
  Workspaces ws;
  std::string error;
  ASSERT_TRUE(ws.save_as("Mine", &error)) << error;
  move_panel(ws.now().normal, Panel::log, region_of(ws.now().normal, Panel::live_view));
  const std::string text = workspaces_to_json(ws);
  Workspaces back;
  ASSERT_TRUE(workspaces_from_json(text, &back, &error)) << error;
  EXPECT_EQ(workspaces_to_json(back), text);
  EXPECT_EQ(back.now().name, "Mine");
  EXPECT_FALSE(back.now().shipped);

  EXPECT_FALSE(ws.save_as("Inspect", &error));
  EXPECT_EQ(error, "'Inspect' is a shipped workspace; choose another name");

  Workspaces untouched;
  const std::string bad = R"({"version":1,"workspaces":[{"name":"Mine","normal":{"split":"rows","ratio":2,)"
                          R"("first":{"tabs":[]},"second":{"tabs":[]}},"presentation":{"tabs":[]}}]})";
  EXPECT_FALSE(workspaces_from_json(bad, &untouched, &error));
  EXPECT_EQ(error, "workspace 'Mine': a split's ratio is outside 0.05..0.95");
  EXPECT_EQ(untouched.find("Mine"), -1);
  EXPECT_FALSE(workspaces_from_json(R"({"version":1,"workspaces":[{"name":"X","normal":{"tabs":["nope"]},)"
                                    R"("presentation":{"tabs":[]}}]})",
                                    &untouched, &error));
  EXPECT_EQ(error, "workspace 'X': no panel \"nope\"");
}

}  // namespace
}  // namespace arwb::ui
