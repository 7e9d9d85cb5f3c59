// Inspector: one candidate (View::selected_candidate) followed through the pipeline. Its fate first; then its
// contour and fitted quad over the frame (a view of its own, centred on the candidate), the frontal view with the
// cell grid, the Otsu histogram, the bit grid beside the nearest marker's bits, and the nearest id in each of the
// four rotations. Whatever the candidate did not reach is said, not left blank.
#include "detect/pipeline.hpp"
#include "ui/panels.hpp"
#include "ui/widgets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace arwb::ui {

namespace {

struct InspectorState : PanelState {
  ImageViewState crop;           // the region view's own zoom and pan
  int centred_on = -1;           // the candidate the region view was last centred on
  int rotation_for = -1;         // the candidate `rotation` was chosen for
  int rotation = -1;             // the rotation whose expected bits are shown; -1: the best one
  std::string dict_name;         // cached dictionary_by_name(dict_name)
  std::optional<Dictionary> dict;
};

const Dictionary* dictionary(InspectorState& st, const std::string& name) {
  if (name.empty()) return nullptr;
  if (name != st.dict_name) {
    st.dict_name = name;
    st.dict = dictionary_by_name(name);
  }
  return st.dict ? &*st.dict : nullptr;
}

// Grey text that wraps at the panel's edge (legends and notes; presentation mode doubles the font).
void note(const char* fmt, ...) IM_FMTARGS(1);
void note(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
  ImGui::TextWrappedV(fmt, args);
  ImGui::PopStyleColor();
  va_end(args);
}

// A foldable section, open at first; the note is drawn on the header line after the title when it fits there
// (a narrow region or presentation mode leaves it out: it is a hint, the tooltip of the views says it too).
bool section(const char* title, const char* hint = nullptr) {
  ImGui::Spacing();
  const bool open = ImGui::CollapsingHeader(title, ImGuiTreeNodeFlags_DefaultOpen | ImGuiTreeNodeFlags_AllowItemOverlap);
  if (hint) {
    const ImGuiStyle& style = ImGui::GetStyle();
    const float x = style.FramePadding.x * 2 + ImGui::GetFontSize() + style.ItemInnerSpacing.x + text_width(title) +
                    style.ItemSpacing.x * 2;
    if (x + text_width(hint) <= ImGui::GetWindowContentRegionMax().x - ImGui::GetWindowContentRegionMin().x) {
      ImGui::SameLine(x);
      ImGui::TextDisabled("%s", hint);
    }
  }
  return open;
}

// What a candidate that stopped early lacks, and why: by the stage, and where one stage stops candidates for more
// than one reason, by the parameter that decided.
const char* missing_after(const CandidateRecord& c) {
  const Rejection& f = c.fate;
  if (f.param == "region_margin_rate")
    return "Stopped at size_filter: its outline runs into the edge of its search region, so it is not whole here. No "
           "quad, no frontal view and no bits; a marker there is searched whole on the next full search.";
  if (f.param == "coarse_factor")
    return "Stopped at quad_fit: the coarse search found the same quad as the first search, which is read instead. "
           "No frontal view and no bits for this one.";
  // Read as found: its corners were never refined, and the frontal view, histogram and bits are of the quad as
  // the polygon gave it.
  if (f.param == "unrefined_miss_rate")
    return "Stopped before corner_refinement: read as found, on the polygon's corners, its nearest id is further "
           "than the correction budget plus unrefined_miss_rate of the code's bits, so its corners were not refined "
           "and it was not read again. The frontal view and bits are of the unrefined quad.";
  if (c.read_as_found && f.stage == Stage::otsu)
    return "Stopped before corner_refinement: read as found, on the polygon's corners, the frontal view is too "
           "uniform to split into black and white, so its corners were not refined and no bits were read.";
  if (c.read_as_found && f.stage == Stage::border_check)
    return "Stopped before corner_refinement: read as found, on the polygon's corners, the outer ring of cells is "
           "not black enough, so its corners were not refined and it was not read again. The frontal view and bits "
           "are of the unrefined quad.";
  if (f.param == "quiet_zone_max_dark_rate")
    return "Stopped at border_check: the bits were read and the frame is black, but outside it, where a printed "
           "marker is light, one side is as dark as the frame: a piece of some larger dark shape. The inner bits "
           "were not looked up in the dictionary.";
  switch (f.stage) {
    case Stage::size_filter:
      return "Stopped at size_filter: its border is too short or too long for a marker, so there is no quad, no "
             "frontal view, no histogram and no bits.";
    case Stage::quad_fit:
      return "Stopped at quad_fit: the contour is not a convex quadrilateral of usable sides, so there is no quad, "
             "no frontal view and no bits.";
    case Stage::nested_filter:
      return "Stopped at nested_filter: its quad traces the same border as an outer quad, which was read instead. "
             "No frontal view and no bits for this one.";
    case Stage::perspective_removal:
      return "Stopped at perspective_removal: no frontal view, no bits.";
    case Stage::otsu:
      return "Stopped at otsu: the frontal view is too uniform to split into black and white, so no bits were read.";
    case Stage::bit_grid:
      return "Stopped at bit_grid: no bits.";
    case Stage::border_check:
      return "Stopped at border_check: the bits were read but the outer ring of cells is not black enough, so the "
             "inner bits were not looked up in the dictionary.";
    case Stage::identification:
      return "Stopped at identification: every stage ran, but no marker is within the correction budget.";
    case Stage::corner_refinement:
      return "Stopped at corner_refinement: its corners could not be refined (the stage drops nothing today).";
    case Stage::duplicates:
      return "Identified, then dropped at duplicates: another candidate gave the same marker.";
    case Stage::fine_search:
      return "Dropped by fine_search: traced at full resolution around a small shape of the decimated search, its "
             "outline did not make a quad of its own (the reason above), so there is no frontal view and no bits.";
    default: return nullptr;
  }
}

// [SECTION] fate

void fate_section(const FrameTrace& t, const CandidateRecord& c) {
  const Rejection& f = c.fate;
  const std::string stage(stage_name(f.stage));
  chip((stage + "##fate").c_str(), fate_colour(f.stage));
  ImGui::SameLine();
  if (f.stage == Stage::accepted && c.marker >= 0 && c.marker < static_cast<int>(t.markers.size())) {
    const Marker& mk = t.markers[static_cast<size_t>(c.marker)];
    ImGui::PushStyleColor(ImGuiCol_Text, accepted_colour());
    ImGui::TextWrapped("marker id %d (%s), rotation %d, %d bit%s corrected", mk.id, mk.dict.c_str(), mk.rotation,
                       mk.hamming, mk.hamming == 1 ? "" : "s");
    ImGui::PopStyleColor();
    return;
  }
  ImGui::PushStyleColor(ImGuiCol_Text, fate_colour(f.stage));
  ImGui::TextWrapped("%s", f.message.empty() ? "(no message)" : f.message.c_str());
  ImGui::PopStyleColor();
  if (ImGui::BeginTable("fate", 4, ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_ScrollX,
                        scroll_table_size(2))) {
    ImGui::TableSetupColumn("stage");
    ImGui::TableSetupColumn("parameter");
    ImGui::TableSetupColumn("value");
    ImGui::TableSetupColumn("limit");
    ImGui::TableHeadersRow();
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(fate_colour(f.stage)), "%s", stage.c_str());
    ImGui::TableNextColumn();
    if (f.param.empty()) ImGui::TextDisabled("(none)");
    else ImGui::TextUnformatted(std::string(f.param).c_str());
    ImGui::TableNextColumn();
    if (!f.param.empty()) ImGui::TextUnformatted(short_number(f.value).c_str());
    ImGui::TableNextColumn();
    if (!f.param.empty()) ImGui::TextUnformatted(short_number(f.limit).c_str());
    ImGui::EndTable();
  }
  if (const char* missing = missing_after(c)) ImGui::TextWrapped("%s", missing);
}

