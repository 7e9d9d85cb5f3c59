#include "lab/report.hpp"

#include "lab/stats.hpp"
#include "base/files.hpp"

#include <plplot.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <iterator>
#include <map>
#include <mutex>
#include <sstream>

namespace arwb::lab {
namespace {

namespace fs = std::filesystem;

// PLplot keeps its streams, its driver table and the current stream in globals: two reports drawn at once from
// two threads would draw into each other's pages. Every use of PLplot here holds this lock.
std::mutex plplot_mutex;

// Frames pooled over cells: P_Rec of the pool and its 95 % Wilson interval, all in percent.
struct Pool {
  int frames = 0, detected = 0;
  void add(const DetectorTally& t) {
    frames += t.frames;
    detected += t.detected;
  }
  double p_rec() const { return frames ? 100.0 * detected / frames : 0; }
  std::pair<double, double> interval() const {
    const auto [lo, hi] = wilson_interval(detected, frames);
    return {100 * lo, 100 * hi};
  }
};

// One curve's points for a detector, x ascending; points without frames are left out (nothing was measured).
struct Curve {
  std::vector<double> x, p, lo, hi;
};

// Pools every detector's tallies by a key of the cell (its side in pixels, its light), x ascending.
template <typename Key>
std::vector<Curve> curves_by(const LabResults& r, Key key) {
  std::vector<Curve> out(r.options.detectors.size());
  for (size_t d = 0; d < out.size(); ++d) {
    std::map<double, Pool> pools;
    for (const CellResult& c : r.cells)
      if (d < c.detectors.size() && !c.cell.curve) pools[key(c)].add(c.detectors[d]);
    for (const auto& [x, pool] : pools) {
      if (pool.frames == 0) continue;
      const auto [lo, hi] = pool.interval();
      out[d].x.push_back(x);
      out[d].p.push_back(pool.p_rec());
      out[d].lo.push_back(lo);
      out[d].hi.push_back(hi);
    }
  }
  return out;
}

// Frames pooled into bins of `width` by a value per frame, P_Rec per bin; a point sits at the mean value of its
// frames (not the bin's middle: a plan of fixed tilts 0, 30, 60 gives its points at 0, 30 and 60).
struct Bins {
  struct Bin {
    Pool pool;
    double sum = 0;
  };
  double width;
  std::map<long, Bin> bins;
  void add(double x, bool detected) {
    Bin& b = bins[std::lround(std::floor(x / width))];
    ++b.pool.frames;
    b.pool.detected += detected;
    b.sum += x;
  }
  Curve curve() const {
    Curve c;
    for (const auto& [k, b] : bins) {
      const auto [lo, hi] = b.pool.interval();
      c.x.push_back(b.sum / b.pool.frames);
      c.p.push_back(b.pool.p_rec());
      c.lo.push_back(lo);
      c.hi.push_back(hi);
    }
    return c;
  }
};

// A bin width for values spread over `span`: 1, 2 or 5 times a power of ten, about eight bins over the span.
double bin_width(double span) {
  if (!(span > 0)) return 1;
  const double raw = span / 8, ten = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0})
    if (raw <= m * ten) return m * ten;
  return 10 * ten;
}

// P_Rec against the marker's tilt, frame by frame: each frame with the marker in view goes to the bin of its own
// tilt (10 degrees wide), whatever its cell.
std::vector<Curve> curves_by_tilt(const LabResults& r) {
  std::vector<Curve> out(r.options.detectors.size());
  for (size_t d = 0; d < out.size(); ++d) {
    Bins bins{10, {}};
    for (const CellResult& c : r.cells) {
      if (d >= c.detectors.size() || c.cell.curve) continue;
      const std::string& marks = c.detectors[d].marks;
      for (size_t k = 0; k < c.tilts_deg.size() && k < marks.size(); ++k) {
        const char m = marks[k];
        if (c.tilts_deg[k] < 0 || (m != mark::detected && m != mark::missed && m != mark::wrong_id)) continue;
        bins.add(c.tilts_deg[k], m == mark::detected);
      }
    }
    out[d] = bins.curve();
  }
  return out;
}

