#include "media/cards.hpp"

#include "media/card_layout.hpp"
#include "media/media_path.hpp"
#include "media/media_store.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

namespace arwb::media {

namespace {

constexpr double kPi = std::numbers::pi;

// RAII for a cairo image surface and its context.
class Canvas {
 public:
  Canvas(int width, int height)
      : surface_(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height)), cr_(cairo_create(surface_)) {}
  ~Canvas() {
    cairo_destroy(cr_);
    cairo_surface_destroy(surface_);
  }
  Canvas(const Canvas&) = delete;
  Canvas& operator=(const Canvas&) = delete;
  cairo_t* cr() const { return cr_; }
  bool ok() const {
    return cairo_surface_status(surface_) == CAIRO_STATUS_SUCCESS && cairo_status(cr_) == CAIRO_STATUS_SUCCESS;
  }

  // The pixels as BGRA with straight alpha. Cairo's ARGB32 is premultiplied, one native-endian 32-bit word a
  // pixel (alpha in the top byte), so it is read by words, whatever the byte order.
  cv::Mat to_bgra() const {
    if (!ok()) return cv::Mat(1, 1, CV_8UC4, cv::Scalar::all(0));  // out of memory: a transparent dot
    cairo_surface_flush(surface_);
    const int w = cairo_image_surface_get_width(surface_), h = cairo_image_surface_get_height(surface_);
    const int stride = cairo_image_surface_get_stride(surface_);
    const unsigned char* data = cairo_image_surface_get_data(surface_);
    cv::Mat out(h, w, CV_8UC4);
    for (int y = 0; y < h; ++y) {
      const auto* src = reinterpret_cast<const uint32_t*>(data + static_cast<ptrdiff_t>(y) * stride);
      auto* dst = out.ptr<cv::Vec4b>(y);
      for (int x = 0; x < w; ++x) {
        const uint32_t px = src[x];
        const uint32_t a = px >> 24;
        const auto un = [a](uint32_t c) {
          return static_cast<uchar>(a == 0 ? 0 : std::min(255u, (c * 255 + a / 2) / a));
        };
        dst[x] = cv::Vec4b(un(px & 0xFF), un(px >> 8 & 0xFF), un(px >> 16 & 0xFF), static_cast<uchar>(a));
      }
    }
    return out;
  }

 private:
  cairo_surface_t* surface_;
  cairo_t* cr_;
};

void set_font(cairo_t* cr, double px, bool bold = false) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, px);
}

double text_width(cairo_t* cr, const std::string& s) {
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  return std::max(e.x_advance, e.x_bearing + e.width);
}

void rounded_rect(cairo_t* cr, double x, double y, double w, double h, double r) {
  r = std::min({r, w / 2, h / 2});
  cairo_new_sub_path(cr);
  cairo_arc(cr, x + w - r, y + r, r, -kPi / 2, 0);
  cairo_arc(cr, x + w - r, y + h - r, r, 0, kPi / 2);
  cairo_arc(cr, x + r, y + h - r, r, kPi / 2, kPi);
  cairo_arc(cr, x + r, y + r, r, kPi, 3 * kPi / 2);
  cairo_close_path(cr);
}

double channel(double v) { return std::isfinite(v) ? std::clamp(v, 0.0, 255.0) / 255.0 : 1.0; }

void set_bgra(cairo_t* cr, const cv::Scalar& c) {
  cairo_set_source_rgba(cr, channel(c[2]), channel(c[1]), channel(c[0]), channel(c[3]));
}

}  // namespace


