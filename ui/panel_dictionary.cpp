// Dictionary explorer: the markers of a dictionary and how far apart they are. The header gives the marker size,
// the id count, the correction budget and the minimum Hamming distance (over ids and rotations), which bounds
// the budget: (min_distance - 1) / 2 bits can be corrected without ever naming the wrong marker. The tabs show
// every marker (a clipped grid, so 1000 ids stay fast; hover one for its bits), the closest pairs side by side
// with the differing cells marked, and the histogram of all pairwise distances. The distances are computed once
// per dictionary, by the window in the background (a request), the first time that dictionary is shown.
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace arwb::ui {

namespace {

// A dictionary shown: its table, and its distances once the window computed them (ComputeDictionaryStats,
// on a thread of its own: 500 000 pairs for 1000 ids).
struct DictEntry {
  const Dictionary& dict;
  const DictionaryStats* stats = nullptr;
};

struct DictionaryState : PanelState {
  std::string name;                            // the one shown; "" until the first draw
  std::map<std::string, Dictionary> dicts;     // every dictionary shown so far
  float thumb = 44.0f;                         // grid thumbnail side (before ctx.scale)
  int selected_id = -1;                        // clicked in the grid: highlighted, first id of the sheet
  int first_id = 0;                            // marker sheet: ids first_id .. first_id + 11
  std::string error;
};

constexpr int kPxPerCell = 8;  // rendered texture resolution; thumbnails are scaled on screen

const Dictionary* dictionary_for(DictionaryState& st, const std::string& name) {
  auto it = st.dicts.find(name);
  if (it == st.dicts.end()) {
    std::string err;
    auto d = dictionary_by_name(name, &err);
    if (!d) {
      st.error = err;
      return nullptr;
    }
    it = st.dicts.emplace(name, std::move(*d)).first;
  }
  return &it->second;
}

// Its distances once computed; until then they are asked for (asking again while they compute does nothing).
const DictionaryStats* stats_for(Context& ctx, const std::string& name) {
  const auto it = ctx.status.dictionary_stats.find(name);
  if (it != ctx.status.dictionary_stats.end()) return &it->second;
  ctx.request(ComputeDictionaryStats{name});
  return nullptr;
}

std::string marker_key(const Dictionary& d, int id, int rotation = 0) {
  return "dict:" + d.name() + ":" + std::to_string(id) + ":" + std::to_string(rotation);
}

cv::Mat render_turned(const Dictionary& d, int id, int rotation) {
  cv::Mat img = d.render(id, kPxPerCell);
  for (int k = 0; k < (rotation & 3); ++k) cv::rotate(img, img, cv::ROTATE_90_CLOCKWISE);
  return img;
}

// A marker as an image; the version is constant since a marker never changes.
void marker_image(Context& ctx, const Dictionary& d, int id, int rotation, float side) {
  ImGui::Image(ctx.texture(marker_key(d, id, rotation), render_turned(d, id, rotation), 1), {side, side});
}

// The marker drawn cell by cell with its inner bits written in, `cell` screen pixels a cell.
void marker_bits(const Dictionary& d, int id, float cell) {
  const int n = d.marker_size();
  const float side = cell * static_cast<float>(n + 2);
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::Dummy({side, side});
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRectFilled(p0, {p0.x + side, p0.y + side}, IM_COL32(0, 0, 0, 255));
  const cv::Mat bits = d.bits(id);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n; ++c) {
      const bool white = bits.at<uint8_t>(r, c) != 0;
      const ImVec2 a{p0.x + cell * static_cast<float>(c + 1), p0.y + cell * static_cast<float>(r + 1)};
      const ImVec2 b{a.x + cell, a.y + cell};
      if (white) dl->AddRectFilled(a, b, IM_COL32(255, 255, 255, 255));
      dl->AddRect(a, b, IM_COL32(128, 128, 128, 255));
      const char* t = white ? "1" : "0";
      const ImVec2 ts = ImGui::CalcTextSize(t);
      dl->AddText({a.x + (cell - ts.x) * 0.5f, a.y + (cell - ts.y) * 0.5f},
                  white ? IM_COL32(60, 60, 60, 255) : IM_COL32(200, 200, 200, 255), t);
    }
  }
}

