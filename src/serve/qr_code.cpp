#include "serve/qr_code.hpp"

#include <qrencode.h>

#include <memory>

namespace arwb::serve {

Result<QrCode> make_qr(const std::string& text) {
  if (text.empty()) return fail("a QR code needs a text");
  std::unique_ptr<QRcode, decltype(&QRcode_free)> q(
      QRcode_encodeString(text.c_str(), 0, QR_ECLEVEL_M, QR_MODE_8, 1), &QRcode_free);
  if (!q) return fail("no QR code holds " + std::to_string(text.size()) + " characters");
  QrCode code;
  code.size = q->width;
  code.dark.resize(std::size_t(q->width) * q->width);
  // libqrencode's bit 0 of each byte is the module's colour; the other bits say what the module is part of.
  for (std::size_t i = 0; i < code.dark.size(); ++i) code.dark[i] = q->data[i] & 1;
  return code;
}

std::string qr_terminal_text(const QrCode& code, bool ansi) {
  constexpr int kQuiet = 4;
  const int side = code.size + 2 * kQuiet;
  std::string out;
  for (int y = 0; y < side; y += 2) {
    if (ansi) out += "\x1b[30;107m";   // black ink on bright white
    for (int x = 0; x < side; ++x) {
      const bool top = code.at(x - kQuiet, y - kQuiet), bottom = y + 1 < side && code.at(x - kQuiet, y + 1 - kQuiet);
      out += top && bottom ? "\u2588" : top ? "\u2580" : bottom ? "\u2584" : " ";
    }
    if (ansi) out += "\x1b[0m";
    out += '\n';
  }
  return out;
}

}  // namespace arwb::serve
