// Candidates: the ledger of every candidate in the frame's trace and its fate, one row each. Sortable by any
// column, filterable by text and by fate stage (the tiny regions dropped at size_filter are hidden by default:
// they are most of the list and rarely the question). Hovering a row highlights the candidate in the live view;
// clicking it selects it for the inspector.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace arwb::ui {

namespace {

enum Column { col_index, col_bbox, col_perimeter, col_fate, col_id, col_param, col_value, col_message, col_count };

constexpr int kFateCount = kStageCount + 1;  // every stage, then accepted

struct LedgerState : PanelState {
  ImGuiTextFilter filter;
  std::array<bool, kFateCount> show{};  // per fate stage
  // Cached for one frame: each row's text (for the filter), the sort order and the rows that pass the filters.
  uint64_t frame = UINT64_MAX;
  size_t candidates = 0;
  std::vector<std::string> lines;
  std::vector<int> sorted;
  std::vector<int> rows;
  std::vector<ImGuiTableColumnSortSpecs> specs;  // the sort applied to `sorted`
  bool resort = true;
  bool refilter = true;
  std::array<int, kFateCount> counts{};
  int hidden_by_fate = 0;
  int hidden_by_text = 0;
  int last_selected = -1;  // to scroll to a selection made elsewhere (the live view)
  LedgerState() {
    show.fill(true);
    show[static_cast<size_t>(Stage::size_filter)] = false;
  }
};

int accepted_id(const FrameTrace& t, const CandidateRecord& c) {
  if (c.fate.stage != Stage::accepted || c.marker < 0 || c.marker >= static_cast<int>(t.markers.size())) return -1;
  return t.markers[static_cast<size_t>(c.marker)].id;
}

std::string id_text(const FrameTrace& t, const CandidateRecord& c) {
  const int id = accepted_id(t, c);
  if (id >= 0) return std::to_string(id);
  const DictMatch m = c.nearest();
  if (m.id < 0) return {};
  char buf[48];
  std::snprintf(buf, sizeof buf, "~%d (%d bit%s)", m.id, m.hamming, m.hamming == 1 ? "" : "s");
  return buf;
}

std::string value_text(const Rejection& f) {
  if (f.param.empty()) return {};
  const char* op = f.value < f.limit ? " < " : (f.value > f.limit ? " > " : " = ");
  return short_number(f.value) + op + short_number(f.limit);
}

std::string row_line(const FrameTrace& t, int i) {
  const CandidateRecord& c = t.candidates[static_cast<size_t>(i)];
  char head[96];
  std::snprintf(head, sizeof head, "#%d %dx%d at %d,%d perimeter %.0f ", i, c.bbox.width, c.bbox.height, c.bbox.x,
                c.bbox.y, c.perimeter);
  std::string s = head;
  s += stage_name(c.fate.stage);
  s += ' ';
  const int id = accepted_id(t, c);
  if (id >= 0) s += "id " + std::to_string(id) + ' ';
  else if (c.nearest().id >= 0) s += "nearest " + id_text(t, c) + ' ';
  if (!c.dict.empty()) s += c.dict + ' ';
  s += std::string(c.fate.param) + ' ' + value_text(c.fate) + ' ' + c.fate.message;
  return s;
}

// Negative, zero or positive as candidate a sorts before, with or after b in `column` (ascending).
int compare(const FrameTrace& t, int a, int b, int column) {
  const CandidateRecord& x = t.candidates[static_cast<size_t>(a)];
  const CandidateRecord& y = t.candidates[static_cast<size_t>(b)];
  auto cmp = [](auto u, auto v) { return u < v ? -1 : (v < u ? 1 : 0); };
  switch (column) {
    case col_bbox: {
      const int r = cmp(x.bbox.area(), y.bbox.area());
      return r ? r : cmp(x.bbox.width, y.bbox.width);
    }
    case col_perimeter: return cmp(x.perimeter, y.perimeter);
    case col_fate: return cmp(static_cast<int>(x.fate.stage), static_cast<int>(y.fate.stage));
    case col_id: {
      // Markers first by id, then rejected candidates by their nearest id and distance, then the rest.
      auto key = [&](const CandidateRecord& c) {
        const int id = accepted_id(t, c);
        if (id >= 0) return std::array<int, 3>{0, id, 0};
        const DictMatch m = c.nearest();
        if (m.id >= 0) return std::array<int, 3>{1, m.id, m.hamming};
        return std::array<int, 3>{2, 0, 0};
      };
      return cmp(key(x), key(y));
    }
    case col_param: return cmp(x.fate.param, y.fate.param);
    case col_value: {
      const int r = cmp(x.fate.param, y.fate.param);
      return r ? r : cmp(x.fate.value, y.fate.value);
    }
    case col_message: return cmp(x.fate.message, y.fate.message);
    default: return 0;
  }
}

bool same_specs(const ImGuiTableSortSpecs* s, const std::vector<ImGuiTableColumnSortSpecs>& v) {
  if (!s || s->SpecsCount != static_cast<int>(v.size())) return false;
  for (int i = 0; i < s->SpecsCount; ++i) {
    const ImGuiTableColumnSortSpecs& a = s->Specs[i];
    const ImGuiTableColumnSortSpecs& b = v[static_cast<size_t>(i)];
    if (a.ColumnIndex != b.ColumnIndex || a.SortDirection != b.SortDirection) return false;
  }
  return true;
}

void resort(LedgerState& st, const FrameTrace& t) {
  const int n = static_cast<int>(t.candidates.size());
  st.sorted.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) st.sorted[static_cast<size_t>(i)] = i;
  const std::vector<ImGuiTableColumnSortSpecs> specs = st.specs;
  std::stable_sort(st.sorted.begin(), st.sorted.end(), [&](int a, int b) {
    for (const ImGuiTableColumnSortSpecs& s : specs) {
      int r = compare(t, a, b, static_cast<int>(s.ColumnUserID));
      if (s.SortDirection == ImGuiSortDirection_Descending) r = -r;
      if (r) return r < 0;
    }
    return a < b;
  });
}

