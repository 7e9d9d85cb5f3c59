#include "lab/plan.hpp"

#include "base/text.hpp"
#include "detect/dictionary.hpp"
#include "detect/yaml_file.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <string_view>

namespace arwb::lab {

namespace {
// An added axis left empty (in code; a plan file always gives values) is the axis at its default.
const std::vector<double>& or_default(const std::vector<double>& v, const std::vector<double>& fallback) {
  return v.empty() ? fallback : v;
}
const std::vector<double> kNone{0}, kRandomTilt{-1};
}  // namespace

std::vector<Cell> LabPlan::cells(double focal_px) const {
  const bool by_side = !sides_px.empty();
  const std::vector<double>& tilts = or_default(tilts_deg, kRandomTilt);
  std::vector<Cell> out;
  for (double s : by_side ? sides_px : sizes_mm)
    for (double d : distances_m)
      for (double t : tilts)
        for (double b : or_default(blurs_px, kNone))
          for (double n : or_default(noises, kNone))
            for (double o : or_default(occlusions, kNone))
              for (double l : lux) {
                Cell c;
                // The inverse of marker_side_px (sensor.hpp): side = focal_px x size / distance.
                c.size_mm = by_side ? (focal_px > 0 ? s * d * 1000 / focal_px : 0) : s;
                c.side_px = by_side ? s : 0;
                c.distance_m = d;
                c.lux = l;
                c.tilt_deg = t;
                c.blur_px = b;
                c.noise = n;
                c.occlusion = o;
                out.push_back(c);
              }
  if (const long base = curve_base(); base >= 0) {
    const Cell at = out[size_t(base)];
    for (double b : curve_blurs_px) {
      out.push_back(at);
      out.back().blur_px = b;
      out.back().curve = kBlurCurve;
    }
    for (double n : curve_noises) {
      out.push_back(at);
      out.back().noise = n;
      out.back().curve = kNoiseCurve;
    }
  }
  return out;
}

size_t LabPlan::cell_count() const {
  return grid_count() + (curve_base() >= 0 ? curve_blurs_px.size() + curve_noises.size() : 0);
}

long LabPlan::curve_base(std::string* why) const {
  auto none = [&](const std::string& reason) {
    if (why) *why = reason;
    return -1L;
  };
  if (curve_blurs_px.empty() && curve_noises.empty()) return none("the plan asks for none");
  if (!sides_px.empty()) return none("the plan gives sides_px, not sizes_mm");
  if (has_tilts() || has_blurs() || has_noises() || has_occlusions()) return none("the plan has added axes of its own");
  const auto at = [](const std::vector<double>& axis, double v) {
    return long(std::find(axis.begin(), axis.end(), v) - axis.begin());
  };
  if (curve_at.size() != 3) return none("curve_at is not a size, a distance and a light");
  const long si = at(sizes_mm, curve_at[0]), di = at(distances_m, curve_at[1]), li = at(lux, curve_at[2]);
  if (si == long(sizes_mm.size()) || di == long(distances_m.size()) || li == long(lux.size())) {
    char b[160];
    std::snprintf(b, sizeof b, "the grid has no cell at %g mm, %g m, %g lx (curve_at)", curve_at[0], curve_at[1],
                  curve_at[2]);
    return none(b);
  }
  return (si * long(distances_m.size()) + di) * long(lux.size()) + li;
}

std::string LabPlan::curves_text() const {
  if (curve_base() < 0) return "";
  char b[160];
  std::snprintf(b, sizeof b, "%zu cells for the blur and noise curves at %g mm, %g m, %g lx",
                curve_blurs_px.size() + curve_noises.size(), curve_at[0], curve_at[1], curve_at[2]);
  return b;
}

size_t LabPlan::grid_count() const {
  return (sides_px.empty() ? sizes_mm.size() : sides_px.size()) * distances_m.size() *
         std::max<size_t>(1, tilts_deg.size()) * std::max<size_t>(1, blurs_px.size()) *
         std::max<size_t>(1, noises.size()) * std::max<size_t>(1, occlusions.size()) * lux.size();
}

size_t LabPlan::pose_index(size_t index) const {
  if (index >= grid_count()) return size_t(curve_base());   // no added axes: the base's own index
  const size_t L = std::max<size_t>(1, lux.size());
  const size_t added = std::max<size_t>(1, tilts_deg.size()) * std::max<size_t>(1, blurs_px.size()) *
                       std::max<size_t>(1, noises.size()) * std::max<size_t>(1, occlusions.size());
  return index / L / added * L + index % L;
}

bool LabPlan::has_blurs() const { return !blurs_px.empty() && blurs_px != kNone; }
bool LabPlan::has_noises() const { return !noises.empty() && noises != kNone; }
bool LabPlan::has_occlusions() const { return !occlusions.empty() && occlusions != kNone; }

std::string added_axes_text(const LabPlan& plan, const Cell& cell) {
  std::string s;
  char b[64];
  auto add = [&](bool has, const char* name, double v) {
    if (!has) return;
    std::snprintf(b, sizeof b, "%s%s %g", s.empty() ? "" : " ", name, v);
    s += b;
  };
  add(plan.has_tilts(), "tilt", cell.tilt_deg);
  add(plan.has_blurs(), "blur", cell.blur_px);
  add(plan.has_noises(), "noise", cell.noise);
  add(plan.has_occlusions(), "occluded", cell.occlusion);
  return s;
}

int LabPlan::empty_frames_per_cell() const {
  return std::max(1, int(std::ceil(frames_per_cell * std::max(0.0, empty_share))));
}

LabPlan paper_plan() { return LabPlan{}; }

const std::vector<PlanAxis>& plan_axes() {
  static const std::vector<PlanAxis> kAxes{{"sizes_mm", 1, 2000, "a size in mm", &LabPlan::sizes_mm},
                                           {"distances_m", 0.05, 100, "a distance in m", &LabPlan::distances_m},
                                           {"lux", 0.1, 200000, "an illuminance in lux", &LabPlan::lux},
                                           {"sides_px", 4, 2000, "a side in pixels", &LabPlan::sides_px},
                                           {"tilts_deg", 0, 85, "a tilt in degrees", &LabPlan::tilts_deg},
                                           {"blurs_px", 0, 20, "a blur sigma in pixels", &LabPlan::blurs_px},
                                           {"noises", 0, 100, "a noise sigma in grey levels", &LabPlan::noises},
                                           {"occlusions", 0, 0.5, "a share of the marker's area",
                                            &LabPlan::occlusions}};
  return kAxes;
}

namespace {
std::string out_of_range(const PlanAxis& a, size_t i, double d) {
  char b[200];
  if (!std::isfinite(d))   // not "(-nan)", which %g would print
    std::snprintf(b, sizeof b, "%s: value %zu is not a finite number", a.key, i + 1);
  else
    std::snprintf(b, sizeof b, "%s: value %zu (%g) must be %s from %g to %g", a.key, i + 1, d, a.what, a.lo, a.hi);
  return b;
}
}  // namespace

Result<std::vector<double>> parse_axis(const PlanAxis& axis, const std::string& text) {
  std::vector<double> v;
  size_t i = 0;
  while (i < text.size()) {
    if (text[i] == ',' || std::isspace(static_cast<unsigned char>(text[i]))) {
      ++i;
      continue;
    }
    size_t end = i;
    while (end < text.size() && text[end] != ',' && !std::isspace(static_cast<unsigned char>(text[end]))) ++end;
    const std::string item = text.substr(i, end - i);
    char* stop = nullptr;
    const double d = std::strtod(item.c_str(), &stop);
    if (stop == item.c_str() || *stop != '\0')
      return fail(std::string(axis.key) + ": value " + std::to_string(v.size() + 1) + " ('" + item + "') is not a number");
    if (!std::isfinite(d) || d < axis.lo || d > axis.hi) return fail(out_of_range(axis, v.size(), d));
    v.push_back(d);
    i = end;
  }
  if (v.empty() || v.size() > 50) return fail(std::string(axis.key) + ": give 1 to 50 values");
  return v;
}

std::string axis_text(const std::vector<double>& values) {
  std::string s;
  char b[64];
  for (double d : values) {
    std::snprintf(b, sizeof b, "%g", d);
    s += (s.empty() ? "" : ", ") + std::string(b);
  }
  return s;
}

namespace {

constexpr FileLimit kPlanFile{"a lab plan", 1u << 20};

// A list of numbers (a single number is a list of one), each in the axis's range.
std::string read_list(const cv::FileNode& n, const PlanAxis& axis, std::vector<double>* out) {
  const char* key = axis.key;
  std::vector<double> v;
  auto take = [&](const cv::FileNode& x, size_t i) -> std::string {
    if (!x.isReal() && !x.isInt()) return std::string(key) + ": value " + std::to_string(i + 1) + " is not a number";
    const double d = double(x);
    if (!std::isfinite(d) || d < axis.lo || d > axis.hi) return out_of_range(axis, i, d);
    v.push_back(d);
    return {};
  };
  if (n.isSeq()) {
    if (n.size() == 0 || n.size() > 50) return std::string(key) + ": give 1 to 50 values";
    for (size_t i = 0; i < n.size(); ++i)
      if (std::string e = take(n[int(i)], i); !e.empty()) return e;
  } else if (std::string e = take(n, 0); !e.empty()) {
    return e;
  }
  *out = std::move(v);
  return {};
}

// One number in [lo, hi]; `whole`: a count, which 1.9 is not (it was cut to 1 without a word).
std::string read_number(const cv::FileNode& n, const char* key, double lo, double hi, double* out,
                        bool whole = false) {
  if (!n.isReal() && !n.isInt()) return std::string(key) + ": not a number";
  const double d = double(n);
  if (!std::isfinite(d)) return std::string(key) + ": not a finite number";
  if (whole && d != std::floor(d)) {
    char b[160];
    std::snprintf(b, sizeof b, "%s: %g is not a whole number", key, d);
    return b;
  }
  if (d < lo || d > hi) {
    char b[160];
    std::snprintf(b, sizeof b, "%s: %g must be from %g to %g", key, d, lo, hi);
    return b;
  }
  *out = d;
  return {};
}

// curve_at: [size_mm, distance_m, lux], each in its axis's range; curve_blurs_px and curve_noises: lists in the
// added axes' ranges, or [] for none. A curve_at given must be a cell of the grid.
std::string read_curves(const cv::FileNode& root, LabPlan* p) {
  std::string e;
  const std::vector<PlanAxis>& axes = plan_axes();
  if (const cv::FileNode n = root["curve_at"]; !n.empty()) {
    if (!n.isSeq() || n.size() != 3) return "curve_at: give [size_mm, distance_m, lux], three numbers";
    for (int i = 0; i < 3; ++i) {
      std::vector<double> one;
      if (!(e = read_list(n[i], axes[size_t(i)], &one)).empty()) return "curve_at: " + e;
      p->curve_at[size_t(i)] = one[0];
    }
    if (std::string why; p->curve_base(&why) < 0 && why.find("curve_at") != std::string::npos)
      return "curve_at: " + why;
  }
  const struct {
    const char* key;
    const PlanAxis& like;
    std::vector<double>* out;
  } lists[] = {{"curve_blurs_px", axes[5], &p->curve_blurs_px}, {"curve_noises", axes[6], &p->curve_noises}};
  for (const auto& l : lists) {
    const cv::FileNode n = root[l.key];
    if (n.empty()) continue;
    if (n.isSeq() && n.size() == 0) {
      l.out->clear();
      continue;
    }
    PlanAxis axis = l.like;
    axis.key = l.key;
    if (!(e = read_list(n, axis, l.out)).empty()) return e;
  }
  return {};
}

}  // namespace

Result<LabPlan> read_plan(const std::string& path) {
  cv::FileStorage fs;
  if (Status s = open_yaml_file(path, kPlanFile, &fs); !s) return fail(s.error());
  LabPlan p;
  p.name = utf8_replaced(std::filesystem::path(path).stem().string());
  const cv::FileNode root = fs.root();
  if (!root.isMap()) return fail(path + ": a plan is a map of fields (sizes_mm: [65, 39, 26], ...)");
  static const std::vector<std::string_view> kKnown = {"name", "dictionary", "markers", "sizes_mm", "distances_m",
                                                       "lux", "max_tilt_deg", "frames_per_cell", "empty_share",
                                                       "sides_px", "tilts_deg", "blurs_px", "noises", "occlusions",
                                                       "curve_at", "curve_blurs_px", "curve_noises"};
  for (const cv::FileNode& n : root) {
    const std::string key = n.name();
    if (std::find(kKnown.begin(), kKnown.end(), key) != kKnown.end()) continue;
    const std::string best = nearest_name(key, kKnown);
    return fail(path + ": unknown field '" + key + "'" + (best.empty() ? "" : " (did you mean '" + best + "'?)"));
  }
  auto at = [&](const char* key) { return root[key]; };
  std::string e;
  if (!at("sides_px").empty() && !at("sizes_mm").empty())
    return fail(path + ": sides_px and sizes_mm: give one of them (sides_px derives the printed size)");
  if (!at("name").empty()) {
    if (!at("name").isString()) return fail(path + ": name: not a text");
    p.name = std::string(at("name"));
  }
  if (!at("dictionary").empty()) {
    const std::string d = at("dictionary").isString() ? std::string(at("dictionary")) : std::string();
    if (!dictionary_by_name(d)) return fail(path + ": dictionary: unknown '" + d + "'");
    p.dictionary = d;
  }
  for (const PlanAxis& axis : plan_axes())
    if (e.empty() && !at(axis.key).empty()) e = read_list(at(axis.key), axis, &(p.*axis.values));
  if (e.empty()) e = read_curves(root, &p);
  double v = 0;
  if (e.empty() && !at("max_tilt_deg").empty() && (e = read_number(at("max_tilt_deg"), "max_tilt_deg", 0, 80, &v)).empty())
    p.max_tilt_deg = v;
  if (e.empty() && !at("frames_per_cell").empty() &&
      (e = read_number(at("frames_per_cell"), "frames_per_cell", 1, 100000, &v, true)).empty())
    p.frames_per_cell = int(v);
  if (e.empty() && !at("empty_share").empty() && (e = read_number(at("empty_share"), "empty_share", 0, 10, &v)).empty())
    p.empty_share = v;
  if (e.empty() && !at("markers").empty() && (e = read_number(at("markers"), "markers", 1, 100000, &v, true)).empty())
    p.markers = int(v);
  if (!e.empty()) return fail(path + ": " + e);
  const int dict_size = dictionary_by_name(p.dictionary)->size();
  if (p.markers > dict_size)
    return fail(path + ": markers: " + std::to_string(p.markers) + " distinct ids, but " + p.dictionary + " has " +
                std::to_string(dict_size));
  const size_t cells = p.cell_count();
  if (cells > kMaxLabCells)
    return fail(path + ": " + std::to_string(cells) + " cells, more than " + std::to_string(kMaxLabCells));
  return p;
}

}  // namespace arwb::lab