// P_Rec against the cell's whole blur (CellResult::blur_px), cells pooled into bins of a width fit for the
// plan's spread of blurs.
std::vector<Curve> curves_by_blur(const LabResults& r) {
  double lo = INFINITY, hi = -INFINITY;
  for (const CellResult& c : r.cells)
    if (!c.cell.curve) lo = std::min(lo, c.blur_px), hi = std::max(hi, c.blur_px);
  const double width = std::isfinite(lo) ? std::max(0.1, bin_width(hi - lo)) : 1;
  std::vector<Curve> out(r.options.detectors.size());
  for (size_t d = 0; d < out.size(); ++d) {
    Bins bins{width, {}};
    for (const CellResult& c : r.cells) {
      if (d >= c.detectors.size() || c.cell.curve) continue;
      const DetectorTally& t = c.detectors[d];
      Bins::Bin& b = bins.bins[std::lround(std::floor(c.blur_px / width))];
      b.pool.add(t);
      b.sum += c.blur_px * t.frames;
    }
    for (auto it = bins.bins.begin(); it != bins.bins.end();)   // bins whose cells had no frame in view
      it = it->second.pool.frames == 0 ? bins.bins.erase(it) : std::next(it);
    out[d] = bins.curve();
  }
  return out;
}

// P_Rec against one added factor (kBlurCurve, kNoiseCurve) at the plan's curve_at: the grid's cell there at 0,
// then the curve's cells, all on the same frames.
std::vector<Curve> curves_at_point(const LabResults& r, int curve) {
  std::vector<Curve> out(r.options.detectors.size());
  const long base = r.plan.curve_base();
  if (base < 0 || size_t(base) >= r.cells.size()) return out;
  for (size_t d = 0; d < out.size(); ++d)
    for (size_t i = size_t(base); i < r.cells.size(); i = i == size_t(base) ? r.plan.grid_count() : i + 1) {
      const CellResult& c = r.cells[i];
      if (d >= c.detectors.size() || (i != size_t(base) && c.cell.curve != curve) || c.detectors[d].frames == 0)
        continue;
      const Pool pool{c.detectors[d].frames, c.detectors[d].detected};
      const auto [lo, hi] = pool.interval();
      out[d].x.push_back(curve == kBlurCurve ? c.cell.blur_px : c.cell.noise);
      out[d].p.push_back(pool.p_rec());
      out[d].lo.push_back(lo);
      out[d].hi.push_back(hi);
    }
  return out;
}

// PLplot reads '#' as the start of an escape sequence ("#u" superscript): a literal one is "##".
std::string plain(const std::string& s) {
  std::string out;
  for (char ch : s) {
    out += ch;
    if (ch == '#') out += '#';
  }
  return out;
}

std::string number(double v, int decimals = -1) {
  char buf[64];
  if (decimals < 0)
    std::snprintf(buf, sizeof buf, "%g", v);
  else
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string joined(const std::vector<double>& v, const std::string& unit) {
  std::ostringstream s;
  for (size_t i = 0; i < v.size(); ++i) s << (i ? ", " : "") << number(v[i]);
  s << " " << unit;
  return s.str();
}

// A detector's name as part of a file name: anything but letters, digits, '-' and '_' becomes '_'.
std::string file_safe(const std::string& name) {
  std::string s = name.empty() ? "detector" : name;
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '-' && ch != '_') ch = '_';
  return s;
}

// Colour map 0: white paper, black ink, a light grey for the grid, then one colour per detector (distinct in
// grey too, for printed reports).
constexpr int kInk = 1, kGrid = 2, kFirstDetectorColour = 3;
void set_colours() {
  const PLINT r[] = {255, 0, 200, 31, 230, 44, 214, 148, 140, 23, 127};
  const PLINT g[] = {255, 0, 200, 119, 120, 160, 39, 103, 86, 190, 127};
  const PLINT b[] = {255, 0, 200, 180, 10, 44, 40, 189, 75, 207, 127};
  plscmap0(r, g, b, PLINT(std::size(r)));
  // Colour map 1 for the heatmaps: red (no recognition) through pale yellow to green (every frame); light
  // enough everywhere for black numbers on top.
  const PLFLT at[] = {0, 0.5, 1}, red[] = {0.96, 1.0, 0.45}, green[] = {0.43, 0.92, 0.80}, blue[] = {0.26, 0.55, 0.45};
  plscmap1l(1, 3, at, red, green, blue, nullptr);
}
int detector_colour(size_t d) { return kFirstDetectorColour + int(d % 8); }
// The points' symbol, a filled circle (UTF-8: the cairo devices draw text with the system's fonts).
constexpr const char* kPointSymbol = "\u25cf";

