// A text as a QR code (libqrencode, error correction level M), and that code as terminal text: how `arwb serve`
// and File > Export... show a phone the player's address.
#pragma once

#include "base/result.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace arwb::serve {

struct QrCode {
  int size = 0;                        // modules a side, without the quiet zone
  std::vector<std::uint8_t> dark;      // size * size, row by row: 1 for a dark module
  bool at(int x, int y) const { return x >= 0 && y >= 0 && x < size && y < size && dark[y * size + x] != 0; }
};

// Fails, saying why, for an empty text or one too long for any QR code.
Result<QrCode> make_qr(const std::string& text);

// The code with its quiet zone of 4 modules, two module rows per line in Unicode half blocks (U+2580, U+2584,
// U+2588), dark modules as ink: square modules in a terminal's cells. `ansi`: in black on white whatever the
// terminal's colours (escape codes per line), for a terminal; without, for a file or a page with a light background.
std::string qr_terminal_text(const QrCode& code, bool ansi);

}  // namespace arwb::serve
