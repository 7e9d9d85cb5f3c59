#include "base/text.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace arwb {

std::vector<std::string> split_list(std::string_view list) {
  std::vector<std::string> out;
  for (size_t start = 0; start <= list.size();) {
    const size_t comma = std::min(list.find(',', start), list.size());
    if (comma > start) out.emplace_back(list.substr(start, comma - start));
    start = comma + 1;
  }
  return out;
}

int edit_distance(std::string_view a, std::string_view b) {
  std::vector<int> row(b.size() + 1);  // one row of the table, updated in place
  for (size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    int diag = row[0];
    row[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      const int up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}


namespace {

// The length of the UTF-8 sequence at the start of s (1..4), or 0 when it is not one: overlong forms,
// surrogates and values above U+10FFFF are not UTF-8 either.
size_t utf8_length(std::string_view s) {
  const auto b = [&](size_t i) { return static_cast<unsigned char>(s[i]); };
  const auto cont = [&](size_t i) { return i < s.size() && (b(i) & 0xC0) == 0x80; };
  const unsigned char c = b(0);
  if (c < 0x80) return 1;
  if (c >= 0xC2 && c <= 0xDF) return cont(1) ? 2 : 0;
  if (c >= 0xE0 && c <= 0xEF) {
    if (!cont(1) || !cont(2)) return 0;
    if (c == 0xE0 && b(1) < 0xA0) return 0;  // overlong
    if (c == 0xED && b(1) > 0x9F) return 0;  // UTF-16 surrogates
    return 3;
  }
  if (c >= 0xF0 && c <= 0xF4) {
    if (!cont(1) || !cont(2) || !cont(3)) return 0;
    if (c == 0xF0 && b(1) < 0x90) return 0;  // overlong
    if (c == 0xF4 && b(1) > 0x8F) return 0;  // above U+10FFFF
    return 4;
  }
  return 0;
}

const char* kHex = "0123456789ABCDEF";

void append_hex(std::string& out, const char* prefix, unsigned v, int digits) {
  out += prefix;
  for (int i = digits - 1; i >= 0; --i) out += kHex[(v >> (4 * i)) & 0xF];
}

}  // namespace

std::string utf8_replaced(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    const size_t n = utf8_length(text.substr(i));
    if (n == 0) {
      out += "\xEF\xBF\xBD";
      ++i;
    } else {
      out.append(text.substr(i, n));
      i += n;
    }
  }
  return out;
}

std::string human_bytes(std::uint64_t n) {
  char buf[32];
  if (n < 10'000) std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(n));
  else if (n < 10'000'000) std::snprintf(buf, sizeof buf, "%.1f KiB", double(n) / 1024);
  else std::snprintf(buf, sizeof buf, "%.1f MiB", double(n) / (1024 * 1024));
  return buf;
}

std::string printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const size_t n = utf8_length(text.substr(i));
    if (n == 0) {
      append_hex(out, "\\x", c, 2);
      ++i;
    } else if (n == 1 && (c < 0x20 || c == 0x7F)) {
      if (c == '\n') out += "\\n";
      else if (c == '\r') out += "\\r";
      else if (c == '\t') out += "\\t";
      else append_hex(out, "\\x", c, 2);
      ++i;
    } else if (n == 2 && c == 0xC2 && static_cast<unsigned char>(text[i + 1]) < 0xA0) {
      // C1 controls: some terminals take U+009B as the start of an escape sequence, as ESC [.
      append_hex(out, "\\u", static_cast<unsigned char>(text[i + 1]), 4);
      i += 2;
    } else {
      out.append(text.substr(i, n));
      i += n;
    }
  }
  return out;
}

Status check_utf8_text(std::string_view text, const std::string& name) {
  const auto starts = [&](std::string_view bom) { return text.substr(0, bom.size()) == bom; };
  using namespace std::string_view_literals;
  if (starts("\xFF\xFE\0\0"sv) || starts("\0\0\xFE\xFF"sv)) return fail(name + ": UTF-32 text; save it as UTF-8");
  if (starts("\xFF\xFE"sv) || starts("\xFE\xFF"sv)) return fail(name + ": UTF-16 text; save it as UTF-8");
  // UTF-16 without a byte order mark: ASCII text has a NUL in every other byte. Judged on the start of the file,
  // where a few NULs in a UTF-8 file would not make a pattern.
  const size_t probe = std::min<size_t>(text.size(), 512) & ~size_t(1);
  if (probe >= 4) {
    size_t even = 0, odd = 0;
    for (size_t i = 0; i < probe; i += 2) {
      even += text[i] == '\0';
      odd += text[i + 1] == '\0';
    }
    const size_t half = probe / 2;
    if ((odd * 4 >= half * 3 && even * 4 < half) || (even * 4 >= half * 3 && odd * 4 < half))
      return fail(name + ": UTF-16 text; save it as UTF-8");
  }
  int line = 1, col = 1;
  for (size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    const size_t n = utf8_length(text.substr(i));
    const std::string at = name + ":" + std::to_string(line) + ":" + std::to_string(col) + ": ";
    if (n == 0) {
      std::string byte;
      append_hex(byte, "0x", c, 2);
      return fail(at + "not UTF-8 (byte " + byte + "); save it as UTF-8");
    }
    if (c == 0) return fail(at + "a NUL byte; not a text file");
    if (c == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
    i += n;
  }
  return {};
}

}  // namespace arwb