// [SECTION] region: contour and quad over the frame

void centre_on(ImageViewState& v, const CandidateRecord& c, ImVec2 size, const cv::Mat& image) {
  const float bw = static_cast<float>(std::max(c.bbox.width, 24));
  const float bh = static_cast<float>(std::max(c.bbox.height, 24));
  const float fit = std::min(size.x / static_cast<float>(image.cols), size.y / static_cast<float>(image.rows));
  v.fit = false;
  v.zoom = std::clamp(std::min(size.x / (bw * 2.0f), size.y / (bh * 2.0f)), fit, 32.0f);
  v.centre = {static_cast<float>(c.bbox.x) + bw * 0.5f - 0.5f, static_cast<float>(c.bbox.y) + bh * 0.5f - 0.5f};
}

void region_section(Context& ctx, InspectorState& st, const Frame& f, int index) {
  const FrameTrace& t = f.trace;
  const CandidateRecord& c = t.candidates[static_cast<size_t>(index)];
  const float s = ctx.scale;
  if (!section("Contour and quad", "(wheel zooms, right-drag pans)")) return;
  const bool centre = ImGui::SmallButton("Centre");
  flow(button_width("Whole frame"));
  if (ImGui::SmallButton("Whole frame")) st.crop.fit = true;
  const ImVec2 size{std::max(ImGui::GetContentRegionAvail().x, 64.0f), 240.0f * s};
  if (centre || st.centred_on != index) {
    centre_on(st.crop, c, size, f.image);
    st.centred_on = index;
  }
  const ImageMapping m = image_view(ctx, "region", "frame", f.image, f.index, st.crop, size);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->PushClipRect(m.min, m.max, true);
  const ImU32 colour = fate_colour(c.fate.stage);
  // The bounding box (faint; without a quad it is all there is to see, so then plain and a few pixels out so a
  // 1 px region shows), the quad thick with its corners numbered, the contour thin on top.
  {
    const ImVec2 a = m.to_screen(static_cast<float>(c.bbox.x) - 0.5f, static_cast<float>(c.bbox.y) - 0.5f);
    const ImVec2 b = m.to_screen(static_cast<float>(c.bbox.br().x) - 0.5f, static_cast<float>(c.bbox.br().y) - 0.5f);
    const float pad = c.has_quad ? 0.0f : 3.0f * s;
    dl->AddRect({a.x - pad, a.y - pad}, {b.x + pad, b.y + pad},
                c.has_quad ? IM_COL32(255, 255, 255, 90) : IM_COL32(255, 255, 255, 230), 0, 0,
                c.has_quad ? 1.0f : 2.0f * s);
  }
  if (c.has_quad) {
    draw_quad(dl, m, c.quad, fate_colour(c.fate.stage, 0.8f), 3.0f * s, true);
    const ImVec2 mid = m.to_screen(quad_centre(c.quad));
    for (int k = 0; k < 4; ++k) {
      const ImVec2 q = m.to_screen(c.quad[static_cast<size_t>(k)]);
      const float dx = q.x - mid.x, dy = q.y - mid.y;
      const float len = std::max(1.0f, std::sqrt(dx * dx + dy * dy));
      const float off = 12.0f * s;
      const char label[2] = {static_cast<char>('0' + k), 0};
      const ImVec2 ts = ImGui::CalcTextSize(label);
      const ImVec2 at{q.x + dx / len * off - ts.x * 0.5f, q.y + dy / len * off - ts.y * 0.5f};
      dl->AddRectFilled({at.x - 2, at.y - 1}, {at.x + ts.x + 2, at.y + ts.y + 1}, IM_COL32(0, 0, 0, 180), 3.0f);
      dl->AddText(at, colour, label);
    }
  }
  // The contour on top of the quad: it is what the quad was fitted to.
  if (c.contour >= 0 && c.contour < static_cast<int>(t.contours.size())) {
    const std::vector<cv::Point>& pts = t.contours[static_cast<size_t>(c.contour)];
    std::vector<ImVec2> screen;
    screen.reserve(pts.size());
    for (const cv::Point& p : pts) screen.push_back(m.to_screen(static_cast<float>(p.x), static_cast<float>(p.y)));
    if (!screen.empty()) {
      dl->AddPolyline(screen.data(), static_cast<int>(screen.size()), IM_COL32(0, 220, 255, 230), ImDrawFlags_Closed,
                      1.0f * s);
    }
  }
  if (c.fate.stage == Stage::accepted && c.marker >= 0 && c.marker < static_cast<int>(t.markers.size())) {
    const Marker& mk = t.markers[static_cast<size_t>(c.marker)];
    const ImVec2 tl = m.to_screen(mk.corners[0]);
    dl->AddCircle(tl, 7.0f * s, accepted_colour(), 16, 2.0f * s);
  }
  dl->PopClipRect();
  if (m.hovered) {
    ImGui::SetTooltip("(%.0f, %.0f)", static_cast<double>(m.mouse_px.x), static_cast<double>(m.mouse_px.y));
  }
  const char* contour_note = "";
  if (c.contour < 0) {
    contour_note = t.level == TraceLevel::full ? ", not traced: the region is too small to hold a marker's border"
                                               : ", kept only in the full trace";
  }
  note("white: bbox %dx%d at %d,%d   cyan: contour (%.0f px)%s", c.bbox.width, c.bbox.height,
                      c.bbox.x, c.bbox.y, c.perimeter, contour_note);
  if (c.has_quad) {
    note("thick: fitted quad, corners 0-3 in the candidate's order (square: corner 0)%s",
                        c.fate.stage == Stage::accepted ? "; green circle: the marker's own top-left" : "");
  } else {
    ImGui::TextDisabled("no quad was fitted");
  }
}

