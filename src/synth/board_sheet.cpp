// The calibration board's printed page: layout on A4 or A3 and drawing with cairo. See board_sheet.hpp.
#include "synth/board_sheet.hpp"

#include "detect/dictionary.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>

namespace arwb {

namespace {

using CairoPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;
using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;

constexpr double kMarginMm = kSheetMarginMm;
constexpr double kTextFontMm = 3.0;
constexpr double kLineMm = 1.5 * kTextFontMm;
constexpr double kTextGapMm = 2.0;     // between the text and the measuring bar
constexpr double kBoardGapMm = 3.0;    // at least between the board (or its quiet zone) and the text
constexpr double kEpsMm = 1e-9;        // sizes that fit exactly are not refused over rounding

struct Page {
  const char* name;
  double w, h;   // portrait
};
constexpr Page kA4{"A4", 210, 297}, kA3{"A3", 297, 420};

// Squares across and down, whatever the kind counts.
cv::Size squares(const BoardSpec& b) {
  return b.kind == BoardKind::charuco ? cv::Size(b.cols, b.rows) : cv::Size(b.cols + 1, b.rows + 1);
}

// A chessboard detector needs white all round the outer squares; a ChArUco board's markers carry their own.
double quiet_zone_mm(const BoardSpec& b) { return b.kind == BoardKind::chessboard ? b.square_mm : 0; }

double widest_line_mm(const std::vector<std::string>& text) {
  SurfacePtr scratch(cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, nullptr), cairo_surface_destroy);
  CairoPtr cr(cairo_create(scratch.get()), cairo_destroy);
  sheet::set_font(cr.get(), kTextFontMm);
  double widest = 0;
  for (const auto& line : text) widest = std::max(widest, sheet::text_width_mm(cr.get(), line));
  return widest;
}

// The layout of `board` on one page of w x h, or nullopt when it does not fit.
std::optional<BoardSheetLayout> place(const BoardSpec& board, const Page& page, bool landscape,
                                      const std::vector<std::string>& text, double widest_line_mm) {
  BoardSheetLayout lay;
  lay.board = board;
  lay.paper = page.name;
  lay.landscape = landscape;
  lay.page_w_mm = landscape ? page.h : page.w;
  lay.page_h_mm = landscape ? page.w : page.h;
  lay.quiet_mm = quiet_zone_mm(board);
  lay.text = text;
  const double across = lay.page_w_mm - 2 * kMarginMm;
  lay.text_font_mm = widest_line_mm > across ? kTextFontMm * across / widest_line_mm : kTextFontMm;
  lay.text_top_mm = lay.page_h_mm - kMarginMm - sheet::kFooterMm - kTextGapMm - kLineMm * double(text.size());

  const cv::Size n = squares(board);
  const double bw = n.width * board.square_mm, bh = n.height * board.square_mm;
  // The squares stay inside the margins; the quiet zone stays on the page and clear of the text.
  const double side = std::max(kMarginMm, lay.quiet_mm);
  const double top = side, bottom = lay.text_top_mm - std::max(kBoardGapMm, lay.quiet_mm);
  if (bw + 2 * side > lay.page_w_mm + kEpsMm || bh > bottom - top + kEpsMm) return std::nullopt;
  lay.board_mm = cv::Rect2d((lay.page_w_mm - bw) / 2, top + (bottom - top - bh) / 2, bw, bh);
  return lay;
}

// The pages to try, smallest first: each paper portrait, then landscape.
std::vector<std::pair<Page, bool>> pages_for(PaperChoice paper) {
  const std::vector<Page> papers = paper == PaperChoice::a4   ? std::vector<Page>{kA4}
                                   : paper == PaperChoice::a3 ? std::vector<Page>{kA3}
                                                              : std::vector<Page>{kA4, kA3};
  std::vector<std::pair<Page, bool>> out;
  for (const Page& p : papers) {
    out.emplace_back(p, false);
    out.emplace_back(p, true);
  }
  return out;
}

std::optional<BoardSheetLayout> first_fit(const BoardSpec& board, PaperChoice paper,
                                          const std::vector<std::string>& text, double widest) {
  for (const auto& [page, landscape] : pages_for(paper))
    if (auto lay = place(board, page, landscape, text, widest)) return lay;
  return std::nullopt;
}

std::optional<Dictionary> board_dictionary(const BoardSpec& board) {
  if (board.kind != BoardKind::charuco) return std::nullopt;
  std::string error;
  std::optional<Dictionary> dict = dictionary_by_name(board.dictionary, &error);
  if (!dict) throw std::invalid_argument("--dict " + board.dictionary + ": " + error);
  if (dict->size() < charuco_marker_count(board))
    throw std::invalid_argument("--dict " + dict->name() + " has " + std::to_string(dict->size()) + " markers; a " +
                                std::to_string(board.cols) + "x" + std::to_string(board.rows) +
                                " ChArUco board needs " + std::to_string(charuco_marker_count(board)));
  return dict;
}

// The squares with their top-left corner at (x, y), cr in millimetres: the black squares as one path (they touch
// only at corners), then a ChArUco board's markers in its white squares.
void draw_board(cairo_t* cr, const BoardSpec& board, const std::optional<Dictionary>& dict, double x, double y) {
  const cv::Size n = squares(board);
  const double sq = board.square_mm;
  cairo_new_path(cr);
  for (int r = 0; r < n.height; ++r)
    for (int c = 0; c < n.width; ++c)
      if ((r + c) % 2 == 0) cairo_rectangle(cr, x + c * sq, y + r * sq, sq, sq);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_fill(cr);
  if (!dict) return;
  const double inset = (sq - board.marker_mm) / 2;
  int id = 0;
  for (int r = 0; r < n.height; ++r)
    for (int c = 0; c < n.width; ++c)
      if ((r + c) % 2 == 1) sheet::draw_marker(cr, dict->bits(id++), x + c * sq + inset, y + r * sq + inset,
                                               board.marker_mm);
}

// The whole page, cr in points.
void draw_page(cairo_t* cr, const BoardSheetLayout& lay, const std::optional<Dictionary>& dict) {
  cairo_save(cr);
  cairo_scale(cr, sheet::kPtPerMm, sheet::kPtPerMm);
  sheet::fill_rect(cr, 0, 0, lay.page_w_mm, lay.page_h_mm, 1);   // an SVG page is transparent otherwise
  draw_board(cr, lay.board, dict, lay.board_mm.x, lay.board_mm.y);
  sheet::set_font(cr, lay.text_font_mm);
  cairo_set_source_rgb(cr, 0, 0, 0);
  for (size_t i = 0; i < lay.text.size(); ++i) {
    cairo_move_to(cr, kMarginMm, lay.text_top_mm + kLineMm * double(i) + kTextFontMm);
    cairo_show_text(cr, lay.text[i].c_str());
  }
  const double baseline = lay.page_h_mm - kMarginMm - 1.0;
  sheet::draw_measuring_bar(cr, kMarginMm, baseline);
  const std::string caption = "print on " + lay.paper_name();
  cairo_move_to(cr, lay.page_w_mm - kMarginMm - sheet::text_width_mm(cr, caption), baseline);
  cairo_show_text(cr, caption.c_str());
  cairo_restore(cr);
}

// An image of w_mm x h_mm at px_per_mm drawn by draw(cr) with cr in points.
template <typename Draw>
cv::Mat render(double w_mm, double h_mm, double px_per_mm, Draw draw) {
  const int w = int(std::lround(w_mm * px_per_mm)), h = int(std::lround(h_mm * px_per_mm));
  SurfacePtr surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h), cairo_surface_destroy);
  CairoPtr cr(cairo_create(surface.get()), cairo_destroy);
  cairo_set_source_rgb(cr.get(), 1, 1, 1);
  cairo_paint(cr.get());
  cairo_scale(cr.get(), px_per_mm / sheet::kPtPerMm, px_per_mm / sheet::kPtPerMm);
  draw(cr.get());
  cr.reset();
  cairo_surface_flush(surface.get());
  // RGB24 is 32 bits a pixel, native-endian 0xXXRRGGBB: B, G, R, X in memory on the machines we build for.
  const cv::Mat bgrx(h, w, CV_8UC4, cairo_image_surface_get_data(surface.get()),
                     size_t(cairo_image_surface_get_stride(surface.get())));
  cv::Mat grey;
  cv::cvtColor(bgrx, grey, cv::COLOR_BGRA2GRAY);
  return grey;
}

}  // namespace