void marker_tooltip(Context& ctx, const Dictionary& d, int id) {
  ImGui::BeginTooltip();
  ImGui::Text("%s id %d", d.name().c_str(), id);
  char hex[32];
  std::snprintf(hex, sizeof hex, "0x%llx", static_cast<unsigned long long>(d.code(id)));
  ImGui::TextDisabled("code %s (row-major, top-left bit first; 1 = white)", hex);
  marker_bits(d, id, std::max(18.0f, 160.0f / static_cast<float>(d.marker_size() + 2)) * ctx.scale);
  ImGui::TextDisabled("Click: first id of the marker sheet");
  ImGui::EndTooltip();
}

void header(Context& ctx, DictionaryState& st, DictEntry& e) {
  const Dictionary& d = e.dict;
  ImGui::TextWrapped("%dx%d bits, %d ids, corrects up to %d bits", d.marker_size(), d.marker_size(), d.size(),
                     d.max_correction_bits());
  flow(text_width("minimum distance: computing..."));   // the longer of the two texts below
  if (e.stats) {
    const int md = e.stats->min_distance;
    ImGui::Text("minimum distance %d", md);
    if (md == 0 && ImGui::IsItemHovered()) {
      ImGui::SetTooltip("Some marker equals another marker turned, or itself turned (see Closest pairs): those\n"
                        "cannot be told apart in every orientation, and no bit can be corrected safely.\n"
                        "Computed in %.1f ms.", e.stats->ms);
    } else if (ImGui::IsItemHovered()) {
      ImGui::SetTooltip("The fewest bits in which two markers (in any rotation), or a marker and itself turned,\n"
                        "differ. Up to (%d - 1) / 2 = %d flipped bits can be corrected without ever reading the\n"
                        "wrong id; the dictionary's own budget is %d. Computed in %.1f ms.",
                        md, (md - 1) / 2, d.max_correction_bits(), e.stats->ms);
    }
    if (d.max_correction_bits() > (md - 1) / 2) {
      flow(text_width("(budget above the safe 00)"));
      ImGui::TextColored({1.0f, 0.7f, 0.2f, 1.0f}, "(budget above the safe %d)", (md - 1) / 2);
    }
  } else {
    ImGui::TextDisabled("minimum distance: computing...");
  }
  // Marker sheets are printed from the first detection dictionary.
  const std::vector<std::string>& det = ctx.settings.dictionaries;
  const bool is_first = !det.empty() && det[0] == d.name();
  if (is_first) {
    fit_item_width(110.0f * ctx.scale, "first id");
    if (ImGui::InputInt("first id", &st.first_id)) st.first_id = std::clamp(st.first_id, 0, std::max(0, d.size() - 1));
    flow(button_width("Print marker sheet..."));
    if (ImGui::Button("Print marker sheet...")) {   // the window's dialog: ids, size, where to save
      ctx.request(OpenSheetDialog{d.name(), st.first_id});
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("A4 PDF of markers %d..%d at a true size.", st.first_id, std::min(d.size() - 1, st.first_id + 11));
  } else {
    const bool listed = std::find(det.begin(), det.end(), d.name()) != det.end();
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("Detection %s this dictionary%s; marker sheets print the first one (%s).",
                       listed ? "reads" : "does not read", listed ? " (not first)" : "",
                       det.empty() ? "none" : det[0].c_str());
    ImGui::PopStyleColor();
    if (ImGui::Button("Use this dictionary for detection")) ctx.settings.dictionaries = {d.name()};
  }
}

void grid_tab(Context& ctx, DictionaryState& st, const Dictionary& d) {
  fit_item_width(160.0f * ctx.scale, "thumbnail size");
  ImGui::SliderFloat("thumbnail size", &st.thumb, 20.0f, 128.0f, "%.0f px");
  const float t = st.thumb * ctx.scale;
  ImGui::BeginChild("grid", {0, 0}, false);
  const ImGuiStyle& style = ImGui::GetStyle();
  const float cell_w = std::max(t, ImGui::CalcTextSize("0000").x) + style.ItemSpacing.x;
  const float avail = ImGui::GetContentRegionAvail().x;
  const int cols = std::max(1, static_cast<int>((avail + style.ItemSpacing.x) / cell_w));
  const int rows = (d.size() + cols - 1) / cols;
  const float row_h = t + ImGui::GetTextLineHeight() + style.ItemSpacing.y * 2;
  ImGuiListClipper clipper;
  clipper.Begin(rows, row_h);
  while (clipper.Step()) {
    for (int r = clipper.DisplayStart; r < clipper.DisplayEnd; ++r) {
      const float y = ImGui::GetCursorPosY();
      for (int c = 0; c < cols; ++c) {
        const int id = r * cols + c;
        if (id >= d.size()) break;
        const float x = static_cast<float>(c) * cell_w;
        ImGui::SetCursorPos({x, y});
        ImGui::BeginGroup();
        const ImVec2 p0 = ImGui::GetCursorScreenPos();
        ImGui::PushID(id);
        ImGui::Image(ctx.texture(marker_key(d, id), d.render(id, kPxPerCell), 1), {t, t});
        const bool hovered = ImGui::IsItemHovered();
        if (ImGui::IsItemClicked()) {
          st.selected_id = id;
          st.first_id = id;
        }
        ImGui::PopID();
        if (id == st.selected_id || hovered) {
          ImGui::GetWindowDrawList()->AddRect({p0.x - 2, p0.y - 2}, {p0.x + t + 2, p0.y + t + 2},
                                              hovered ? IM_COL32(255, 255, 0, 255) : accepted_colour(), 0, 0,
                                              2.0f * ctx.scale);
        }
        char label[16];
        std::snprintf(label, sizeof label, "%d", id);
        const float lw = ImGui::CalcTextSize(label).x;
        ImGui::SetCursorPosX(x + (t - lw) * 0.5f);
        ImGui::TextDisabled("%s", label);
        ImGui::EndGroup();
        if (hovered) marker_tooltip(ctx, d, id);
      }
      ImGui::SetCursorPos({0, y + row_h});
    }
  }
  clipper.End();
  ImGui::EndChild();
}

void pairs_tab(Context& ctx, const DictEntry& e) {
  const Dictionary& d = e.dict;
  if (!e.stats) {
    ImGui::TextDisabled("Computing the distances of every pair...");
    return;
  }
  ImGui::TextWrapped("The %zu entries with the fewest differing bits: two markers (b turned to its closest "
                     "rotation), or one marker against itself turned (a = b). Red: the cells that differ. A camera "
                     "that misreads that many cells sees the other marker.",
                     e.stats->pairs.size());
  const float side = 52.0f * ctx.scale;
  const ImGuiTableFlags tf = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerH | ImGuiTableFlags_ScrollY |
                             ImGuiTableFlags_SizingFixedFit;
  if (!ImGui::BeginTable("pairs", 5, tf)) return;
  ImGui::TableSetupScrollFreeze(0, 1);
  ImGui::TableSetupColumn("distance");
  ImGui::TableSetupColumn("a");
  ImGui::TableSetupColumn("b");
  ImGui::TableSetupColumn("b turned");
  ImGui::TableSetupColumn("markers", ImGuiTableColumnFlags_WidthStretch);
  ImGui::TableHeadersRow();
  const int n = d.marker_size();
  ImGuiListClipper clipper;
  clipper.Begin(static_cast<int>(e.stats->pairs.size()), side + ImGui::GetStyle().CellPadding.y * 2);
  while (clipper.Step()) {
    for (int i = clipper.DisplayStart; i < clipper.DisplayEnd; ++i) {
      const DictPair& p = e.stats->pairs[static_cast<size_t>(i)];
      ImGui::TableNextRow(0, side);
      ImGui::TableNextColumn();
      ImGui::Text("%d", p.distance);
      ImGui::TableNextColumn();
      ImGui::Text("%d", p.a);
      ImGui::TableNextColumn();
      ImGui::Text("%d", p.b);
      ImGui::TableNextColumn();
      ImGui::Text("%d x 90 deg", p.rotation);
      ImGui::TableNextColumn();
      marker_image(ctx, d, p.a, 0, side);
      if (ImGui::IsItemHovered()) marker_tooltip(ctx, d, p.a);
      ImGui::SameLine();
      const ImVec2 b0 = ImGui::GetCursorScreenPos();
      marker_image(ctx, d, p.b, p.rotation, side);
      const bool hov_b = ImGui::IsItemHovered();
      // Mark the inner cells where a and turned b differ.
      const cv::Mat ba = Dictionary::unpack(d.code(p.a, 0), n);
      const cv::Mat bb = Dictionary::unpack(d.code(p.b, p.rotation), n);
      const float cell = side / static_cast<float>(n + 2);
      ImDrawList* dl = ImGui::GetWindowDrawList();
      for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
          if (ba.at<uint8_t>(r, c) != bb.at<uint8_t>(r, c)) {
            const ImVec2 a{b0.x + cell * static_cast<float>(c + 1), b0.y + cell * static_cast<float>(r + 1)};
            dl->AddRect({a.x + 1, a.y + 1}, {a.x + cell - 1, a.y + cell - 1}, IM_COL32(255, 60, 60, 255), 0, 0,
                        std::max(1.5f, cell * 0.15f));
          }
      if (hov_b) {
        ImGui::SetTooltip("id %d turned %d quarter-turn(s) clockwise: %d cell(s) differ from id %d", p.b, p.rotation,
                          p.distance, p.a);
      }
    }
  }
  ImGui::EndTable();
}

void histogram_tab(Context& ctx, const DictEntry& e) {
  if (!e.stats) {
    ImGui::TextDisabled("Computing the distances of every pair...");
    return;
  }
  const std::vector<int>& h = e.stats->histogram;
  size_t last = 0;
  long long total = 0;
  for (size_t k = 0; k < h.size(); ++k) {
    if (h[k] > 0) last = k;
    total += h[k];
  }
  std::vector<float> v(last + 1);
  float mx = 0;
  for (size_t k = 0; k <= last; ++k) {
    v[k] = static_cast<float>(h[k]);
    mx = std::max(mx, v[k]);
  }
  ImGui::TextWrapped("How many of the %lld entries (pairs of markers in their closest rotation, and markers against "
                     "their own rotations) differ in k bits, k = 0 .. %zu. The leftmost bar is the minimum distance.",
                     total, last);
  ImGui::PlotHistogram("##hist", v.data(), static_cast<int>(v.size()), 0, nullptr, 0.0f, mx * 1.05f,
                       {ImGui::GetContentRegionAvail().x, 140.0f * ctx.scale});
  ImGui::TextDisabled("0 bits");
  ImGui::SameLine(std::max(0.0f, ImGui::GetContentRegionAvail().x - ImGui::CalcTextSize("00 bits").x));
  ImGui::TextDisabled("%zu bits", last);
  // The smallest distances in numbers: they decide how much correction is safe.
  int shown = 0;
  for (size_t k = 0; k < h.size() && shown < 4; ++k) {
    if (h[k] == 0) continue;
    ImGui::Text("%2zu bits: %d", k, h[k]);
    ++shown;
  }
}

}  // namespace

