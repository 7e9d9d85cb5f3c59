// Numbers cut to a few decimals: as text for people (tables, messages), and as values for JSON (nlohmann writes
// the shortest text that reads back the same, so a rounded value stays short: 12.346, not 12.345678901).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

namespace arwb {

// v rounded to `decimals` decimals; -0 becomes 0. NaN and infinities stay (nlohmann writes them as null, the
// JSON for "no number").
inline double round_decimals(double v, int decimals) {
  if (!std::isfinite(v)) return v;
  const double scale = std::pow(10.0, decimals);
  if (std::fabs(v) * scale >= 9e15) return v;   // beyond what a double's integers hold: nothing to round
  const double r = std::round(v * scale) / scale;
  return r == 0 ? 0.0 : r;
}

// v with exactly `decimals` decimals, as printf's %.*f ("25.00", "0.5"): for figures a message lines up or compares.
inline std::string fixed_text(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// v as printf's %g (six significant digits: "0.5", "1e-06", "1.5e+07"); "nan" for every NaN (x86 makes 0/0 a
// negative NaN, which %g prints as "-nan").
inline std::string general_text(double v) {
  if (std::isnan(v)) return "nan";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// v with at most `decimals` decimals and no trailing zeros ("2.5", "3", never "-0"); "nan", "inf" or "-inf".
inline std::string decimals_text(double v, int decimals) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

}  // namespace arwb
