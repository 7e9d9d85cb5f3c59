// Small reusable drawers shared by the panels (as ImGui's Metrics window is built from one drawer per struct):
// an image view with zoom and pan, quads over it, a candidate's one-line summary, an Otsu histogram and a bit
// grid. Reused by the live view, the pipeline, the ledger's tooltips, the inspector and the teaching tour.
#pragma once

#include "detect/dictionary.hpp"
#include "detect/params.hpp"
#include "detect/trace.hpp"
#include "inspect/trace_view.hpp"
#include "ui/context.hpp"

#include <imgui.h>

#include <string>
#include <string_view>
#include <vector>

namespace arwb::ui {

// The empty state of a panel that needs a frame: says so and returns true while there is none yet.
bool waiting_for_frame(const Context& ctx);

// Opens the Script editor (and brings it to the front) scrolled to `line` of the scene file (0: where it was):
// for the line numbers of the Scene panel's mappings, of errors in the console and of the scene's load error.
void show_script_line(Context& ctx, int line);
// The line of a scene message that reads "file:line: message" when its file is `file` (the same path, one ending
// with the other at a '/', or Lua's shortened ".../end/of/path"); 0 otherwise.
int message_line_in(const std::string& message, const std::string& file);
// The scene file to show and edit: the one in use or, when none is because its first load failed, the .lua or
// .xml file the load error names, so it can be fixed in the editor (the worker reloads it when it changes).
std::string scene_file_to_edit(const SceneStatus& s);

// Text colours: a fault, a warning, all well.
inline const ImVec4 kRed{1.0f, 0.35f, 0.35f, 1.0f};
inline const ImVec4 kYellow{1.0f, 0.8f, 0.3f, 1.0f};
inline const ImVec4 kGreen{0.35f, 0.9f, 0.4f, 1.0f};

// A section's title over a separator, with a little space above.
void section_heading(const char* title);
// A figure for a table: a whole number as it is ("12"), another to 3 significant digits ("0.125", "1.5e+03").
std::string short_number(double v);

// The colour of a stage (rejected candidates are drawn in the colour of the stage that dropped them).
ImU32 stage_colour(Stage s, float alpha = 1.0f);
ImU32 accepted_colour(float alpha = 1.0f);
// The colour of a candidate's fate: accepted_colour for markers, else the colour of the stage that dropped it.
ImU32 fate_colour(Stage s, float alpha = 1.0f);

// Where an image landed on screen, to draw overlays on it.
struct ImageMapping {
  ImVec2 origin{0, 0};   // screen position of image pixel (-0.5, -0.5), the top-left of the first pixel
  float zoom = 1;        // screen pixels per image pixel
  bool hovered = false;  // the mouse is over the view
  ImVec2 mouse_px{-1, -1};  // image pixel coordinates under the mouse (pixel centres at integers)
  ImVec2 min{0, 0}, max{0, 0};  // the view's screen rectangle
  ImVec2 to_screen(float x, float y) const { return {origin.x + (x + 0.5f) * zoom, origin.y + (y + 0.5f) * zoom}; }
  ImVec2 to_screen(cv::Point2f p) const { return to_screen(p.x, p.y); }
  cv::Point2f to_image(ImVec2 s) const { return {(s.x - origin.x) / zoom - 0.5f, (s.y - origin.y) / zoom - 0.5f}; }
};

// Draws `image` (uploaded as texture `key` at `version`) in a child region of `size` (0: all available space)
// with zoom (mouse wheel, about the cursor), pan (drag with the right or middle button) and fit (double-click
// with the right button, or the state's fit flag). `state` may be shared by several views. When `texture` is
// given it is drawn instead of uploading `image`, which then only gives the size (the live view draws the
// composited frame this way, in the same pixel coordinates).
ImageMapping image_view(Context& ctx, const char* id, const std::string& key, const cv::Mat& image,
                        uint64_t version, ImageViewState& state, ImVec2 size = {0, 0}, ImTextureID texture = nullptr);

// Outline of a quad; corner 0 gets a filled square so the marker's orientation shows.
void draw_quad(ImDrawList* dl, const ImageMapping& m, const Quad& q, ImU32 colour, float thickness,
               bool mark_corner0 = false);

// A stage picture's text (inspect/trace_view.hpp) over the picture at `m`, in the window's type with a dark
// outline; a label in a strip no taller than the strip on screen. Returns the smallest type size drawn, in
// screen pixels (0: none drawn).
float draw_stage_labels(ImDrawList* dl, const ImageMapping& m, const std::vector<StageLabel>& labels);

// "#12 id 37 (ARUCO_ORIGINAL)" or "#12 otsu: stddev 3.1 < otsu_min_stddev 5": the candidate's fate in a line.
std::string candidate_line(const FrameTrace& t, int index);

// The frontal view's histogram with Otsu's threshold marked.
void histogram_plot(const CandidateRecord& c, ImVec2 size);

// The bit grid, one square per cell: border cells that are not black outlined in red, and, when `expected`
// (the inner bits of a marker, n x n 0/1) is given, inner bits that differ from it crossed. `cell` is the side
// of a cell in screen pixels.
void bit_grid(const CandidateRecord& c, float cell, const cv::Mat& expected = {});

// Parameters of the table (params.hpp): the printf format for a double from its range, a value as text, the
// tooltip (name, help, default, range) and the control itself. param_slider returns true when edited; a
// rejected value leaves `p` as it was and says why in `error`.
const char* format_for(const ParamInfo& info);
std::string value_text(const ParamInfo& info, double v);
void param_tooltip(const ParamInfo& info);
bool param_slider(DetectorParams& p, const ParamInfo& info, std::string* error = nullptr);

// An image drawn at a fixed size with a border (thumbnails, frontal views). Returns true when clicked.
// A small rounded label filled with `colour` (dimmed when !on), dark text on it, on the current line. Returns true
// when clicked. Used for per-stage counts that toggle a filter, and for a fate in a heading.
bool chip(const char* label, ImU32 colour, bool on = true);

bool image_button(Context& ctx, const std::string& key, const cv::Mat& image, uint64_t version, ImVec2 size,
                  bool selected = false);

// A message list's toolbar (Log, Console): one checkbox per level with its count, in the level's colour, then a
// text filter with a clear button. `show` and `filter` are the panel's view state.
void level_filter_bar(const char* const names[3], const ImU32 colours[3], const int counts[3], bool show[3],
                      char* filter, size_t filter_size, float filter_width);
// Toolbars that wrap instead of running past a narrow region's edge (and presentation mode's larger text):
// flow() continues the line when the next item, `width` wide, still fits, else starts a new line. The widths of
// a checkbox, a button and a text, for it.
void flow(float width);
float checkbox_width(const char* label);
float button_width(const char* label);
float text_width(const char* text);
// The next item `want` wide, or narrower so that it and its label (shown right of it) fit the window.
void fit_item_width(float want, const char* label);
// The outer size of a table with ImGuiTableFlags_ScrollX (which needs one) showing `rows` rows of text, header
// included, and its scrollbar: a narrow region scrolls the table sideways instead of cutting its columns.
ImVec2 scroll_table_size(int rows);
// TextDisabled that wraps at the window's edge (hints, explanations).
void text_disabled_wrapped(const char* text);
// "Why not detected?" on a marker whose exact corners are known (a lab frame's truth): the region around it, the
// truth drawn, the live view zoomed in on it, the Why panel shown.
void why_on_marker(View& view, const Quad& corners);

// Case-insensitive substring test; an empty needle matches everything.
bool contains_nocase(std::string_view hay, std::string_view needle);

}  // namespace arwb::ui