void refilter(LedgerState& st, const FrameTrace& t) {
  st.rows.clear();
  st.hidden_by_fate = st.hidden_by_text = 0;
  for (int i : st.sorted) {
    const CandidateRecord& c = t.candidates[static_cast<size_t>(i)];
    if (!st.show[static_cast<size_t>(c.fate.stage)]) {
      ++st.hidden_by_fate;
      continue;
    }
    if (!st.filter.PassFilter(st.lines[static_cast<size_t>(i)].c_str())) {
      ++st.hidden_by_text;
      continue;
    }
    st.rows.push_back(i);
  }
}

// Sorts and filters again when the frame, the sort or a filter changed.
void update(LedgerState& st, const FrameTrace& t) {
  if (st.resort) {
    resort(st, t);
    st.resort = false;
    st.refilter = true;
  }
  if (st.refilter) {
    refilter(st, t);
    st.refilter = false;
  }
}

// Totals and one chip per fate seen; clicking a chip shows or hides that fate's rows.
void header(LedgerState& st, const FrameTrace& t) {
  const int total = static_cast<int>(t.candidates.size());
  const int hidden = st.hidden_by_fate + st.hidden_by_text;
  ImGui::Text("%d candidates, %d accepted", total, st.counts[static_cast<size_t>(Stage::accepted)]);
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("Every region the pipeline looked at (full trace) and the stage that dropped it.\n"
                      "Click a chip to show or hide that stage's rows.");
  }
  const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
  char shown[128];
  if (hidden > 0) {
    const char* why = st.hidden_by_text == 0 ? " by fate" : (st.hidden_by_fate == 0 ? " by text" : "");
    std::snprintf(shown, sizeof shown, "%zu shown, %d hidden%s", st.rows.size(), hidden, why);
    if (!*why) {
      const size_t len = std::strlen(shown);
      std::snprintf(shown + len, sizeof shown - len, " (%d by fate, %d by text)", st.hidden_by_fate, st.hidden_by_text);
    }
  } else {
    std::snprintf(shown, sizeof shown, "showing all");
  }
  ImGui::SameLine();
  if (ImGui::GetCursorScreenPos().x + ImGui::CalcTextSize(shown).x > right) ImGui::NewLine();
  ImGui::TextDisabled("%s", shown);
  bool first = true;
  auto place = [&](const char* label) {
    if (first) {
      first = false;
      return;
    }
    const float w = ImGui::CalcTextSize(label, nullptr, true).x + ImGui::GetStyle().FramePadding.x * 2;
    ImGui::SameLine();
    if (ImGui::GetCursorScreenPos().x + w > right) ImGui::NewLine();
  };
  // Accepted first, then the stages in pipeline order.
  std::array<int, kFateCount> order{};
  order[0] = static_cast<int>(Stage::accepted);
  for (int i = 0; i < kStageCount; ++i) order[static_cast<size_t>(i + 1)] = i;
  for (int f : order) {
    const int n = st.counts[static_cast<size_t>(f)];
    if (n == 0) continue;
    const Stage s = static_cast<Stage>(f);
    char label[96];
    std::snprintf(label, sizeof label, "%s %d##chip%d", std::string(stage_name(s)).c_str(), n, f);
    place(label);
    bool& on = st.show[static_cast<size_t>(f)];
    if (chip(label, fate_colour(s), on)) {
      on = !on;
      st.refilter = true;
    }
    if (ImGui::IsItemHovered()) {
      ImGui::SetTooltip("%d candidate%s %s. Click to %s them.", n, n == 1 ? "" : "s",
                        s == Stage::accepted ? "became markers" : ("stopped at " + std::string(stage_name(s))).c_str(),
                        on ? "hide" : "show");
    }
  }
}

