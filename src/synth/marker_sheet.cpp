// Printable marker sheets: layout of A4 pages and drawing with cairo. See marker_sheet.hpp.
#include "synth/marker_sheet.hpp"

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

constexpr double kPtPerMm = 72.0 / 25.4;  // cairo's PDF and SVG surfaces measure in points
constexpr double kPrintableWidthMm = kSheetPageWidthMm - 2 * kSheetMarginMm;
constexpr double kFooterMm = 14.0;        // the measuring bar and its text, at the bottom inside the margin
constexpr double kGridHeightMm = kSheetPageHeightMm - 2 * kSheetMarginMm - kFooterMm;
constexpr double kGapMm = 3.0;            // between cut outlines, so cutting one piece out spares its neighbours
constexpr double kCutLineMm = 0.2;
constexpr double kLabelPadMm = 1.0;       // each side of a label that is wider than the marker
constexpr double kFooterFontMm = 2.6;
constexpr double kBarMm = 100.0;
// A little slack so that sizes which fit exactly are not rejected over rounding.
constexpr double kEpsMm = 1e-9;

// Label font size: a fixed fraction of the marker, kept readable on small markers and modest on large ones.
double label_font_mm(double marker_mm) { return std::clamp(0.06 * marker_mm, 1.8, 3.0); }
double label_height_mm(double font_mm) { return 1.6 * font_mm; }  // room for descenders and a little air

std::string format_mm(double mm) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", mm);
  return buf;
}

std::string marker_label(const Dictionary& dict, int id, double marker_mm) {
  return dict.name() + " id " + std::to_string(id) + ", " + format_mm(marker_mm) + " mm";
}

using CairoPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;
using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;

// Text metrics must not be rounded to device pixels: the layout is in millimetres on a vector surface.
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

// The widest label on the sheet, measured with the font the sheet uses.
double widest_label_mm(const Dictionary& dict, const std::vector<int>& ids, double marker_mm) {
  SurfacePtr scratch(cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, nullptr), cairo_surface_destroy);
  CairoPtr cr(cairo_create(scratch.get()), cairo_destroy);
  cairo_scale(cr.get(), kPtPerMm, kPtPerMm);
  set_font(cr.get(), label_font_mm(marker_mm));
  double widest = 0;
  for (int id : ids) widest = std::max(widest, text_width_mm(cr.get(), marker_label(dict, id, marker_mm)));
  return widest;
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

// A 100 mm bar with ticks every 10 mm (longer every 50 mm) and the instruction to measure it. The end ticks stay
// inside the bar so that the whole figure is exactly 100 mm wide.
void draw_footer(cairo_t* cr, const std::string& caption) {
  const double x0 = kSheetMarginMm;
  const double baseline = kSheetPageHeightMm - kSheetMarginMm - 1.0;
  const double bar_top = baseline - 7.5;
  const double bar_h = 1.2;
  fill_rect(cr, x0, bar_top, kBarMm, bar_h, 0);
  constexpr double tick_w = 0.25;
  for (int k = 0; k <= 10; ++k) {
    const double len = k % 5 == 0 ? 3.0 : 1.8;
    const double tx = std::clamp(x0 + 10.0 * k - tick_w / 2, x0, x0 + kBarMm - tick_w);
    fill_rect(cr, tx, bar_top - len, tick_w, len, 0);
  }
  set_font(cr, kFooterFontMm);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_move_to(cr, x0, baseline);
  cairo_show_text(cr, "this bar must measure 100 mm (print at actual size, not fit to page)");
  cairo_move_to(cr, kSheetPageWidthMm - kSheetMarginMm - text_width_mm(cr, caption), baseline);
  cairo_show_text(cr, caption.c_str());
}

