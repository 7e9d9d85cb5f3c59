// Printable marker sheets: layout of A4 pages and drawing with cairo. See marker_sheet.hpp.
#include "synth/marker_sheet.hpp"

#include "base/files.hpp"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <span>
#include <stdexcept>
#include <utility>

namespace arwb {

namespace {

constexpr double kFooterFontMm = 2.6;
constexpr double kBarMm = 100.0;

using CairoPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;
using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;

}  // namespace

namespace sheet {

std::string format_mm(double mm) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", mm);
  return buf;
}

void set_font(cairo_t* cr, double size_mm) {
  cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size_mm);
  std::unique_ptr<cairo_font_options_t, decltype(&cairo_font_options_destroy)> opts(cairo_font_options_create(),
                                                                                   cairo_font_options_destroy);
  cairo_font_options_set_hint_metrics(opts.get(), CAIRO_HINT_METRICS_OFF);
  cairo_font_options_set_hint_style(opts.get(), CAIRO_HINT_STYLE_NONE);
  cairo_set_font_options(cr, opts.get());
}

double text_width_mm(cairo_t* cr, const std::string& text) {
  cairo_text_extents_t ext;
  cairo_text_extents(cr, text.c_str(), &ext);
  return ext.x_advance;
}

void fill_rect(cairo_t* cr, double x, double y, double w, double h, double grey) {
  cairo_rectangle(cr, x, y, w, h);
  cairo_set_source_rgb(cr, grey, grey, grey);
  cairo_fill(cr);
}

// The marker as one even-odd path: the outer black square first, then each run of white cells in a row as a hole.
// A single path has no internal edges for a rasteriser to blend, so neighbouring black cells never show seams
// (cairo_set_antialias would not help here: PDF and SVG viewers rasterise with their own settings).
void draw_marker(cairo_t* cr, const cv::Mat& bits, double x, double y, double size_mm) {
  const int n = bits.rows;
  const double cell = size_mm / (n + 2);
  cairo_new_path(cr);
  cairo_rectangle(cr, x, y, size_mm, size_mm);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < n;) {
      if (!bits.at<uint8_t>(r, c)) {
        ++c;
        continue;
      }
      int end = c;
      while (end < n && bits.at<uint8_t>(r, end)) ++end;
      cairo_rectangle(cr, x + (c + 1) * cell, y + (r + 1) * cell, (end - c) * cell, cell);
      c = end;
    }
  }
  cairo_set_fill_rule(cr, CAIRO_FILL_RULE_EVEN_ODD);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_fill(cr);
  cairo_set_fill_rule(cr, CAIRO_FILL_RULE_WINDING);
}

void draw_measuring_bar(cairo_t* cr, double x0, double baseline) {
  const double bar_top = baseline - 7.5;
  const double bar_h = 1.2;
  fill_rect(cr, x0, bar_top, kBarMm, bar_h, 0);
  constexpr double tick_w = 0.15;
  for (int k = 0; k <= 100; ++k) {
    const double len = k % 10 == 0 ? 3.0 : k % 5 == 0 ? 2.0 : 1.2;
    const double tx = std::clamp(x0 + k - tick_w / 2, x0, x0 + kBarMm - tick_w);
    fill_rect(cr, tx, bar_top - len, tick_w, len, 0);
  }
  set_font(cr, kFooterFontMm);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_move_to(cr, x0, baseline);
  cairo_show_text(cr, "print at 100 % (actual size, not fit to page): this bar must measure 100 mm");
}

