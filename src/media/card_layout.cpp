#include "media/card_layout.hpp"

#include "media/media_store.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace arwb::media {

namespace {

struct CardFontFace {
  int units_per_em, ascender, descender, height;
};
struct CardGlyph {
  uint16_t cp;
  int16_t advance, ink_left, ink_right;
};
#include "card_font.inc"

constexpr std::string_view kEllipsis = "\u2026";

const CardGlyph* glyph(uint32_t cp) {
  const auto* end = std::end(kCardGlyphs);
  const auto* g = std::lower_bound(std::begin(kCardGlyphs), end, cp,
                                   [](const CardGlyph& a, uint32_t c) { return a.cp < c; });
  if (g != end && g->cp == cp) return g;
  return cp == 0xFFFD ? &kCardGlyphs[0] : glyph(0xFFFD);
}

// The next code point of valid UTF-8 at s[i], i moved past it.
uint32_t next_code_point(std::string_view s, size_t& i) {
  const auto c = static_cast<unsigned char>(s[i]);
  size_t len = c < 0x80 ? 1 : c < 0xE0 ? 2 : c < 0xF0 ? 3 : 4;
  len = std::min(len, s.size() - i);
  uint32_t cp = len == 1 ? c : c & (0xFFu >> (len + 1));
  for (size_t k = 1; k < len; ++k) cp = cp << 6 | (static_cast<unsigned char>(s[i + k]) & 0x3Fu);
  i += len;
  return cp;
}

}  // namespace

double card_text_width(std::string_view utf8, double px) {
  // In font units, exactly (integers), then scaled: the same number wherever it is computed.
  long pen = 0, right = 0;
  for (size_t i = 0; i < utf8.size();) {
    const CardGlyph* g = glyph(next_code_point(utf8, i));
    right = std::max(right, pen + g->ink_right);
    pen += g->advance;
  }
  return double(std::max(pen, right)) * px / kCardFontFace.units_per_em;
}

double card_font_ascent(double px) { return double(kCardFontFace.ascender) * px / kCardFontFace.units_per_em; }
double card_font_height(double px) { return double(kCardFontFace.height) * px / kCardFontFace.units_per_em; }

std::string fit_line(const std::string& s, double max_width, bool force_ellipsis,
                     const std::function<double(const std::string&)>& width) {
  if (!force_ellipsis && width(s) <= max_width) return s;
  std::vector<size_t> ends{0};  // byte offsets where a character ends
  for (size_t i = 1; i <= s.size(); ++i)
    if (i == s.size() || (static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) ends.push_back(i);
  const auto with_ellipsis = [&](size_t k) { return s.substr(0, ends[k]) + std::string(kEllipsis); };
  size_t lo = 0, hi = ends.size() - 1;  // the answer is in [lo, hi]; prefix 0 ("…" alone) is the fallback
  while (lo < hi) {
    const size_t mid = (lo + hi + 1) / 2;
    if (width(with_ellipsis(mid)) <= max_width) lo = mid;
    else hi = mid - 1;
  }
  return with_ellipsis(lo);
}

size_t utf8_prefix(std::string_view s, size_t bytes) {
  if (bytes >= s.size()) return s.size();
  while (bytes > 0 && (static_cast<unsigned char>(s[bytes]) & 0xC0) == 0x80) --bytes;
  return bytes;
}

std::string clean_card_text(std::string_view in) {
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

CardLayout layout_text_card(const MediaSpec& spec) {
  CardLayout l;
  l.font_px = std::isfinite(spec.font_px) ? std::clamp(spec.font_px, 4.0, 512.0) : 32.0;
  std::string text = clean_card_text(spec.text);
  if (text.size() > MediaStore::kMaxCardText)
    text = text.substr(0, utf8_prefix(text, MediaStore::kMaxCardText)) + std::string(kEllipsis);
  for (size_t start = 0;;) {
    const size_t nl = text.find('\n', start);
    l.lines.push_back(text.substr(start, nl == std::string::npos ? std::string::npos : nl - start));
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
  l.pad = static_cast<int>(std::ceil(l.font_px * 0.35));
  l.line_h = std::max(1, static_cast<int>(std::ceil(card_font_height(l.font_px))));
  l.ascent = card_font_ascent(l.font_px);
  const int max_text = MediaStore::kMaxCardSide - 2 * l.pad;
  const size_t max_lines = static_cast<size_t>(std::max(1, max_text / l.line_h));
  bool cut_lines = false;
  if (l.lines.size() > max_lines) {
    l.lines.resize(max_lines);
    cut_lines = true;
  }
  const auto width = [&](const std::string& s) { return card_text_width(s, l.font_px); };
  double widest = 0;
  for (size_t i = 0; i < l.lines.size(); ++i) {
    l.lines[i] = fit_line(l.lines[i], max_text, cut_lines && i + 1 == l.lines.size(), width);
    widest = std::max(widest, width(l.lines[i]));
  }
  l.width = std::max(1, std::min(MediaStore::kMaxCardSide, static_cast<int>(std::ceil(widest)) + 2 * l.pad));
  l.height = std::max(1, std::min(MediaStore::kMaxCardSide, static_cast<int>(l.lines.size()) * l.line_h + 2 * l.pad));
  return l;
}

}  // namespace arwb::media