int charuco_marker_count(const BoardSpec& board) { return board.cols * board.rows / 2; }

std::optional<BoardSheetLayout> board_sheet_layout(const BoardSpec& board, PaperChoice paper,
                                                   std::vector<std::string> text, std::string* problem) {
  const double widest = widest_line_mm(text);
  if (auto lay = first_fit(board, paper, text, widest)) return lay;
  // The fit only grows with the square (a marker inside it changes nothing), so the largest is found walking down.
  double largest = 0;
  BoardSpec smaller = board;
  for (long tenths = std::lround(std::floor(board.square_mm * 10)); tenths >= 1 && largest == 0; --tenths) {
    smaller.square_mm = double(tenths) / 10;
    if (first_fit(smaller, paper, text, widest)) largest = smaller.square_mm;
  }
  const cv::Size n = squares(board);
  const std::string what = std::string(board.kind == BoardKind::charuco ? "a ChArUco board" : "a chessboard") +
                           " of " + std::to_string(n.width) + "x" + std::to_string(n.height) + " squares of " +
                           sheet::format_mm(board.square_mm) + " mm";
  const std::string where = paper == PaperChoice::a4   ? "A4 (--paper a4)"
                            : paper == PaperChoice::a3 ? "A3 (--paper a3)"
                                                       : "A4 or A3";
  *problem = what + " does not fit on " + where + " within 10 mm margins with the text under it" +
             (board.kind == BoardKind::chessboard ? " and a one-square white border" : "") +
             (largest > 0 ? "; the largest --square-mm that fits is " + sheet::format_mm(largest)
                          : "; fewer --cols or --rows are needed");
  return std::nullopt;
}

SheetResult write_board_sheet(const BoardSheetLayout& layout, SheetFormat format, const std::string& path) {
  const std::optional<Dictionary> dict = board_dictionary(layout.board);
  return sheet::write_pages(format, path, layout.page_w_mm, layout.page_h_mm, 1, layout.board.describe(),
                            [&](cairo_t* cr, int) { draw_page(cr, layout, dict); });
}

cv::Mat render_board_sheet(const BoardSheetLayout& layout, double px_per_mm) {
  const std::optional<Dictionary> dict = board_dictionary(layout.board);
  return render(layout.page_w_mm, layout.page_h_mm, px_per_mm, [&](cairo_t* cr) { draw_page(cr, layout, dict); });
}

cv::Mat render_board(const BoardSpec& board, double px_per_mm) {
  const std::optional<Dictionary> dict = board_dictionary(board);
  const cv::Size n = squares(board);
  return render(n.width * board.square_mm, n.height * board.square_mm, px_per_mm, [&](cairo_t* cr) {
    cairo_scale(cr, sheet::kPtPerMm, sheet::kPtPerMm);
    draw_board(cr, board, dict, 0, 0);
  });
}

}  // namespace arwb