namespace {

// What cairo writes, kept in memory until the page is whole.
cairo_status_t append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

// Page k (from 1) of an SVG sheet: the path itself first, then <stem>-k<ext>.
std::string svg_page_path(const std::string& path, int page) {
  if (page == 1) return path;
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  const std::string stem = has_ext ? path.substr(0, dot) : path;
  const std::string ext = has_ext ? path.substr(dot) : "";
  return stem + "-" + std::to_string(page) + ext;
}

void check(cairo_surface_t* surface, const std::string& path) {
  if (const cairo_status_t status = cairo_surface_status(surface); status != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error("cannot write '" + path + "': " + cairo_status_to_string(status));
}

}  // namespace

SheetResult write_pages(SheetFormat format, const std::string& path, double w_mm, double h_mm, int pages,
                        const std::string& title, const std::function<void(cairo_t*, int)>& draw) {
  const double w_pt = w_mm * kPtPerMm, h_pt = h_mm * kPtPerMm;
  std::vector<std::pair<std::string, std::string>> files;  // name, bytes
  if (format == SheetFormat::pdf) {
    std::string bytes;
    SurfacePtr surface(cairo_pdf_surface_create_for_stream(&append, &bytes, w_pt, h_pt), cairo_surface_destroy);
    cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_TITLE, title.c_str());
    cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_CREATOR, "arwb markers");
    CairoPtr cr(cairo_create(surface.get()), cairo_destroy);
    for (int page = 0; page < pages; ++page) {
      draw(cr.get(), page);
      cairo_show_page(cr.get());
    }
    cr.reset();
    cairo_surface_finish(surface.get());
    check(surface.get(), path);
    files.emplace_back(path, std::move(bytes));
  } else {
    // SVG 1.1 keeps only the last page of a multi-page cairo surface, hence one surface and file per page.
    for (int page = 0; page < pages; ++page) {
      std::string bytes;
      const std::string file = svg_page_path(path, page + 1);
      SurfacePtr surface(cairo_svg_surface_create_for_stream(&append, &bytes, w_pt, h_pt), cairo_surface_destroy);
      // Units on width and height make viewers and printers honour the physical size (the default is unitless).
      cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PT);
      CairoPtr cr(cairo_create(surface.get()), cairo_destroy);
      draw(cr.get(), page);
      cr.reset();
      cairo_surface_finish(surface.get());
      check(surface.get(), file);
      files.emplace_back(file, std::move(bytes));
    }
  }
  SheetResult result;
  result.pages = pages;
  if (files.size() == 1) {
    std::string error;
    if (!write_file_atomically(path, files.front().second, &error))
      throw std::runtime_error("cannot write '" + path + "': " + error);
    result.files.push_back(path);
    return result;
  }
  // The pages of one sheet go together: each is made beside its place first, and they replace the old pages only
  // once all are there, so a failure leaves the old pages as they were.
  std::vector<std::string> staged;
  for (const auto& [file, bytes] : files) {
    std::string error;
    if (!write_file_atomically(file + ".arwb-page", bytes, &error)) {
      for (const std::string& s : staged) std::remove(s.c_str());
      std::remove((file + ".arwb-page").c_str());
      throw std::runtime_error("cannot write '" + file + "': " + error);
    }
    staged.push_back(file + ".arwb-page");
  }
  for (size_t i = 0; i < files.size(); ++i) {
    if (std::rename(staged[i].c_str(), files[i].first.c_str()) != 0) {
      const std::string why = std::strerror(errno);
      for (size_t k = i; k < staged.size(); ++k) std::remove(staged[k].c_str());
      throw std::runtime_error("cannot write '" + files[i].first + "': " + why);
    }
    result.files.push_back(files[i].first);
  }
  return result;
}

}  // namespace sheet

namespace {

using sheet::fill_rect;
using sheet::format_mm;
using sheet::kFooterMm;
using sheet::set_font;
using sheet::text_width_mm;

constexpr double kPrintableWidthMm = kSheetPageWidthMm - 2 * kSheetMarginMm;
constexpr double kGridHeightMm = kSheetPageHeightMm - 2 * kSheetMarginMm - kFooterMm;
constexpr double kGapMm = 3.0;            // between cut outlines, so cutting one piece out spares its neighbours
constexpr double kCutLineMm = 0.2;
constexpr double kLabelPadMm = 1.0;       // each side of a label that is wider than the marker
// A little slack so that sizes which fit exactly are not rejected over rounding.
constexpr double kFitEpsMm = 1e-9;

// Label font size: a fixed fraction of the marker, kept readable on small markers and modest on large ones.
double label_font_mm(double marker_mm) { return std::clamp(0.06 * marker_mm, 1.8, 3.0); }
double label_height_mm(double font_mm) { return 1.6 * font_mm; }  // room for descenders and a little air

std::string marker_label(const Dictionary& dict, int id, double marker_mm) {
  return dict.name() + " id " + std::to_string(id) + ", " + format_mm(marker_mm) + " mm";
}

// The widest label on the sheet, measured with the font the sheet uses.
double widest_label_mm(const Dictionary& dict, const std::vector<int>& ids, double marker_mm) {
  SurfacePtr scratch(cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, nullptr), cairo_surface_destroy);
  CairoPtr cr(cairo_create(scratch.get()), cairo_destroy);
  cairo_scale(cr.get(), sheet::kPtPerMm, sheet::kPtPerMm);
  set_font(cr.get(), label_font_mm(marker_mm));
  double widest = 0;
  for (int id : ids) widest = std::max(widest, text_width_mm(cr.get(), marker_label(dict, id, marker_mm)));
  return widest;
}

// The measuring bar at the left, the page's caption at the right.
void draw_footer(cairo_t* cr, const std::string& caption) {
  const double baseline = kSheetPageHeightMm - kSheetMarginMm - 1.0;
  sheet::draw_measuring_bar(cr, kSheetMarginMm, baseline);
  set_font(cr, kFooterFontMm);
  cairo_move_to(cr, kSheetPageWidthMm - kSheetMarginMm - text_width_mm(cr, caption), baseline);
  cairo_show_text(cr, caption.c_str());
}

