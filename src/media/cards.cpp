#include "media/cards.hpp"

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

// The longest prefix of valid UTF-8 `s` of at most `bytes` bytes that ends on a character boundary.
size_t utf8_prefix(std::string_view s, size_t bytes) {
  if (bytes >= s.size()) return s.size();
  while (bytes > 0 && (static_cast<unsigned char>(s[bytes]) & 0xC0) == 0x80) --bytes;
  return bytes;
}

constexpr std::string_view kEllipsis = "\u2026";
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

// `s` if it fits in `max_width` with the current font (and no ellipsis is forced), else its longest prefix
// that fits followed by "…".
std::string fit(cairo_t* cr, const std::string& s, double max_width, bool force_ellipsis = false) {
  if (!force_ellipsis && text_width(cr, s) <= max_width) return s;
  std::vector<size_t> ends{0};  // byte offsets where a character ends
  for (size_t i = 1; i <= s.size(); ++i)
    if (i == s.size() || (static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) ends.push_back(i);
  const auto with_ellipsis = [&](size_t k) { return s.substr(0, ends[k]) + std::string(kEllipsis); };
  size_t lo = 0, hi = ends.size() - 1;  // the answer is in [lo, hi]; prefix 0 ("…" alone) is the fallback
  while (lo < hi) {
    const size_t mid = (lo + hi + 1) / 2;
    if (text_width(cr, with_ellipsis(mid)) <= max_width) lo = mid;
    else hi = mid - 1;
  }
  return with_ellipsis(lo);
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

// Valid UTF-8 with U+FFFD for invalid bytes; tabs as spaces; other control characters dropped, except '\n'.
std::string clean_text(std::string_view in) {
  std::string out;
  out.reserve(in.size());
  size_t i = 0;
  while (i < in.size()) {
    const auto c = static_cast<unsigned char>(in[i]);
    if (c < 0x80) {
      if (c == '\n') out += '\n';
      else if (c == '\t') out += "    ";
      else if (c >= 0x20 && c != 0x7f) out += static_cast<char>(c);
      ++i;
      continue;
    }
    size_t len = 0;
    uint32_t cp = 0;
    if (c >= 0xC2 && c <= 0xDF) len = 2, cp = c & 0x1Fu;
    else if (c >= 0xE0 && c <= 0xEF) len = 3, cp = c & 0x0Fu;
    else if (c >= 0xF0 && c <= 0xF4) len = 4, cp = c & 0x07u;
    bool valid = len > 0 && i + len <= in.size();
    for (size_t k = 1; valid && k < len; ++k) {
      const auto cc = static_cast<unsigned char>(in[i + k]);
      valid = (cc & 0xC0) == 0x80;
      cp = cp << 6 | (cc & 0x3Fu);
    }
    // Overlong forms, surrogates and code points past U+10FFFF are invalid too.
    if (valid && ((len == 3 && cp < 0x800) || (len == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ||
                  (cp >= 0xD800 && cp <= 0xDFFF)))
      valid = false;
    if (!valid) {
      out += "\uFFFD";
      ++i;
      continue;
    }
    if (!(cp >= 0x80 && cp <= 0x9F)) out.append(in.substr(i, len));  // C1 controls dropped
    i += len;
  }
  return out;
}

}  // namespace


cv::Mat draw_text_card(const MediaSpec& spec) {
  const double font_px = std::isfinite(spec.font_px) ? std::clamp(spec.font_px, 4.0, 512.0) : 32.0;
  std::string text = clean_text(spec.text);
  if (text.size() > MediaStore::kMaxCardText)
    text = text.substr(0, utf8_prefix(text, MediaStore::kMaxCardText)) + std::string(kEllipsis);

  std::vector<std::string> lines;
  for (size_t start = 0;;) {
    const size_t nl = text.find('\n', start);
    lines.push_back(text.substr(start, nl == std::string::npos ? std::string::npos : nl - start));
    if (nl == std::string::npos) break;
    start = nl + 1;
  }

  // Measure on a 1x1 surface, then draw on one of the measured size.
  Canvas probe(1, 1);
  set_font(probe.cr(), font_px);
  cairo_font_extents_t fe;
  cairo_font_extents(probe.cr(), &fe);
  const int pad = static_cast<int>(std::ceil(font_px * 0.35));
  const int line_h = std::max(1, static_cast<int>(std::ceil(fe.height)));
  const int max_text = MediaStore::kMaxCardSide - 2 * pad;
  const size_t max_lines = static_cast<size_t>(std::max(1, max_text / line_h));
  bool cut_lines = false;
  if (lines.size() > max_lines) {
    lines.resize(max_lines);
    cut_lines = true;
  }
  double widest = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    const bool last_cut = cut_lines && i + 1 == lines.size();
    lines[i] = fit(probe.cr(), lines[i], max_text, last_cut);
    widest = std::max(widest, text_width(probe.cr(), lines[i]));
  }
  const int width = std::min(MediaStore::kMaxCardSide, static_cast<int>(std::ceil(widest)) + 2 * pad);
  const int height = std::min(MediaStore::kMaxCardSide, static_cast<int>(lines.size()) * line_h + 2 * pad);

  Canvas canvas(std::max(1, width), std::max(1, height));
  cairo_t* cr = canvas.cr();
  if (spec.background[3] > 0) {
    rounded_rect(cr, 0, 0, width, height, font_px * 0.3);
    set_bgra(cr, spec.background);
    cairo_fill(cr);
  }
  set_font(cr, font_px);
  set_bgra(cr, spec.colour);
  for (size_t i = 0; i < lines.size(); ++i) {
    cairo_move_to(cr, pad, pad + static_cast<double>(i) * line_h + fe.ascent);
    cairo_show_text(cr, lines[i].c_str());
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

  std::string title = clean_text(spec.title.substr(0, MediaStore::kMaxCardText));
  if (title.find_first_not_of(" \n") == std::string::npos) title = url_host(spec.url);
  if (title.empty()) title = clean_text(spec.url.substr(0, MediaStore::kMaxCardText));
  if (title.empty()) title = "(no link)";
  std::replace(title.begin(), title.end(), '\n', ' ');
  std::string url = clean_text(spec.url.substr(0, MediaStore::kMaxCardText));
  std::replace(url.begin(), url.end(), '\n', ' ');

  const double x = 190, max_w = W - x - 24;
  set_font(cr, 34, true);
  cairo_set_source_rgba(cr, 1, 1, 1, 1);
  cairo_move_to(cr, x, 82);
  cairo_show_text(cr, fit(cr, title, max_w).c_str());
  set_font(cr, 18);
  cairo_set_source_rgba(cr, 0.78, 0.8, 0.84, 1);
  cairo_move_to(cr, x, 122);
  cairo_show_text(cr, fit(cr, url, max_w).c_str());
  set_font(cr, 15);
  cairo_set_source_rgba(cr, 0.45, 0.7, 1.0, 1);
  cairo_move_to(cr, x, 164);
  cairo_show_text(cr, "click to open");
  return canvas.to_bgra();
}

}  // namespace arwb::media