// A legend of detector names, lines and symbols, to the right of the viewport.
void legend(const LabResults& r) {
  const auto n = PLINT(r.options.detectors.size());
  std::vector<std::string> names;
  for (const std::string& d : r.options.detectors) names.push_back(plain(d));
  std::vector<const char*> text, symbols;
  std::vector<PLINT> opts, colours, styles, symbol_numbers;
  std::vector<PLFLT> widths, symbol_scales;
  for (PLINT i = 0; i < n; ++i) {
    text.push_back(names[size_t(i)].c_str());
    symbols.push_back(kPointSymbol);
    opts.push_back(PL_LEGEND_LINE | PL_LEGEND_SYMBOL);
    colours.push_back(detector_colour(size_t(i)));
    styles.push_back(1);
    symbol_numbers.push_back(1);
    widths.push_back(2);
    symbol_scales.push_back(0.7);
  }
  PLFLT width = 0, height = 0;
  pllegend(&width, &height, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX,
           PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, 0.03, 0, 0.08, 0, kInk, 1, 0, 1, n,
           opts.data(), 1.0, 0.85, 2.0, 0, colours.data(), text.data(), nullptr, nullptr, nullptr, nullptr,
           colours.data(), styles.data(), widths.data(), colours.data(), symbol_scales.data(),
           symbol_numbers.data(), symbols.data());
}

// P_Rec (0..100 with room above) against `curves`' x, a line with points and error bars per detector.
void draw_curves(const LabResults& r, const std::vector<Curve>& curves, const std::string& xlabel,
                 const std::string& title) {
  double xmin = INFINITY, xmax = -INFINITY;
  for (const Curve& c : curves)
    for (double x : c.x) xmin = std::min(xmin, x), xmax = std::max(xmax, x);
  if (!std::isfinite(xmin)) xmin = 0, xmax = 1;   // no frames at all: empty axes, still a page
  const double span = xmax > xmin ? xmax - xmin : std::max(1.0, std::abs(xmin) * 0.2);
  const double pad = 0.06 * span;
  pladv(0);
  plvpor(0.1, 0.7, 0.13, 0.88);
  plwind(xmin - pad, xmax + pad, 0, 105);
  plcol0(kGrid);
  plwidth(0.5);
  plbox("g", 0, 0, "g", 20, 0);
  plcol0(kInk);
  plwidth(1);
  plbox("bcnst", 0, 0, "bcnstv", 20, 2);
  pllab(xlabel.c_str(), "P#dRec#u (%)", "");
  plmtex("t", 2.2, 0.5, 0.5, title.c_str());
  plschr(0, 0.8);
  plmtex("t", 0.8, 0.5, 0.5, "error bars: 95 % Wilson intervals");
  plschr(0, 1);
  // Detectors' points sit side by side (a small offset each) so their error bars do not hide one another.
  const double nudge = 0.008 * (xmax - xmin + 2 * pad);
  for (size_t d = 0; d < curves.size(); ++d) {
    const Curve& c = curves[d];
    if (c.x.empty()) continue;
    std::vector<double> x = c.x;
    for (double& v : x) v += nudge * (double(d) - 0.5 * double(curves.size() - 1));
    const auto n = PLINT(x.size());
    plcol0(detector_colour(d));
    plwidth(2);
    plline(n, x.data(), c.p.data());
    plwidth(1);
    plerry(n, x.data(), c.lo.data(), c.hi.data());
    plssym(0, 0.7);
    plstring(n, x.data(), c.p.data(), kPointSymbol);
    plssym(0, 1);
  }
  plcol0(kInk);
  legend(r);
}