void draw_page(cairo_t* cr, const SheetLayout& lay, const Dictionary& dict, std::span<const int> ids,
               const std::string& caption) {
  cairo_save(cr);
  cairo_scale(cr, sheet::kPtPerMm, sheet::kPtPerMm);
  // An SVG page is transparent otherwise, which shows as black on a dark viewer background.
  fill_rect(cr, 0, 0, kSheetPageWidthMm, kSheetPageHeightMm, 1);

  const double grid_w = lay.cols * lay.box_w_mm + (lay.cols - 1) * kGapMm;
  const double gx = kSheetMarginMm + (kPrintableWidthMm - grid_w) / 2;  // centred across, top-aligned
  for (size_t i = 0; i < ids.size(); ++i) {
    const int r = static_cast<int>(i) / lay.cols, c = static_cast<int>(i) % lay.cols;
    const double bx = gx + c * (lay.box_w_mm + kGapMm);
    const double by = kSheetMarginMm + r * (lay.box_h_mm + kGapMm);

    // The stroke lies inside the piece, beyond the quiet zone, so the quiet zone stays a full cell of white.
    cairo_rectangle(cr, bx + kCutLineMm / 2, by + kCutLineMm / 2, lay.box_w_mm - kCutLineMm, lay.box_h_mm - kCutLineMm);
    cairo_set_source_rgb(cr, 0.75, 0.75, 0.75);
    cairo_set_line_width(cr, kCutLineMm);
    cairo_stroke(cr);

    const double mx = bx + (lay.box_w_mm - lay.marker_mm) / 2;
    const double my = by + kCutLineMm + lay.quiet_mm;
    sheet::draw_marker(cr, dict.bits(ids[i]), mx, my, lay.marker_mm);

    const std::string label = marker_label(dict, ids[i], lay.marker_mm);
    set_font(cr, lay.label_mm);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_move_to(cr, bx + (lay.box_w_mm - text_width_mm(cr, label)) / 2,
                  my + lay.marker_mm + lay.quiet_mm + 1.1 * lay.label_mm);
    cairo_show_text(cr, label.c_str());
  }
  draw_footer(cr, caption);
  cairo_restore(cr);
}

}  // namespace

SheetLayout sheet_layout(double marker_mm, int marker_size, double label_width_mm) {
  SheetLayout lay;
  lay.marker_mm = marker_mm;
  lay.cell_mm = marker_mm / (marker_size + 2);
  lay.quiet_mm = lay.cell_mm;
  lay.label_mm = label_font_mm(marker_mm);
  lay.box_w_mm = std::max(marker_mm + 2 * (lay.quiet_mm + kCutLineMm), label_width_mm + 2 * (kLabelPadMm + kCutLineMm));
  lay.box_h_mm = marker_mm + 2 * (lay.quiet_mm + kCutLineMm) + label_height_mm(lay.label_mm);
  lay.cols = static_cast<int>(std::floor((kPrintableWidthMm + kGapMm + kFitEpsMm) / (lay.box_w_mm + kGapMm)));
  lay.rows = static_cast<int>(std::floor((kGridHeightMm + kGapMm + kFitEpsMm) / (lay.box_h_mm + kGapMm)));
  return lay;
}

double max_sheet_marker_mm(int marker_size) {
  for (int tenths = static_cast<int>(kSheetMaxMarkerMm * 10); tenths >= static_cast<int>(kSheetMinMarkerMm * 10);
       --tenths)
    if (sheet_layout(tenths / 10.0, marker_size).fits()) return tenths / 10.0;
  return 0;
}

SheetResult write_marker_sheet(const Dictionary& dict, const std::vector<int>& ids, double marker_mm,
                               SheetFormat format, const std::string& path) {
  const SheetLayout lay = sheet_layout(marker_mm, dict.marker_size(), widest_label_mm(dict, ids, marker_mm));
  if (!lay.fits())
    throw std::invalid_argument("a " + format_mm(marker_mm) + " mm " + dict.name() + " marker does not fit on the page");
  const int pages = std::max(1, lay.pages(static_cast<int>(ids.size())));
  auto page_ids = [&](int page) {
    const size_t first = static_cast<size_t>(page * lay.per_page());
    const size_t n = std::min(static_cast<size_t>(lay.per_page()), ids.size() - std::min(first, ids.size()));
    return std::span<const int>(ids).subspan(std::min(first, ids.size()), n);
  };
  const std::string title = dict.name() + " markers, " + format_mm(marker_mm) + " mm";
  return sheet::write_pages(format, path, kSheetPageWidthMm, kSheetPageHeightMm, pages, title,
                            [&](cairo_t* cr, int page) {
                              const std::string caption = dict.name() + ", " + format_mm(marker_mm) + " mm, page " +
                                                          std::to_string(page + 1) + " of " + std::to_string(pages);
                              draw_page(cr, lay, dict, page_ids(page), caption);
                            });
}

}  // namespace arwb
