// What draw_workspace checks in what ImGui drew (ui/workspace_audit.hpp): regions overlapping, and items or
// table cells cut off, from ImGui's own rectangles, reported once they stay cut for two frames.
#include "ui/workspace_audit.hpp"

#include <imgui_internal.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string_view>

namespace arwb::ui {

namespace {
// The panel whose content window `w` is or lies in; Panel::count when none.
Panel panel_of(ImGuiWindow* w, const std::vector<std::pair<ImGuiWindow*, Panel>>& shown) {
  for (; w; w = w->ParentWindow) {
    for (const auto& s : shown)
      if (s.first == w) return s.second;
    if (!(w->Flags & ImGuiWindowFlags_ChildWindow)) break;
  }
  return Panel::count;
}

std::string window_what(const ImGuiWindow* w, const char* side, float by) {
  const char* name = std::strrchr(w->Name, '/');
  char buf[160];
  std::snprintf(buf, sizeof buf, "window %s: content %.0f px past its %s edge", name ? name + 1 : w->Name, by, side);
  return buf;
}

// The part of an entry that names what is cut ("table column 'parameter'"), without by how much.
std::string_view cut_item(std::string_view what) { return what.substr(0, what.find(':')); }

void audit_windows_and_tables(const std::vector<std::pair<ImGuiWindow*, Panel>>& shown, LayoutAudit* audit) {
  ImGuiContext& g = *ImGui::GetCurrentContext();
  std::array<bool, kPanelCount> settled{};
  std::array<std::vector<std::string>, kPanelCount> now;   // this frame's entries
  for (int i = 0; i < kPanelCount; ++i) {
    const bool drawn = std::any_of(shown.begin(), shown.end(), [i](const auto& s) { return static_cast<int>(s.second) == i; });
    int& n = audit->drawn_in_a_row[static_cast<size_t>(i)];
    n = drawn ? n + 1 : 0;
    settled[static_cast<size_t>(i)] = n >= 3;
    if (!settled[static_cast<size_t>(i)]) audit->last_frame[static_cast<size_t>(i)].clear();
  }
  for (ImGuiWindow* w : g.Windows) {
    if (!w->Active || w->Hidden) continue;
    const Panel p = panel_of(w, shown);
    if (p == Panel::count || !settled[static_cast<size_t>(p)]) continue;
    auto& out = now[static_cast<size_t>(p)];
    // Sideways: cut off unless the window scrolls sideways. Downwards: only a window without a scrollbar cuts.
    // Against the window's own inner rectangle, not its clip rectangle: a child scrolled out of its parent's view
    // is the parent's scrolling (the parent's own overflow is checked on the parent).
    const ImRect& clip = w->InnerRect;
    // A nested child may reach its padding: ImGui's InputTextMultiline sizes its own child's content a frame
    // padding past its edge (1.86) with nothing drawn there.
    const bool content = std::any_of(shown.begin(), shown.end(), [w](const auto& s) { return s.first == w; });
    const float tolerance = content ? 1.0f : std::max(w->WindowPadding.x, ImGui::GetStyle().FramePadding.x) + 0.5f;
    const float right = w->DC.CursorMaxPos.x - clip.Max.x;
    if (!(w->Flags & ImGuiWindowFlags_HorizontalScrollbar) && !w->ScrollbarX && right > tolerance) {
      out.push_back(window_what(w, "right", right));
    }
    const float below = w->DC.CursorMaxPos.y - clip.Max.y;
    if ((w->Flags & ImGuiWindowFlags_NoScrollbar) && !w->ScrollbarY && below > 1) {
      out.push_back(window_what(w, "bottom", below));
    }
  }
  for (int i = 0; i < g.Tables.GetMapSize(); ++i) {
    ImGuiTable* t = g.Tables.TryGetMapData(i);
    if (!t || t->LastFrameActive != g.FrameCount) continue;
    const Panel p = panel_of(t->OuterWindow, shown);
    if (p == Panel::count || !settled[static_cast<size_t>(p)]) continue;
    const bool scroll_x = (t->Flags & ImGuiTableFlags_ScrollX) != 0;
    // A table that scrolls downwards but has no room for a row under its header shows nothing (the Candidates
    // ledger in presentation mode once did).
    if (t->Flags & ImGuiTableFlags_ScrollY) {
      const float row = ImGui::GetTextLineHeight() + g.Style.CellPadding.y * 2;
      const float need = row * 2 + (scroll_x ? g.Style.ScrollbarSize : 0.0f);
      if (t->OuterRect.GetHeight() < need) {
        char buf[120];
        std::snprintf(buf, sizeof buf, "table: %.0f px high, no room for a row under its header", t->OuterRect.GetHeight());
        now[static_cast<size_t>(p)].push_back(buf);
      }
    }
    for (int c = 0; c < t->ColumnsCount; ++c) {
      const ImGuiTableColumn& col = t->Columns[c];
      if (!col.IsEnabled) continue;
      const float content = std::max(col.ContentMaxXFrozen, col.ContentMaxXUnfrozen);
      // A table that scrolls sideways shows a column whole when scrolled to; else what passes the table's edge is lost.
      const float edge = scroll_x ? col.MaxX : col.ClipRect.Max.x;
      const char* name = t->ColumnsNames.Buf.Size && col.NameOffset >= 0 ? t->ColumnsNames.c_str() + col.NameOffset : "";
      char buf[200];
      if (content > edge + 1) {
        std::snprintf(buf, sizeof buf, "table column '%s': content %.0f px past its edge", name, content - edge);
        now[static_cast<size_t>(p)].push_back(buf);
      } else if (col.ContentMaxXHeadersIdeal > edge + 1) {
        std::snprintf(buf, sizeof buf, "table column '%s': header %.0f px past its edge", name,
                      col.ContentMaxXHeadersIdeal - edge);
        now[static_cast<size_t>(p)].push_back(buf);
      }
    }
  }
  // Reported: what is cut in this frame and was in the one before. A table's columns fit new content a frame
  // after it appears (a longer parameter name in a new row), which no one sees; what stays cut is a fault.
  for (size_t i = 0; i < now.size(); ++i) {
    if (!settled[i]) continue;
    std::vector<std::string>& out = audit->clipped[i];
    out.clear();
    for (const std::string& w : now[i]) {
      const auto& last = audit->last_frame[i];
      if (std::any_of(last.begin(), last.end(), [&](const std::string& l) { return cut_item(l) == cut_item(w); })) {
        out.push_back(w);
      }
    }
    audit->last_frame[i] = std::move(now[i]);
  }
}
}  // namespace

void audit_layout(const Layout& l, const std::vector<int>& leaves,
                  const std::vector<std::pair<ImGuiWindow*, Panel>>& shown, LayoutAudit* audit) {
  audit->regions.clear();
  audit->overlaps = 0;
  for (int r : leaves) {
    const LayoutNode& n = at(l, r);
    const int front = std::clamp(n.active, 0, std::max(0, static_cast<int>(n.tabs.size()) - 1));
    LayoutAudit::Region reg{n.tabs, n.tabs.empty() ? Panel::count : n.tabs[static_cast<size_t>(front)], n.pos, n.size};
    for (const LayoutAudit::Region& o : audit->regions) {
      const float w = std::min(o.pos.x + o.size.x, reg.pos.x + reg.size.x) - std::max(o.pos.x, reg.pos.x);
      const float h = std::min(o.pos.y + o.size.y, reg.pos.y + reg.size.y) - std::max(o.pos.y, reg.pos.y);
      if (w > 0 && h > 0) ++audit->overlaps;
    }
    audit->regions.push_back(std::move(reg));
  }
  audit_windows_and_tables(shown, audit);
}

std::vector<std::string> windows_off_screen() {
  std::vector<std::string> out;
  const ImGuiContext& g = *ImGui::GetCurrentContext();
  const ImGuiViewport* vp = ImGui::GetMainViewport();
  const ImVec2 lo = vp->Pos, hi{vp->Pos.x + vp->Size.x, vp->Pos.y + vp->Size.y};
  for (const ImGuiWindow* w : g.Windows) {
    if (!w->Active || w->Hidden || (w->Flags & (ImGuiWindowFlags_ChildWindow | ImGuiWindowFlags_Tooltip))) continue;
    const float slack = 1.0f;   // rounding of positions
    if (w->Pos.x >= lo.x - slack && w->Pos.y >= lo.y - slack && w->Pos.x + w->Size.x <= hi.x + slack &&
        w->Pos.y + w->Size.y <= hi.y + slack)
      continue;
    char where[96];
    std::snprintf(where, sizeof where, " %.0fx%.0f at %.0f,%.0f", w->Size.x, w->Size.y, w->Pos.x, w->Pos.y);
    out.push_back(std::string(w->Name, std::strcspn(w->Name, "#")) + where);
  }
  return out;
}

}  // namespace arwb::ui