// [SECTION] frontal view, histogram

int grid_cells(const Frame& f, const CandidateRecord& c) {
  if (!c.bits.empty()) return c.bits.rows;
  const int cp = f.params.warp_cell_px;   // the frame's, which made the warp
  if (cp > 0 && c.warp.cols % cp == 0 && c.warp.cols / cp >= 3) return c.warp.cols / cp;
  return 0;
}

void warp_view(Context& ctx, const Frame& f, int index, float side) {
  const CandidateRecord& c = f.trace.candidates[static_cast<size_t>(index)];
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("warp", {side, side});
  const bool hovered = ImGui::IsItemHovered();
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const std::string key = "inspector:warp:" + std::to_string(index);
  dl->AddImage(ctx.texture(key, c.warp, f.index, true), p0, {p0.x + side, p0.y + side});
  const int cells = grid_cells(f, c);
  if (cells > 0) {
    const float cs = side / static_cast<float>(cells);
    for (int i = 0; i <= cells; ++i) {
      const float o = static_cast<float>(i) * cs;
      dl->AddLine({p0.x + o, p0.y}, {p0.x + o, p0.y + side}, IM_COL32(0, 200, 255, 110), 1.0f);
      dl->AddLine({p0.x, p0.y + o}, {p0.x + side, p0.y + o}, IM_COL32(0, 200, 255, 110), 1.0f);
    }
    // The border ring's inner edge: inside are the marker's bits.
    dl->AddRect({p0.x + cs, p0.y + cs}, {p0.x + side - cs, p0.y + side - cs}, IM_COL32(255, 220, 0, 200), 0, 0,
                1.5f * ctx.scale);
  }
  dl->AddRect(p0, {p0.x + side, p0.y + side}, IM_COL32(90, 90, 100, 255));
  if (hovered && cells > 0) {
    const ImVec2 mp = ImGui::GetIO().MousePos;
    const int x = std::clamp(static_cast<int>((mp.x - p0.x) / side * static_cast<float>(c.warp.cols)), 0, c.warp.cols - 1);
    const int y = std::clamp(static_cast<int>((mp.y - p0.y) / side * static_cast<float>(c.warp.rows)), 0, c.warp.rows - 1);
    const int col = std::clamp(static_cast<int>((mp.x - p0.x) / side * static_cast<float>(cells)), 0, cells - 1);
    const int row = std::clamp(static_cast<int>((mp.y - p0.y) / side * static_cast<float>(cells)), 0, cells - 1);
    const int grey = c.warp.at<uint8_t>(y, x);
    if (!c.bits.empty()) {
      ImGui::SetTooltip("cell row %d, col %d%s: read %s\ngrey %d (Otsu threshold %d)", row, col,
                        (row == 0 || col == 0 || row == cells - 1 || col == cells - 1) ? " (border)" : "",
                        c.bits.at<uint8_t>(row, col) ? "white" : "black", grey, c.otsu_threshold);
    } else {
      ImGui::SetTooltip("cell row %d, col %d\ngrey %d (Otsu threshold %d)", row, col, grey, c.otsu_threshold);
    }
  }
}