void controls(Context& ctx, LedgerState& st) {
  const float s = ctx.scale;
  ImGui::SetNextItemWidth(std::min(200.0f * s, ImGui::GetContentRegionAvail().x * 0.4f));
  if (ImGui::InputTextWithHint("##filter", "filter rows (a,b -c)", st.filter.InputBuf,
                               IM_ARRAYSIZE(st.filter.InputBuf))) {
    st.filter.Build();
    st.refilter = true;
  }
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("Filters on each row's text: \"otsu\", \"id 37\", \"min_perimeter\"...\n"
                      "Comma-separated terms match any; a leading '-' excludes.");
  }
  ImGui::SameLine();
  bool hide_small = !st.show[static_cast<size_t>(Stage::size_filter)];
  if (ImGui::Checkbox("Hide size_filter", &hide_small)) {
    st.show[static_cast<size_t>(Stage::size_filter)] = !hide_small;
    st.refilter = true;
  }
  if (ImGui::IsItemHovered()) {
    ImGui::SetTooltip("Regions too short or too long to be a marker's border: usually most of the list.");
  }
  ImGui::SameLine();
  if (ImGui::Button("Fates...")) ImGui::OpenPopup("fates");
  if (ImGui::BeginPopup("fates")) {
    if (ImGui::SmallButton("All")) {
      st.show.fill(true);
      st.refilter = true;
    }
    ImGui::SameLine();
    if (ImGui::SmallButton("None")) {
      st.show.fill(false);
      st.refilter = true;
    }
    ImGui::SameLine();
    if (ImGui::SmallButton("Quads only")) {
      // What reached a quad: hide the contour-level fates.
      st.show.fill(true);
      st.show[static_cast<size_t>(Stage::size_filter)] = st.show[static_cast<size_t>(Stage::quad_fit)] = false;
      st.refilter = true;
    }
    for (int f = 0; f < kFateCount; ++f) {
      const Stage stage = static_cast<Stage>(f);
      char label[96];
      std::snprintf(label, sizeof label, "%s (%d)", std::string(stage_name(stage)).c_str(),
                    st.counts[static_cast<size_t>(f)]);
      ImGui::PushStyleColor(ImGuiCol_Text, fate_colour(stage));
      if (ImGui::Checkbox(label, &st.show[static_cast<size_t>(f)])) st.refilter = true;
      ImGui::PopStyleColor();
    }
    ImGui::EndPopup();
  }
}

// The widest name in the parameter table: scrolling may bring a row with any of them into view, and a column
// fitted to the rows shown would be a frame too narrow for it (the clipping audit saw 28 px cut).
float widest_param_name() {
  float w = 0;
  for (const ParamInfo& info : param_table()) w = std::max(w, ImGui::CalcTextSize(info.name).x);
  return w;
}