cv::Mat draw_text_card(const MediaSpec& spec) {
  // The layout (card_layout.hpp) is measured with the font's unhinted metrics: drawn with hinting and hinted
  // metrics off, the glyphs land where it measured them.
  const CardLayout l = layout_text_card(spec);
  Canvas canvas(l.width, l.height);
  cairo_t* cr = canvas.cr();
  if (spec.background[3] > 0) {
    rounded_rect(cr, 0, 0, l.width, l.height, l.font_px * 0.3);
    set_bgra(cr, spec.background);
    cairo_fill(cr);
  }
  cairo_font_options_t* options = cairo_font_options_create();
  cairo_font_options_set_hint_metrics(options, CAIRO_HINT_METRICS_OFF);
  cairo_font_options_set_hint_style(options, CAIRO_HINT_STYLE_NONE);
  cairo_set_font_options(cr, options);
  cairo_font_options_destroy(options);
  set_font(cr, l.font_px);
  set_bgra(cr, spec.colour);
  for (size_t i = 0; i < l.lines.size(); ++i) {
    cairo_move_to(cr, l.pad, l.pad + static_cast<double>(i) * l.line_h + l.ascent);
    cairo_show_text(cr, l.lines[i].c_str());
  }
  return canvas.to_bgra();
}

cv::Mat draw_web_card(const MediaSpec& spec) {
  constexpr int W = MediaStore::kWebCardWidth, H = MediaStore::kWebCardHeight;
  Canvas canvas(W, H);
  cairo_t* cr = canvas.cr();
  rounded_rect(cr, 1, 1, W - 2, H - 2, 16);
  cairo_set_source_rgba(cr, 0.13, 0.14, 0.16, 0.92);
  cairo_fill_preserve(cr);
  cairo_set_source_rgba(cr, 0.35, 0.6, 0.95, 1.0);
  cairo_set_line_width(cr, 2);
  cairo_stroke(cr);

  // The globe: an outline, two meridians and three parallels.
  const double cx = 100, cy = H / 2.0, r = 62;
  cairo_set_line_width(cr, 4);
  cairo_set_source_rgba(cr, 0.55, 0.8, 1.0, 1.0);
  cairo_arc(cr, cx, cy, r, 0, 2 * kPi);
  cairo_stroke(cr);
  cairo_set_line_width(cr, 3);
  cairo_save(cr);
  cairo_translate(cr, cx, cy);
  cairo_scale(cr, 0.45, 1.0);
  cairo_arc(cr, 0, 0, r, 0, 2 * kPi);
  cairo_restore(cr);
  cairo_stroke(cr);
  cairo_move_to(cr, cx, cy - r);
  cairo_line_to(cr, cx, cy + r);
  for (const double dy : {-r / 2, 0.0, r / 2}) {
    const double half = std::sqrt(r * r - dy * dy);
    cairo_move_to(cr, cx - half, cy + dy);
    cairo_line_to(cr, cx + half, cy + dy);
  }
  cairo_stroke(cr);

  std::string title = clean_card_text(spec.title.substr(0, MediaStore::kMaxCardText));
  if (title.find_first_not_of(" \n") == std::string::npos) title = url_host(spec.url);
  if (title.empty()) title = clean_card_text(spec.url.substr(0, MediaStore::kMaxCardText));
  if (title.empty()) title = "(no link)";
  std::replace(title.begin(), title.end(), '\n', ' ');
  std::string url = clean_card_text(spec.url.substr(0, MediaStore::kMaxCardText));
  std::replace(url.begin(), url.end(), '\n', ' ');

  const double x = 190, max_w = W - x - 24;
  const auto width = [cr](const std::string& t) { return text_width(cr, t); };
  set_font(cr, 34, true);
  cairo_set_source_rgba(cr, 1, 1, 1, 1);
  cairo_move_to(cr, x, 82);
  cairo_show_text(cr, fit_line(title, max_w, false, width).c_str());
  set_font(cr, 18);
  cairo_set_source_rgba(cr, 0.78, 0.8, 0.84, 1);
  cairo_move_to(cr, x, 122);
  cairo_show_text(cr, fit_line(url, max_w, false, width).c_str());
  set_font(cr, 15);
  cairo_set_source_rgba(cr, 0.45, 0.7, 1.0, 1);
  cairo_move_to(cr, x, 164);
  cairo_show_text(cr, "click to open");
  return canvas.to_bgra();
}

}  // namespace arwb::media