void draw_page(cairo_t* cr, const SheetLayout& lay, const Dictionary& dict, std::span<const int> ids,
               const std::string& caption) {
  cairo_save(cr);
  cairo_scale(cr, kPtPerMm, kPtPerMm);
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
    draw_marker(cr, dict.bits(ids[i]), mx, my, lay.marker_mm);

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

// A file cairo writes through, so that a failure can be reported with the system's reason.
struct FileSink {
  std::string path;
  std::FILE* file = nullptr;
  int error = 0;

  static cairo_status_t write(void* closure, const unsigned char* data, unsigned int length) {
    auto* self = static_cast<FileSink*>(closure);
    if (std::fwrite(data, 1, length, self->file) != length) {
      self->error = errno;
      return CAIRO_STATUS_WRITE_ERROR;
    }
    return CAIRO_STATUS_SUCCESS;
  }

  explicit FileSink(std::string p) : path(std::move(p)) {
    file = std::fopen(path.c_str(), "wb");
    if (!file) throw std::runtime_error("cannot write '" + path + "': " + std::strerror(errno));
  }
  FileSink(const FileSink&) = delete;
  FileSink& operator=(const FileSink&) = delete;
  ~FileSink() {
    if (file) {
      std::fclose(file);
      std::remove(path.c_str());
    }
  }

  // Called once cairo has finished the surface; throws if anything went wrong on the way.
  void close(cairo_status_t status) {
    std::FILE* f = std::exchange(file, nullptr);
    const bool closed = std::fclose(f) == 0;
    if (!closed && error == 0) error = errno;
    if (status == CAIRO_STATUS_SUCCESS && closed && error == 0) return;
    std::remove(path.c_str());
    const std::string why = error != 0 ? std::strerror(error) : cairo_status_to_string(status);
    throw std::runtime_error("cannot write '" + path + "': " + why);
  }
};

void finish(cairo_surface_t* surface, FileSink& sink) {
  cairo_surface_finish(surface);
  sink.close(cairo_surface_status(surface));
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

}  // namespace

SheetLayout sheet_layout(double marker_mm, int marker_size, double label_width_mm) {
  SheetLayout lay;
  lay.marker_mm = marker_mm;
  lay.cell_mm = marker_mm / (marker_size + 2);
  lay.quiet_mm = lay.cell_mm;
  lay.label_mm = label_font_mm(marker_mm);
  lay.box_w_mm = std::max(marker_mm + 2 * (lay.quiet_mm + kCutLineMm), label_width_mm + 2 * (kLabelPadMm + kCutLineMm));
  lay.box_h_mm = marker_mm + 2 * (lay.quiet_mm + kCutLineMm) + label_height_mm(lay.label_mm);
  lay.cols = static_cast<int>(std::floor((kPrintableWidthMm + kGapMm + kEpsMm) / (lay.box_w_mm + kGapMm)));
  lay.rows = static_cast<int>(std::floor((kGridHeightMm + kGapMm + kEpsMm) / (lay.box_h_mm + kGapMm)));
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
  const int count = static_cast<int>(ids.size());
  SheetResult result;
  result.pages = std::max(1, lay.pages(count));
  const double w_pt = kSheetPageWidthMm * kPtPerMm, h_pt = kSheetPageHeightMm * kPtPerMm;

  auto page_ids = [&](int page) {
    const size_t first = static_cast<size_t>(page * lay.per_page());
    const size_t n = std::min(static_cast<size_t>(lay.per_page()), ids.size() - std::min(first, ids.size()));
    return std::span<const int>(ids).subspan(std::min(first, ids.size()), n);
  };
  auto caption = [&](int page) {
    return dict.name() + ", " + format_mm(marker_mm) + " mm, page " + std::to_string(page + 1) + " of " +
           std::to_string(result.pages);
  };

  if (format == SheetFormat::pdf) {
    FileSink sink(path);
    SurfacePtr surface(cairo_pdf_surface_create_for_stream(&FileSink::write, &sink, w_pt, h_pt),
                       cairo_surface_destroy);
    const std::string title = dict.name() + " markers, " + format_mm(marker_mm) + " mm";
    cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_TITLE, title.c_str());
    cairo_pdf_surface_set_metadata(surface.get(), CAIRO_PDF_METADATA_CREATOR, "arwb markers");
    CairoPtr cr(cairo_create(surface.get()), cairo_destroy);
    for (int page = 0; page < result.pages; ++page) {
      draw_page(cr.get(), lay, dict, page_ids(page), caption(page));
      cairo_show_page(cr.get());
    }
    cr.reset();
    finish(surface.get(), sink);
    result.files.push_back(path);
    return result;
  }

  // SVG 1.1 keeps only the last page of a multi-page cairo surface, hence one surface and file per page.
  for (int page = 0; page < result.pages; ++page) {
    const std::string file = svg_page_path(path, page + 1);
    FileSink sink(file);
    SurfacePtr surface(cairo_svg_surface_create_for_stream(&FileSink::write, &sink, w_pt, h_pt),
                       cairo_surface_destroy);
    // Units on width and height make viewers and printers honour the physical size (the default is unitless).
    cairo_svg_surface_set_document_unit(surface.get(), CAIRO_SVG_UNIT_PT);
    CairoPtr cr(cairo_create(surface.get()), cairo_destroy);
    draw_page(cr.get(), lay, dict, page_ids(page), caption(page));
    cr.reset();
    finish(surface.get(), sink);
    result.files.push_back(file);
  }
  return result;
}

}  // namespace arwb