// The widest stage name, for the fate column, for the same reason: a frame whose rows bring a longer fate into
// view (fine_search after quad_fit) would otherwise cut it for a frame.
float widest_stage_name() {
  float w = 0;
  for (int i = 0; i <= kStageCount; ++i) {
    const std::string_view name = stage_name(Stage(i));
    w = std::max(w, ImGui::CalcTextSize(name.data(), name.data() + name.size()).x);
  }
  return w;
}

void table(Context& ctx, LedgerState& st, const FrameTrace& t) {
  const ImGuiTableFlags flags = ImGuiTableFlags_Sortable | ImGuiTableFlags_SortMulti | ImGuiTableFlags_Resizable |
                                ImGuiTableFlags_Reorderable | ImGuiTableFlags_Hideable | ImGuiTableFlags_RowBg |
                                ImGuiTableFlags_BordersV | ImGuiTableFlags_BordersOuterH | ImGuiTableFlags_ScrollY |
                                ImGuiTableFlags_ScrollX | ImGuiTableFlags_SizingFixedFit;
  // The rest of the panel, but never less than a few rows: in a short region (presentation mode's large text)
  // the panel scrolls to the table rather than showing its header alone.
  const float rows = (ImGui::GetTextLineHeight() + ImGui::GetStyle().CellPadding.y * 2) * 5 + ImGui::GetStyle().ScrollbarSize;
  const ImVec2 outer{0, std::max(ImGui::GetContentRegionAvail().y, rows)};
  if (!ImGui::BeginTable("ledger", col_count, flags, outer)) return;
  ImGui::TableSetupScrollFreeze(1, 1);
  ImGui::TableSetupColumn("#", ImGuiTableColumnFlags_DefaultSort | ImGuiTableColumnFlags_NoHide, 0, col_index);
  // As wide as the widest box this frame can have, for the same reason as the parameter's column.
  char widest_box[64];
  std::snprintf(widest_box, sizeof widest_box, "%dx%d at %d,%d", t.work_width, t.work_height, t.work_width,
                t.work_height);
  ImGui::TableSetupColumn("bbox", ImGuiTableColumnFlags_PreferSortDescending | ImGuiTableColumnFlags_WidthFixed,
                          ImGui::CalcTextSize(widest_box).x, col_bbox);
  ImGui::TableSetupColumn("perimeter", ImGuiTableColumnFlags_PreferSortDescending, 0, col_perimeter);
  ImGui::TableSetupColumn("fate", ImGuiTableColumnFlags_WidthFixed, widest_stage_name(), col_fate);
  ImGui::TableSetupColumn("ID", 0, 0, col_id);
  ImGui::TableSetupColumn("parameter", ImGuiTableColumnFlags_WidthFixed, widest_param_name(), col_param);
  ImGui::TableSetupColumn("value vs limit", 0, 0, col_value);
  ImGui::TableSetupColumn("message", 0, 0, col_message);
  ImGui::TableHeadersRow();

  if (ImGuiTableSortSpecs* specs = ImGui::TableGetSortSpecs(); specs && (specs->SpecsDirty || !same_specs(specs, st.specs))) {
    st.specs.assign(specs->Specs, specs->Specs + specs->SpecsCount);
    specs->SpecsDirty = false;
    st.resort = true;
  }
  update(st, t);

  // A selection made elsewhere (the live view): bring its row into view.
  int scroll_to = -1;
  if (ctx.view.selected_candidate != st.last_selected) {
    st.last_selected = ctx.view.selected_candidate;
    const auto it = std::find(st.rows.begin(), st.rows.end(), ctx.view.selected_candidate);
    if (it != st.rows.end()) scroll_to = static_cast<int>(it - st.rows.begin());
  }

  ImGuiListClipper clipper;
  clipper.Begin(static_cast<int>(st.rows.size()));
  if (scroll_to >= 0) clipper.ForceDisplayRangeByIndices(scroll_to, scroll_to + 1);
  while (clipper.Step()) {
    for (int r = clipper.DisplayStart; r < clipper.DisplayEnd; ++r) {
      const int i = st.rows[static_cast<size_t>(r)];
      const CandidateRecord& c = t.candidates[static_cast<size_t>(i)];
      const ImU32 colour = fate_colour(c.fate.stage);
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(col_index);
      char label[32];
      std::snprintf(label, sizeof label, "%d", i);
      const bool selected = ctx.view.selected_candidate == i;
      if (ImGui::Selectable(label, selected, ImGuiSelectableFlags_SpanAllColumns | ImGuiSelectableFlags_AllowItemOverlap)) {
        ctx.view.selected_candidate = i;
        st.last_selected = i;
        ctx.view.show(Panel::inspector);
      }
      if (ImGui::IsItemHovered()) {
        ctx.view.hovered_candidate = i;
        ImGui::SetTooltip("%s\n(click to inspect)", candidate_line(t, i).c_str());
      }
      if (r == scroll_to) ImGui::SetScrollHereY(0.5f);
      if (ImGui::TableSetColumnIndex(col_bbox)) {
        ImGui::Text("%dx%d at %d,%d", c.bbox.width, c.bbox.height, c.bbox.x, c.bbox.y);
      }
      if (ImGui::TableSetColumnIndex(col_perimeter)) ImGui::Text("%.0f", c.perimeter);
      if (ImGui::TableSetColumnIndex(col_fate)) {
        ImGui::PushStyleColor(ImGuiCol_Text, colour);
        const std::string name(stage_name(c.fate.stage));
        ImGui::TextUnformatted(name.c_str());
        ImGui::PopStyleColor();
      }
      if (ImGui::TableSetColumnIndex(col_id)) {
        const std::string id = id_text(t, c);
        if (c.fate.stage == Stage::accepted) ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(accepted_colour()), "%s", id.c_str());
        else ImGui::TextDisabled("%s", id.c_str());
      }
      if (ImGui::TableSetColumnIndex(col_param)) {
        const std::string p(c.fate.param);
        ImGui::TextUnformatted(p.c_str());
      }
      if (ImGui::TableSetColumnIndex(col_value)) ImGui::TextUnformatted(value_text(c.fate).c_str());
      if (ImGui::TableSetColumnIndex(col_message)) ImGui::TextUnformatted(c.fate.message.c_str());
    }
  }
  ImGui::EndTable();
}

}  // namespace