void draw_recall_by_side(const LabResults& r) {
  // Cells whose marker spans the same pixels (to a hundredth) are one point, whatever their light.
  draw_curves(r, curves_by(r, [](const CellResult& c) { return std::round(c.side_px * 100) / 100; }),
              "marker side (pixels, facing the camera at the image centre)",
              "Recognition against the marker's size in the image");
}

void draw_recall_by_light(const LabResults& r) {
  draw_curves(r, curves_by(r, [](const CellResult& c) { return c.cell.lux; }), "light (lux)",
              "Recognition against light (all sizes and distances)");
}

void draw_recall_by_tilt(const LabResults& r) {
  draw_curves(r, curves_by_tilt(r), "tilt (degrees from facing the camera, 10-degree bins)",
              "Recognition against tilt (every frame, all cells)");
}

void draw_recall_by_blur(const LabResults& r) {
  draw_curves(r, curves_by_blur(r), "blur (px: defocus, half the streak, added; combined)",
              "Recognition against blur (cells in bins)");
}

// The curves at curve_at: only the added blur, or only the added noise, changes.
void draw_recall_at_point(const LabResults& r, int curve) {
  char where[96];
  std::snprintf(where, sizeof where, " at %g mm, %g m, %g lx (same frames)", r.plan.curve_at[0], r.plan.curve_at[1],
                r.plan.curve_at[2]);
  const bool blur = curve == kBlurCurve;
  draw_curves(r, curves_at_point(r, curve), blur ? "added blur (sigma, px)" : "added noise (sigma, grey levels)",
              std::string(blur ? "Recognition against blur" : "Recognition against noise") + where);
}

// Size (rows, the plan's order from the top) x distance (columns), each cell's colour and number P_Rec pooled
// over light (lux < 0) or under one light, with its interval and the marker's side underneath.
void draw_heatmap(const LabResults& r, size_t d, double lux) {
  // A sides_px plan's rows are its sides in pixels (its printed sizes differ by distance).
  const bool by_side = !r.plan.sides_px.empty();
  const std::vector<double>& sizes = by_side ? r.plan.sides_px : r.plan.sizes_mm;
  const bool added = r.plan.has_tilts() || r.plan.has_blurs() || r.plan.has_noises() || r.plan.has_occlusions();
  const std::vector<double>& distances = r.plan.distances_m;
  const auto rows = double(sizes.size()), cols = double(distances.size());
  pladv(0);
  plvpor(0.17, 0.8, 0.14, 0.88);
  plwind(0, std::max(cols, 1.0), 0, std::max(rows, 1.0));
  plcol0(kInk);
  const std::string light = lux < 0 ? ", pooled over light" : ", under " + number(lux) + " lx";
  pllab("distance", "",
        ("P#dRec#u of " + plain(r.options.detectors[d]) + light + (added ? (lux < 0 ? " and" : ", pooled over") +
                                                                         std::string(" the added axes") : ""))
            .c_str());
  // Clear of the sizes' labels, which are wider than numbers.
  plmtex("l", 7.5, 0.5, 0.5, by_side ? "marker side at the centre" : "printed size");
  for (size_t i = 0; i < sizes.size(); ++i) {
    const double y0 = rows - double(i) - 1;
    plmtex("lv", 1.0, (y0 + 0.5) / rows, 1.0, (number(sizes[i]) + (by_side ? " px" : " mm")).c_str());
    for (size_t j = 0; j < distances.size(); ++j) {
      const auto x0 = double(j);
      if (i == 0) plmtex("b", 1.5, (x0 + 0.5) / cols, 0.5, (number(distances[j]) + " m").c_str());
      Pool pool;
      double side = 0;
      for (const CellResult& c : r.cells)
        if ((by_side ? c.cell.side_px : c.cell.size_mm) == sizes[i] && c.cell.distance_m == distances[j] &&
            (lux < 0 || c.cell.lux == lux) && d < c.detectors.size() && !c.cell.curve) {
          pool.add(c.detectors[d]);
          side = c.side_px;
        }
      const PLFLT xs[] = {x0, x0 + 1, x0 + 1, x0}, ys[] = {y0, y0, y0 + 1, y0 + 1};
      plcol0(kInk);
      if (pool.frames > 0) {
        plcol1(pool.p_rec() / 100);
        plfill(4, xs, ys);
        plcol0(kInk);
        const auto [lo, hi] = pool.interval();
        plschr(0, 1.6);
        plptex(x0 + 0.5, y0 + 0.55, 1, 0, 0.5, (number(pool.p_rec(), 1) + " %").c_str());
        plschr(0, 0.85);
        char interval[64];
        std::snprintf(interval, sizeof interval, "[%.0f-%.0f]", lo, hi);
        plptex(x0 + 0.5, y0 + 0.33, 1, 0, 0.5, interval);
        plptex(x0 + 0.5, y0 + 0.17, 1, 0, 0.5, (number(side, 1) + " px").c_str());
        plschr(0, 1);
      } else {
        plptex(x0 + 0.5, y0 + 0.45, 1, 0, 0.5, "no frames");
      }
      plline(5, std::vector<PLFLT>{x0, x0 + 1, x0 + 1, x0, x0}.data(),
             std::vector<PLFLT>{y0, y0, y0 + 1, y0 + 1, y0}.data());
    }
  }
  // The colour scale, 0 to 100 %, right of the grid: 100 shades of one percent each (not a gradient: the cairo
  // driver of PLplot 5.15 leaks each gradient's cairo pattern, which the sanitizer tree reports).
  PLFLT width = 0, height = 0;
  const char* labels[] = {"P#dRec#u (%)"};
  const PLINT label_opts[] = {PL_COLORBAR_LABEL_RIGHT};
  const char* axis_opts[] = {"bcvtm"};
  const PLFLT ticks[] = {20};
  std::vector<PLFLT> scale;
  for (int v = 0; v <= 100; ++v) scale.push_back(v);
  const PLINT sub_ticks[] = {2}, n_values[] = {PLINT(scale.size())};
  const PLFLT* values[] = {scale.data()};
  plcolorbar(&width, &height, PL_COLORBAR_SHADE,
             PL_POSITION_RIGHT | PL_POSITION_OUTSIDE | PL_POSITION_VIEWPORT, 0.04, 0, 0.04, 1.0, 0, kInk, 1, 0, 0, 0, 0,
             1, label_opts, labels, 1, axis_opts, ticks, sub_ticks, n_values, values);
}

