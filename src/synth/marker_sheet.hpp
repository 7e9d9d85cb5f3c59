// Printable marker sheets for `arwb markers`: A4 portrait pages with markers at a true physical size, drawn with
// cairo into a PDF (all pages in one file) or SVG (one file per page, since SVG 1.1 has no pages).
//
// Every length here is in millimetres. The size of a marker is measured on its outer black edge. Each marker sits in
// a white quiet zone of one cell inside a thin light-grey cut outline, with a label under the quiet zone; each page
// ends with a 100 mm measuring bar so a user can check that the printer did not scale the page.
//
// In the output every marker is exactly one black path filled with the even-odd rule: its first subpath is the outer
// black edge and the others are the white cells (merged into runs along each row) as holes. One path leaves no
// anti-aliasing seams between neighbouring black cells in any viewer, and it lets tests find each marker's true size.
#pragma once

#include "detect/dictionary.hpp"

#include <cairo.h>

#include <functional>
#include <string>
#include <vector>

namespace arwb {

constexpr double kSheetPageWidthMm = 210.0;
constexpr double kSheetPageHeightMm = 297.0;
constexpr double kSheetMarginMm = 10.0;
constexpr double kSheetMinMarkerMm = 5.0;
constexpr double kSheetMaxMarkerMm = 190.0;  // the width inside the margins; a quiet zone makes the real limit lower

// Where the markers go on a page, for one marker size and dictionary.
struct SheetLayout {
  double marker_mm = 0;   // outer black edge
  double cell_mm = 0;     // one cell of the marker, border included
  double quiet_mm = 0;    // white space between the black edge and the cut outline (one cell)
  double box_w_mm = 0;    // the cut-out piece, outline included
  double box_h_mm = 0;
  double label_mm = 0;    // label font size
  int cols = 0;           // markers across a page; 0 when one does not fit
  int rows = 0;           // markers down a page
  int per_page() const { return cols * rows; }
  bool fits() const { return cols > 0 && rows > 0; }
  int pages(int markers) const { return fits() ? (markers + per_page() - 1) / per_page() : 0; }
};

// The layout for markers of marker_mm with marker_size inner bits, when the widest label is label_width_mm wide
// (0: the label never widens the piece, which is true from about 25 mm up).
SheetLayout sheet_layout(double marker_mm, int marker_size, double label_width_mm = 0);
// The largest marker size, in steps of 0.1 mm, that fits on a page; 0 if none from kSheetMinMarkerMm does.
double max_sheet_marker_mm(int marker_size);

enum class SheetFormat { pdf, svg };

struct SheetResult {
  int pages = 0;
  std::vector<std::string> files;  // a PDF: path; an SVG: path, then <stem>-2.svg, <stem>-3.svg ... for more pages
};

// Writes the sheet. Throws std::invalid_argument if the size does not fit on a page, std::runtime_error naming the
// file if it cannot be written (nothing is written then; an older file of that name stays as it was).
SheetResult write_marker_sheet(const Dictionary& dict, const std::vector<int>& ids, double marker_mm,
                               SheetFormat format, const std::string& path);

// ---- What every printed sheet shares (the marker sheets here, the calibration board in board_sheet.hpp) ----------
namespace sheet {

constexpr double kPtPerMm = 72.0 / 25.4;  // cairo's PDF and SVG surfaces measure in points
constexpr double kFooterMm = 14.0;        // the measuring bar and its instruction, at the bottom inside the margin

std::string format_mm(double mm);   // "25", "22.5": a length in a sheet's text

// In these, cr is scaled to millimetres. Text metrics are not rounded to device pixels (the page is vector).
void set_font(cairo_t* cr, double size_mm);
double text_width_mm(cairo_t* cr, const std::string& text);
void fill_rect(cairo_t* cr, double x, double y, double w, double h, double grey);
// A marker whose outer black edge is size_mm, top-left at (x, y), as one even-odd path (see above).
void draw_marker(cairo_t* cr, const cv::Mat& bits, double x, double y, double size_mm);
// A 100 mm bar, a tick every millimetre (longer every 5 and 10), its left end at x, and under it on `baseline` the
// instruction to print at actual size. The ends' ticks stay inside the bar, so the figure is exactly 100 mm wide.
void draw_measuring_bar(cairo_t* cr, double x, double baseline);

// Draws `pages` pages of w_mm x h_mm, each by draw(cr, page) with cr in points, into a PDF (one file) or SVG (one
// file a page: path, <stem>-2.svg, ...), and writes the file(s) whole: the bytes are made first, then the files
// replace their old selves by renames once all are on disk. Throws std::runtime_error "cannot write '<file>':
// <reason>", the older files as they were.
SheetResult write_pages(SheetFormat format, const std::string& path, double w_mm, double h_mm, int pages,
                        const std::string& title, const std::function<void(cairo_t*, int)>& draw);

}  // namespace sheet

}  // namespace arwb