void frontal_section(Context& ctx, const Frame& f, int index) {
  const CandidateRecord& c = f.trace.candidates[static_cast<size_t>(index)];
  const float s = ctx.scale;
  if (!section("Frontal view and Otsu threshold")) return;
  if (c.warp.empty() && c.otsu_threshold < 0) {
    note("%s", c.has_quad ? "Not read: no frontal view." : "No quad, so no frontal view.");
    return;
  }
  const float avail = ImGui::GetContentRegionAvail().x;
  if (!c.warp.empty()) {
    const float side = std::min(220.0f * s, std::max(64.0f * s, avail * 0.45f));
    ImGui::BeginGroup();
    warp_view(ctx, f, index, side);
    const int cells = grid_cells(f, c);
    ImGui::TextDisabled("%dx%d px, %d x %d cells", c.warp.cols, c.warp.rows, cells, cells);
    ImGui::EndGroup();
    flow(160.0f * s);   // the histogram beside the frontal view when it has room, else under it
  }
  ImGui::BeginGroup();
  const float hist_w = std::max(64.0f * s, ImGui::GetContentRegionAvail().x);
  histogram_plot(c, {hist_w, 110.0f * s});
  if (c.otsu_threshold >= 0) {
    ImGui::TextWrapped("Otsu threshold %d, grey stddev %.1f", c.otsu_threshold, c.stddev);
    const double min_sd = f.params.otsu_min_stddev;
    note("otsu_min_stddev %.1f (this frame's): %s", min_sd,
                        c.stddev < min_sd ? "too uniform to read" : "contrast enough to read");
  }
  if (!c.warp.empty()) {
    note("Dark bins (left of the red line) read black, light bins white; a marker shows two humps.");
  }
  ImGui::EndGroup();
}