void draw_title_page(const LabResults& r) {
  const LabPlan& p = r.plan;
  const SensorModel& s = r.options.sensor;
  const SynthCamera& cam = r.options.camera;
  // Lists built with a stream (GCC 12 warns, wrongly, on `"sep" + std::string` in loops: -Wrestrict).
  std::ostringstream detectors, distortion;
  // The ids, 16 to a line (the paper's 25 do not fit on one).
  std::vector<std::string> id_lines;
  for (size_t i = 0; i < r.ids.size(); i += 16) {
    std::ostringstream line;
    line << (i ? "     " : "ids: ");
    for (size_t k = i; k < std::min(r.ids.size(), i + 16); ++k) line << (k > i ? " " : "") << r.ids[k];
    id_lines.push_back(line.str());
  }
  for (size_t i = 0; i < r.options.detectors.size(); ++i) detectors << (i ? ", " : "") << r.options.detectors[i];
  for (size_t i = 0; i < cam.distortion.size(); ++i) distortion << (i ? " " : "") << number(cam.distortion[i]);
  char when[64] = "";
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  if (gmtime_r(&now, &utc)) std::strftime(when, sizeof when, "%Y-%m-%d %H:%M UTC", &utc);

  // Lines of the page from the top: a heading (empty text is a gap) and its lines.
  std::vector<std::pair<bool, std::string>> lines{
      {true, "Plan"},
      {false, "'" + p.name + "': " + std::to_string(p.markers) + " random " + p.dictionary + " markers, " +
                  std::to_string(p.grid_count()) + " cells x " + std::to_string(p.frames_per_cell) + " frames"},
      {false, (p.sides_px.empty() ? "printed " + joined(p.sizes_mm, "mm")
                                  : "sides of " + joined(p.sides_px, "px") + " at the image centre") +
                  "; at " + joined(p.distances_m, "m") + "; under " + joined(p.lux, "lux")},
      {false, "turned in plane over 360 deg, " +
                  (p.has_tilts() ? "tilted by exactly " + joined(p.tilts_deg, "deg") + " about a random axis"
                                 : "tilted up to " + number(p.max_tilt_deg) + " deg about x and about y")},
  };
  {
    std::string more;
    if (p.has_blurs()) more += "added blur " + joined(p.blurs_px, "px (sigma)");
    if (p.has_noises()) more += (more.empty() ? "" : "; ") + std::string("added noise ") + joined(p.noises, "grey levels");
    if (p.has_occlusions()) more += (more.empty() ? "" : "; ") + std::string("occluded ") + joined(p.occlusions, "of the marker");
    if (!more.empty()) lines.emplace_back(false, more);
  }
  if (const std::string curves = p.curves_text(); !curves.empty()) lines.emplace_back(false, "and " + curves);
  for (const std::string& l : id_lines) lines.emplace_back(false, l);
  lines.insert(lines.end(), {
      {true, "Camera"},
      {false, r.options.camera_name},
      {false, std::to_string(cam.size.width) + "x" + std::to_string(cam.size.height) + " px, fx " +
                  number(cam.camera_matrix(0, 0), 1) + ", fy " + number(cam.camera_matrix(1, 1), 1) + ", cx " +
                  number(cam.camera_matrix(0, 2), 1) + ", cy " + number(cam.camera_matrix(1, 2), 1) +
                  ", distortion " + (distortion.str().empty() ? "none" : distortion.str())},
      {true, "Sensor"},
      {false, "sensitivity " + number(s.sensitivity) + " e-/(lux s), full well " + number(s.full_well) +
                  " e-, read noise " + number(s.read_noise) + " e- RMS"},
      {false, "auto-exposure: a 0.18 grey card at " + number(s.target_level) + " of full scale; exposure <= " +
                  number(s.max_exposure_s * 1000) + " ms, then gain <= " + number(s.max_gain)},
      {false, "lens " + number(s.focal_length_mm) + " mm f/" + number(s.f_number) + " focused at " +
                  number(s.focus_m) + " m; hand-held shake " + number(s.shake_deg_s) + " deg/s RMS"},
      {true, "Run"},
      {false, "detectors: " + detectors.str()},
      {false, "seed " + std::to_string(r.options.seed) + ", report written " + when},
      {false, "ran in " + lab_time_text(r)},
      {true, "Measure"},
      {false, "P_Rec = frames in which a detector reported the marker's id, on the marker,"},
      {false, "           / frames with the marker in view x 100; intervals are 95 % Wilson intervals"},
  });
  pladv(0);
  plvpor(0.06, 0.96, 0.05, 0.95);
  plwind(0, 1, 0, 1);
  plcol0(kInk);
  plschr(0, 1.8);
  plptex(0, 0.96, 1, 0, 0, "ArUco Workbench: recognition lab report");
  // The lines' steps, closer together when a plan with added axes or a resumed run's time needs more of them than
  // the page holds at the usual spacing.
  double needed = 0;
  for (const auto& line : lines) needed += line.first ? 0.062 : 0.04;
  const double step = std::min(1.0, 0.86 / needed);
  double y = 0.87;
  for (const auto& [heading, text] : lines) {
    if (heading) y -= 0.015 * step;
    plschr(0, heading ? 1.1 : 0.85);
    plptex(heading ? 0 : 0.02, y, 1, 0, 0, plain(text).c_str());
    y -= (heading ? 0.047 : 0.04) * step;
  }
  plschr(0, 1);
}