void draw_dictionary(Context& ctx) {
  DictionaryState& st = panel_state<DictionaryState>(ctx.view, Panel::dictionary);
  if (st.name.empty()) st.name = ctx.settings.dictionaries.empty() ? "ARUCO_ORIGINAL" : ctx.settings.dictionaries[0];
  fit_item_width(220.0f * ctx.scale, "dictionary");
  if (ImGui::BeginCombo("dictionary", st.name.c_str(), ImGuiComboFlags_HeightLarge)) {
    for (const std::string& n : dictionary_names()) {
      const bool sel = n == st.name;
      if (ImGui::Selectable(n.c_str(), sel) && !sel) {
        st.name = n;
        st.selected_id = -1;
        st.first_id = 0;
        st.error.clear();
      }
      if (sel) ImGui::SetItemDefaultFocus();
    }
    ImGui::EndCombo();
  }
  const Dictionary* dict = dictionary_for(st, st.name);
  if (!dict) {
    ImGui::TextColored({1.0f, 0.3f, 0.3f, 1.0f}, "%s", st.error.c_str());
    return;
  }
  DictEntry entry{*dict, stats_for(ctx, st.name)};
  DictEntry* e = &entry;
  header(ctx, st, *e);
  if (ImGui::BeginTabBar("dict_tabs")) {
    if (ImGui::BeginTabItem("Markers")) {
      grid_tab(ctx, st, e->dict);
      ImGui::EndTabItem();
    }
    if (ImGui::BeginTabItem("Closest pairs")) {
      pairs_tab(ctx, *e);
      ImGui::EndTabItem();
    }
    if (ImGui::BeginTabItem("Distances")) {
      histogram_tab(ctx, *e);
      ImGui::EndTabItem();
    }
    ImGui::EndTabBar();
  }
}

}  // namespace arwb::ui