// [SECTION] bits and identification

// An (n+2)x(n+2) grid of the marker's expected cells (black border, inner bits from `inner`); cells that differ
// from `read` are crossed.
void expected_grid(const cv::Mat& inner, const cv::Mat& read, float cell) {
  const int n = inner.rows + 2;
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::Dummy({cell * static_cast<float>(n), cell * static_cast<float>(n)});
  ImDrawList* dl = ImGui::GetWindowDrawList();
  for (int r = 0; r < n; ++r) {
    for (int col = 0; col < n; ++col) {
      const bool border = r == 0 || col == 0 || r == n - 1 || col == n - 1;
      const bool white = !border && inner.at<uint8_t>(r - 1, col - 1) != 0;
      const ImVec2 a{p0.x + static_cast<float>(col) * cell, p0.y + static_cast<float>(r) * cell};
      const ImVec2 b{a.x + cell, a.y + cell};
      dl->AddRectFilled(a, b, white ? IM_COL32(235, 235, 235, 255) : IM_COL32(20, 20, 20, 255));
      dl->AddRect(a, b, IM_COL32(90, 90, 100, 255));
      if (!border && read.rows == n && (read.at<uint8_t>(r, col) != 0) != white) {
        const ImU32 red = IM_COL32(255, 40, 40, 255);
        dl->AddLine({a.x + 3, a.y + 3}, {b.x - 3, b.y - 3}, red, 2.5f);
        dl->AddLine({b.x - 3, a.y + 3}, {a.x + 3, b.y - 3}, red, 2.5f);
      }
    }
  }
}