// A detector's part of the paper's table (lab_table_text: a row per size and distance, a column per light) in a
// fixed-width font, small enough for its longest line; a plan of more rows than a page holds ends with where the
// rest is.
void draw_table_page(const std::string& section) {
  std::vector<std::string> lines;
  std::istringstream in(section);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  size_t longest = 1;
  for (const std::string& l : lines) longest = std::max(longest, l.size());
  constexpr size_t kRowsPerPage = 44;
  if (lines.size() > kRowsPerPage) {
    lines.resize(kRowsPerPage - 1);
    lines.push_back("... the other rows are in table.txt");
  }
  pladv(0);
  plvpor(0.05, 0.97, 0.05, 0.95);
  plwind(0, 1, 0, 1);
  plcol0(kInk);
  plsfont(PL_FCI_MONO, PL_FCI_UPRIGHT, PL_FCI_MEDIUM);
  plschr(0, std::min(1.1, 58.0 / double(longest)));   // about 60 characters of the font at scale 1 span the page
  const double step = std::min(0.045, 0.95 / double(lines.size()));
  for (size_t i = 0; i < lines.size(); ++i) plptex(0, 0.97 - double(i) * step, 1, 0, 0, plain(lines[i]).c_str());
  plsfont(PL_FCI_SANS, PL_FCI_UPRIGHT, PL_FCI_MEDIUM);
  plschr(0, 1);
}