void draw_candidates(Context& ctx) {
  LedgerState& st = panel_state<LedgerState>(ctx.view, Panel::candidates);
  ctx.view.hovered_candidate = -1;  // set again below while a row is under the mouse
  if (waiting_for_frame(ctx)) return;
  const Frame& f = *ctx.frame;
  const FrameTrace& t = f.trace;
  if (f.index != st.frame || t.candidates.size() != st.candidates) {
    st.frame = f.index;
    st.candidates = t.candidates.size();
    st.lines.resize(t.candidates.size());
    st.counts.fill(0);
    for (size_t i = 0; i < t.candidates.size(); ++i) {
      st.lines[i] = row_line(t, static_cast<int>(i));
      ++st.counts[static_cast<size_t>(t.candidates[i].fate.stage)];
    }
    st.resort = true;
  }
  if (t.level == TraceLevel::off) {
    ImGui::TextWrapped("The trace is off: only the markers are recorded, not the candidates. Raise the trace level "
                       "to summary (quads and their fates) or full (every contour).");
    return;
  }
  if (t.candidates.empty()) {
    if (t.level == TraceLevel::full) {
      ImGui::TextWrapped("No candidates: nothing dark enough was found, see adaptive_threshold (the binary image in "
                         "the pipeline panel) and its threshold_window_px and threshold_offset.");
    } else {
      ImGui::TextWrapped("No candidates: no contour passed size_filter. The summary trace lists quads and later "
                         "only; switch to the full trace to see every contour, and see adaptive_threshold.");
    }
    return;
  }
  update(st, t);  // before the header, which shows the counts (a sort clicked now applies in table())
  header(st, t);
  controls(ctx, st);
  if (t.level != TraceLevel::full) {
    ImGui::TextDisabled("Summary trace: contours dropped at size_filter are not listed.");
  }
  if (st.rows.empty() && !st.refilter && !st.resort) {
    ImGui::TextDisabled("All %zu candidates are hidden by the filters.", t.candidates.size());
    ImGui::SameLine();
    if (ImGui::SmallButton("Show all")) {
      st.show.fill(true);
      st.filter.Clear();
      st.refilter = true;
    }
  }
  table(ctx, st, t);
}

}  // namespace arwb::ui