void bits_section(Context& ctx, InspectorState& st, const Frame& f, int index) {
  const FrameTrace& t = f.trace;
  const CandidateRecord& c = t.candidates[static_cast<size_t>(index)];
  const float s = ctx.scale;
  if (!section("Bits and identification")) return;
  if (c.bits.empty() && c.border_errors < 0 && c.best_rotation() < 0) {
    note("No bits: the candidate stopped at %s, before bit_grid.",
                        std::string(stage_name(c.fate.stage)).c_str());
    return;
  }
  if (st.rotation_for != index) {
    st.rotation_for = index;
    st.rotation = -1;
  }
  const int best = c.best_rotation();
  const int shown = st.rotation >= 0 ? st.rotation : best;
  const Dictionary* dict = dictionary(st, c.dict);
  if (!c.bits.empty()) {
    const int n = c.bits.rows;
    const float cell = std::clamp(150.0f * s / static_cast<float>(n), 10.0f * s, 24.0f * s);
    // The nearest marker's bits in its best rotation: the read grid crosses the bits that differ from them.
    cv::Mat best_bits;
    if (best >= 0 && dict && dict->marker_size() == n - 2) {
      best_bits = Dictionary::unpack(dict->code(c.per_rotation[static_cast<size_t>(best)].id, best), n - 2);
    }
    ImGui::BeginGroup();
    ImGui::TextUnformatted("read");
    bit_grid(c, cell, best_bits);
    ImGui::EndGroup();
    if (shown >= 0 && dict && dict->marker_size() == n - 2) {
      const DictMatch& mm = c.per_rotation[static_cast<size_t>(shown)];
      flow(std::max(cell * static_cast<float>(n), text_width("id 0000, rotation 0")) + 16.0f * s);
      ImGui::BeginGroup();
      ImGui::Text("id %d, rotation %d", mm.id, shown);
      expected_grid(Dictionary::unpack(dict->code(mm.id, shown), n - 2), c.bits, cell);
      ImGui::EndGroup();
    }
    // The legend beside the grids when there is room for lines of a dozen words, else under them (never one
    // word per line).
    flow(ImGui::GetFontSize() * 16);
    ImGui::BeginGroup();
    ImGui::TextDisabled("Legend");
    ImGui::TextWrapped("red outline: a border cell read white (it must be black)");
    ImGui::TextWrapped("red cross on 'read': an inner bit that differs from the nearest id in its best rotation");
    ImGui::TextWrapped("red cross on the right: the same comparison for the rotation chosen in the table below");
    ImGui::EndGroup();
  } else if (t.level != TraceLevel::full) {
    note("The bit grid is kept only in the full trace.");
  }
  if (c.border_errors >= 0) {
    ImGui::Text("border: %d of %d cells white", c.border_errors, c.border_cells);
    if (c.fate.stage == Stage::border_check) {
      flow(text_width("> 00 allowed"));
      ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(stage_colour(Stage::border_check)), "> %s allowed",
                         short_number(c.fate.limit).c_str());
    }
  }
  if (best < 0) {
    if (c.fate.stage == Stage::border_check) note("Identification did not run (border_check failed).");
    return;
  }
  // The correction budget: from the fate when identification decided, else from the parameters the frame was
  // detected with (not the current settings: the frame may be frozen, or older than a slider's move).
  std::string budget_text;
  int budget = -1;
  if (c.fate.stage == Stage::identification) {
    budget = static_cast<int>(c.fate.limit);
    budget_text = "budget " + short_number(c.fate.limit) + " bits (this frame)";
  } else if (dict) {
    budget = stages::correction_budget(*dict, f.params);
    char buf[128];
    std::snprintf(buf, sizeof buf, "budget %d bits = max_correction_bits %d x error_correction_rate %.2f (this frame)",
                  budget, dict->max_correction_bits(), f.params.error_correction_rate);
    budget_text = buf;
  }
  ImGui::TextWrapped("Nearest marker of %s in each rotation", c.dict.empty() ? "?" : c.dict.c_str());
  if (!budget_text.empty()) note("%s", budget_text.c_str());
  const ImGuiTableFlags flags = ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_BordersInnerV |
                                ImGuiTableFlags_BordersOuterH | ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollX;
  if (ImGui::BeginTable("rotations", 4, flags, scroll_table_size(5))) {
    ImGui::TableSetupColumn("rotation");
    ImGui::TableSetupColumn("nearest id");
    ImGui::TableSetupColumn("Hamming");
    ImGui::TableSetupColumn("verdict");
    ImGui::TableHeadersRow();
    for (int k = 0; k < 4; ++k) {
      const DictMatch& mm = c.per_rotation[static_cast<size_t>(k)];
      ImGui::TableNextRow();
      if (k == best) ImGui::TableSetBgColor(ImGuiTableBgTarget_RowBg1, IM_COL32(60, 110, 60, 160));
      ImGui::TableNextColumn();
      char label[48];
      std::snprintf(label, sizeof label, "%d (%d deg)", k, k * 90);
      if (ImGui::Selectable(label, k == shown, ImGuiSelectableFlags_SpanAllColumns)) st.rotation = k;
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("Show this rotation's expected bits beside the read grid.");
      ImGui::TableNextColumn();
      if (mm.id >= 0) ImGui::Text("%d", mm.id);
      else ImGui::TextDisabled("-");
      ImGui::TableNextColumn();
      if (mm.id >= 0) ImGui::Text("%d", mm.hamming);
      ImGui::TableNextColumn();
      if (mm.id < 0) {
        ImGui::TextDisabled("-");
      } else if (budget >= 0) {
        const bool within = mm.hamming <= budget;
        ImGui::TextColored(within ? ImVec4(0.3f, 1.0f, 0.4f, 1) : ImVec4(1.0f, 0.5f, 0.4f, 1), "%s%s",
                           within ? "within budget" : "too far", k == best ? " (best)" : "");
      } else if (k == best) {
        ImGui::TextUnformatted("best");
      }
    }
    ImGui::EndTable();
  }
}

}  // namespace