// One page of plots: a curve (0 side, 1 light, 2 tilt, 3 blur; 4 and 5 blur and noise at curve_at), or a
// detector's heatmap pooled over light (lux < 0) or under one light (when the plan has more than one), with its
// PNG's name.
struct PlotPage {
  int curve = -1;
  size_t detector = 0;
  double lux = -1;
  std::string png;
};

std::vector<PlotPage> plot_pages(const LabResults& r) {
  std::vector<PlotPage> pages{{0, 0, -1, "recall_by_side.png"},
                              {1, 0, -1, "recall_by_light.png"},
                              {2, 0, -1, "recall_by_tilt.png"},
                              {3, 0, -1, "recall_by_blur.png"}};
  if (r.plan.curve_base() >= 0 && r.cells.size() > r.plan.grid_count()) {
    if (!r.plan.curve_blurs_px.empty()) pages.push_back({4, 0, -1, "recall_at_added_blur.png"});
    if (!r.plan.curve_noises.empty()) pages.push_back({5, 0, -1, "recall_at_added_noise.png"});
  }
  const auto taken = [&](const std::string& png) {
    return std::any_of(pages.begin(), pages.end(), [&](const PlotPage& p) { return p.png == png; });
  };
  for (size_t d = 0; d < r.options.detectors.size(); ++d) {
    // Two detectors whose names read alike in a file name ("a b", "a_b", or one named twice) get a number each.
    std::string name = "heatmap_" + file_safe(r.options.detectors[d]);
    for (int k = 2; taken(name + ".png"); ++k)
      name = "heatmap_" + file_safe(r.options.detectors[d]) + "_" + std::to_string(k);
    pages.push_back({-1, d, -1, name + ".png"});
    if (r.plan.lux.size() > 1)
      for (double lux : r.plan.lux) pages.push_back({-1, d, lux, name + "_" + number(lux) + "lx.png"});
  }
  return pages;
}

void draw_plot(const LabResults& r, const PlotPage& page) {
  switch (page.curve) {
    case 0: draw_recall_by_side(r); break;
    case 1: draw_recall_by_light(r); break;
    case 2: draw_recall_by_tilt(r); break;
    case 3: draw_recall_by_blur(r); break;
    case 4: draw_recall_at_point(r, kBlurCurve); break;
    case 5: draw_recall_at_point(r, kNoiseCurve); break;
    default: draw_heatmap(r, page.detector, page.lux);
  }
}

// One PLplot stream for one output file, ended (plend1) and the caller's stream made current again whatever
// happens; the FILE is PLplot's once plinit has run (its driver closes it at plend1).
class Stream {
 public:
  explicit Stream(std::FILE* file) : file_(file) {
    plgstrm(&previous_);
    plmkstrm(&id_);
  }
  ~Stream() {
    if (id_ >= 0) {
      plsstrm(id_);
      plend1();
    }
    if (!initialised_ && file_) std::fclose(file_);
    plsstrm(previous_);
  }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  bool ok() const { return id_ >= 0; }
  // Opens `device` at `width` x `height` (pixels for PNG, points for PDF) on the file.
  void init(const char* device, int width, int height) {
    plsdev(device);
    plspage(0, 0, width, height, 0, 0);
    set_colours();   // before plinit: the first page's background is painted with colour 0
    plsfile(file_);
    initialised_ = true;
    plinit();
  }

 private:
  std::FILE* file_;
  PLINT previous_ = 0, id_ = -1;
  bool initialised_ = false;
};

// PLplot prompts on the terminal for a device it does not know, and then exits: the devices must be there first.
Status check_devices() {
  std::vector<const char*> menus(256), names(256);
  int n = int(menus.size());
  const char** menu_list = menus.data();
  const char** name_list = names.data();
  plgDevs(&menu_list, &name_list, &n);
  for (const char* wanted : {"pngcairo", "pdfcairo"}) {
    bool found = false;
    for (int i = 0; i < n && !found; ++i) found = name_list[i] && std::strcmp(name_list[i], wanted) == 0;
    if (!found)
      return fail(std::string("lab report: PLplot has no ") + wanted +
                  " device (its cairo driver is missing: install plplot-driver-cairo)");
  }
  return {};
}

// Draws one file: under a temporary name in its folder, renamed over `path` when PLplot has finished it.
template <typename Draw>
Status draw_file(const fs::path& path, const char* device, int width, int height, Draw draw) {
  // The suffix write_file_atomically uses for the same purpose.
  const fs::path part = fs::path(path).concat(".arwb-saving");
  std::FILE* file = std::fopen(part.c_str(), "wb");
  if (!file) return fail("lab report: cannot write " + part.string() + ": " + std::strerror(errno));
  {
    Stream stream(file);
    if (!stream.ok()) {
      std::error_code ec;
      fs::remove(part, ec);
      return fail("lab report: PLplot has no free stream for " + path.string());
    }
    stream.init(device, width, height);
    draw();
  }
  std::error_code ec;
  if (fs::file_size(part, ec) == 0 || ec) {
    fs::remove(part, ec);
    return fail("lab report: PLplot's " + std::string(device) + " wrote nothing to " + part.string());
  }
  fs::rename(part, path, ec);
  if (ec) {
    fs::remove(part, ec);
    return fail("lab report: cannot write " + path.string() + ": " + ec.message());
  }
  return {};
}

}  // namespace

std::vector<std::string> lab_report_png_names(const LabResults& r) {
  std::vector<std::string> names;
  for (const PlotPage& p : plot_pages(r)) names.push_back(p.png);
  return names;
}

Status write_lab_report(const LabResults& r, const std::string& dir) {
  if (r.cells.empty()) return fail("lab report: the results have no cells to plot");
  if (r.options.detectors.empty()) return fail("lab report: the results have no detectors to plot");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir, ec)) return fail("lab report: cannot create the folder " + dir +
                                                    (ec ? ": " + ec.message() : ": a file is in the way"));
  const std::vector<PlotPage> pages = plot_pages(r);

  const std::lock_guard lock(plplot_mutex);
  if (Status s = check_devices(); !s) return s;
  for (const PlotPage& page : pages)
    if (Status s = draw_file(fs::path(dir) / page.png, "pngcairo", kPlotWidthPx, kPlotHeightPx,
                             [&] { draw_plot(r, page); });
        !s)
      return s;
  // The table's sections, one per detector, are separated by an empty line.
  const std::string table = lab_table_text(r);
  std::vector<std::string> sections;
  for (size_t start = 0; start < table.size();) {
    const size_t end = std::min(table.find("\n\n", start), table.size());
    if (end > start) sections.push_back(table.substr(start, end - start));
    start = end + 2;
  }
  return draw_file(fs::path(dir) / "report.pdf", "pdfcairo", kReportPageWidthPt, kReportPageHeightPt, [&] {
    draw_title_page(r);
    for (const std::string& section : sections) draw_table_page(section);
    for (const PlotPage& page : pages) draw_plot(r, page);
  });
}

Status write_lab_outputs(const LabResults& r, const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::string text = lab_table_text(r), csv = lab_table_csv(r), js = lab_results_json(r);
  for (const auto& [name, content] : {std::pair{"table.txt", &text}, {"table.csv", &csv}, {"results.json", &js}}) {
    const std::string path = (std::filesystem::path(dir) / name).string();
    if (std::string e; !write_file_atomically(path, *content, &e)) return fail(e);
  }
  return write_lab_report(r, dir);
}

}  // namespace arwb::lab