void draw_inspector(Context& ctx) {
  InspectorState& st = panel_state<InspectorState>(ctx.view, Panel::inspector);
  if (waiting_for_frame(ctx)) return;
  const Frame& f = *ctx.frame;
  const FrameTrace& t = f.trace;
  int& sel = ctx.view.selected_candidate;
  if (t.level == TraceLevel::off) {
    ImGui::TextWrapped("The trace is off: candidates are not recorded. Raise the trace level to inspect them.");
    return;
  }
  if (sel < 0) {
    ImGui::TextWrapped("No candidate selected: click a candidate in the live view or the ledger (Candidates).");
    return;
  }
  const int count = static_cast<int>(t.candidates.size());
  if (sel >= count) {
    ImGui::TextWrapped("Candidate #%d is not in this frame (it has %d candidates): the selection is a position in "
                       "the current frame's list. Click a candidate again.", sel, count);
    return;
  }
  // Header: step through the candidates, and the candidate's fate in a line.
  if (ImGui::ArrowButton("prev", ImGuiDir_Left) && sel > 0) --sel;
  ImGui::SameLine(0, 2);
  if (ImGui::ArrowButton("next", ImGuiDir_Right) && sel + 1 < count) ++sel;
  ImGui::SameLine();
  const CandidateRecord& c = t.candidates[static_cast<size_t>(sel)];
  ImGui::PushStyleColor(ImGuiCol_Text, fate_colour(c.fate.stage));
  ImGui::TextWrapped("%s", candidate_line(t, sel).c_str());
  ImGui::PopStyleColor();
  if (t.level != TraceLevel::full) {
    note("Summary trace: the contour, frontal view, histogram and bits are kept only at the full level.");
  }
  fate_section(t, c);
  region_section(ctx, st, f, sel);
  frontal_section(ctx, f, sel);
  bits_section(ctx, st, f, sel);
}

}  // namespace arwb::ui
