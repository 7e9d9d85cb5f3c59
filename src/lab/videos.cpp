#include "lab/videos.hpp"

#include "lab/detectors.hpp"
#include "base/files.hpp"
#include "capture/video_reader.hpp"
#include "detect/dictionary.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace arwb::lab {
namespace {

constexpr FileLimit kVideoList{"a video list", 4u << 20};
constexpr const char* kHeader = "file,id,dictionary,size_mm,distance_m,lux[,first_frame,last_frame]";

std::string trim(std::string s) {
  const auto ws = [](unsigned char c) { return std::isspace(c) != 0; };
  while (!s.empty() && ws(static_cast<unsigned char>(s.back()))) s.pop_back();
  size_t i = 0;
  while (i < s.size() && ws(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ',');) out.push_back(trim(f));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

bool number(const std::string& s, double* out) {
  if (s.empty()) return false;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (*end != '\0' || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

}  // namespace

Result<std::vector<VideoRow>> read_video_list(const std::string& dir) {
  const std::string path = (std::filesystem::path(dir) / "videos.csv").string();
  Result<std::string> text = read_text_file(path, kVideoList);
  if (!text) return fail(text.error());
  const std::string name = "videos.csv";
  std::vector<VideoRow> rows;
  std::stringstream in(*text);
  int line_no = 0;
  bool header = false;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (trim(line).empty() || trim(line)[0] == '#') continue;
    const std::string at = name + ":" + std::to_string(line_no) + ": ";
    const std::vector<std::string> f = split(line);
    if (!header) {
      const std::vector<std::string> want{"file", "id", "dictionary", "size_mm", "distance_m", "lux"};
      if (f.size() < 6 || !std::equal(want.begin(), want.end(), f.begin()) ||
          (f.size() > 6 && (f.size() != 8 || f[6] != "first_frame" || f[7] != "last_frame")))
        return fail(at + "the header must be " + kHeader);
      header = true;
      continue;
    }
    if (f.size() != 6 && f.size() != 8)
      return fail(at + std::to_string(f.size()) + " fields, not 6 or 8 (" + kHeader + ")");
    VideoRow r;
    r.line = line_no;
    r.file = f[0];
    const ResolvedPath p = resolve_inside(dir, f[0], {}, "the videos' folder");
    if (!p.ok()) return fail(at + p.error);
    r.path = p.path;
    double v = 0;
    if (!number(f[1], &v) || v != std::floor(v)) return fail(at + "id '" + shown_name(f[1]) + "' is not a whole number");
    r.id = int(v);
    r.dictionary = f[2];
    const auto dict = dictionary_by_name(f[2]);
    if (!dict) return fail(at + "dictionary: unknown '" + shown_name(f[2]) + "'");
    if (r.id < 0 || r.id >= dict->size())
      return fail(at + "id " + f[1] + " is not a marker of " + f[2] + " (0 to " + std::to_string(dict->size() - 1) + ")");
    const struct {
      const char* key;
      double* out;
      double lo, hi;
    } nums[] = {{"size_mm", &r.size_mm, 1, 2000}, {"distance_m", &r.distance_m, 0.05, 100}, {"lux", &r.lux, 0.1, 200000}};
    for (size_t i = 0; i < 3; ++i) {
      const std::string& s = f[3 + i];
      if (!number(s, nums[i].out)) return fail(at + nums[i].key + " '" + shown_name(s) + "' is not a number");
      if (*nums[i].out < nums[i].lo || *nums[i].out > nums[i].hi) {
        char b[160];
        std::snprintf(b, sizeof b, "%s %g is outside %g to %g", nums[i].key, *nums[i].out, nums[i].lo, nums[i].hi);
        return fail(at + b);
      }
    }
    if (f.size() == 8) {
      double a = 0, b = 0;
      if (!number(f[6], &a) || !number(f[7], &b) || a < 0 || b < a || a != std::floor(a) || b != std::floor(b))
        return fail(at + "first_frame and last_frame must be whole numbers, 0 <= first <= last (got '" +
                    shown_name(f[6]) + "', '" + shown_name(f[7]) + "')");
      r.first_frame = int64_t(a);
      r.last_frame = int64_t(b);
    }
    rows.push_back(std::move(r));
  }
  if (!header) return fail(name + ": empty; the first line must be " + kHeader);
  if (rows.empty()) return fail(name + ": no videos listed");
  return rows;
}

Status check_video_row(const VideoRow& row) {
  const auto dict = dictionary_by_name(row.dictionary);
  if (!dict) return fail("dictionary: unknown '" + shown_name(row.dictionary) + "'");
  if (row.id < 0 || row.id >= dict->size())
    return fail("id " + std::to_string(row.id) + " is not a marker of " + row.dictionary + " (0 to " +
                std::to_string(dict->size() - 1) + ")");
  const struct {
    const char* key;
    double v, lo, hi;
  } nums[] = {{"size_mm", row.size_mm, 1, 2000}, {"distance_m", row.distance_m, 0.05, 100}, {"lux", row.lux, 0.1, 200000}};
  for (const auto& n : nums) {
    if (!std::isfinite(n.v) || n.v < n.lo || n.v > n.hi) {
      char b[160];
      std::snprintf(b, sizeof b, "%s %g is outside %g to %g", n.key, n.v, n.lo, n.hi);
      return fail(b);
    }
  }
  if (row.last_frame >= 0 && (row.first_frame < 0 || row.last_frame < row.first_frame))
    return fail("last_frame " + std::to_string(row.last_frame) + " is before first_frame " + std::to_string(row.first_frame));
  return {};
}

Status save_video_row(const std::string& dir, const std::string& clip, const VideoRow& row) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (dir.empty() || !fs::is_directory(dir, ec)) return fail("the videos' folder '" + shown_name(dir) + "' is not a folder");
  const fs::path base = fs::weakly_canonical(fs::absolute(dir), ec);
  const fs::path file = fs::weakly_canonical(fs::absolute(clip), ec);
  const fs::path rel = file.lexically_relative(base);
  if (rel.empty() || *rel.begin() == "..") return fail(shown_name(clip) + ": not inside the videos' folder " + shown_name(dir));
  const std::string name = rel.generic_string();
  if (name.find(',') != std::string::npos || name.find('"') != std::string::npos)
    return fail(shown_name(name) + ": a file name with a comma or a quote cannot be a row of videos.csv");
  if (Status s = check_video_row(row); !s) return s;
  const bool span = row.last_frame >= 0;
  char b[512];
  std::snprintf(b, sizeof b, "%s,%d,%s,%g,%g,%g", name.c_str(), row.id, row.dictionary.c_str(), row.size_mm,
                row.distance_m, row.lux);
  std::string line = b;
  if (span) line += "," + std::to_string(row.first_frame) + "," + std::to_string(row.last_frame);
  // The list as it is: its lines kept, the header made the 8-column one, this file's row replaced or appended.
  const std::string path = (fs::path(dir) / "videos.csv").string();
  std::vector<std::string> lines;
  if (fs::exists(path, ec)) {
    Result<std::string> text = read_text_file(path, kVideoList);
    if (!text) return fail(text.error());
    std::stringstream in(*text);
    for (std::string l; std::getline(in, l);) {
      if (!l.empty() && l.back() == '\r') l.pop_back();
      lines.push_back(l);
    }
  }
  const std::string header = "file,id,dictionary,size_mm,distance_m,lux,first_frame,last_frame";
  bool have_header = false, replaced = false;
  for (std::string& l : lines) {
    const std::string t = trim(l);
    if (t.empty() || t[0] == '#') continue;
    if (!have_header) {
      if (split(t).size() < 6 || split(t)[0] != "file") return fail("videos.csv:1: the header must be " + std::string(kHeader));
      l = header;
      have_header = true;
      continue;
    }
    const std::vector<std::string> f = split(t);
    if (!f.empty() && f[0] == name) {
      l = replaced ? std::string() : line;
      replaced = true;
    }
  }
  if (!have_header) lines.insert(lines.begin(), header);
  if (!replaced) lines.push_back(line);
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  if (std::string e; !write_file_atomically(path, out, &e)) return fail(e);
  return {};
}

Result<LabResults> run_videos(const std::string& dir, const std::vector<VideoRow>& rows, const LabOptions& options,
                              std::vector<std::string>* warnings, const std::function<void(int, int)>& progress) {
  (void)dir;
  const auto t0 = std::chrono::steady_clock::now();
  // Every detector is tried on every dictionary before anything is decoded, so that one that cannot run stops the
  // run at once; each clip then gets its own.
  for (const VideoRow& r : rows)
    for (const std::string& name : options.detectors)
      if (auto d = make_detector(name, r.dictionary, options.params); !d)
        return fail("videos.csv:" + std::to_string(r.line) + ": " + d.error());
  LabResults out;
  out.options = options;
  out.plan.name = "videos";
  out.plan.dictionary = rows.front().dictionary;
  out.plan.frames_per_cell = 0;
  out.plan.empty_share = 0;
  out.plan.curve_blurs_px.clear();   // clips are as filmed: no blur or noise is added to them
  out.plan.curve_noises.clear();
  std::set<double, std::greater<>> sizes, distances, lux;
  std::set<int> ids;
  for (const VideoRow& r : rows) {
    sizes.insert(r.size_mm);
    distances.insert(r.distance_m);
    lux.insert(r.lux);
    ids.insert(r.id);
  }
  out.plan.sizes_mm.assign(sizes.begin(), sizes.end());
  out.plan.distances_m.assign(distances.begin(), distances.end());
  out.plan.lux.assign(lux.begin(), lux.end());
  out.plan.markers = int(ids.size());
  out.ids.assign(ids.begin(), ids.end());
  // The grid is every size by every distance by every light: checked before a cell of it is made.
  if (const size_t cells = out.plan.cell_count(); cells > kMaxLabCells)
    return fail("videos.csv: " + std::to_string(sizes.size()) + " sizes x " + std::to_string(distances.size()) +
                " distances x " + std::to_string(lux.size()) + " lights make " + std::to_string(cells) +
                " cells, more than " + std::to_string(kMaxLabCells) + " (rows with the same three share a cell)");
  const double f = options.camera.camera_matrix(0, 0);
  for (const Cell& c : out.plan.cells(f)) {
    CellResult cr;
    cr.cell = c;
    cr.side_px = marker_side_px(c.size_mm, c.distance_m, f);
    cr.detectors.resize(options.detectors.size());
    out.cells.push_back(std::move(cr));
  }
  auto cell_of = [&](const VideoRow& r) -> CellResult& {
    for (CellResult& c : out.cells)
      if (c.cell.size_mm == r.size_mm && c.cell.distance_m == r.distance_m && c.cell.lux == r.lux) return c;
    return out.cells.front();   // every row's values are in the grid
  };
  for (size_t i = 0; i < rows.size(); ++i) {
    const VideoRow& r = rows[i];
    cv::Mat frame;
    Result<VideoReader> reader = VideoReader::open(r.path, &frame);
    if (!reader) {
      warnings->push_back("videos.csv:" + std::to_string(r.line) + ": " + reader.error() + "; not counted");
      if (progress) progress(int(i) + 1, int(rows.size()));
      continue;
    }
    CellResult& cell = cell_of(r);
    // Each clip is a video of its own: arwb searches it as video from its first frame (detect/video_search.hpp).
    std::vector<DetectFn> list;
    for (const std::string& name : options.detectors)
      list.push_back(*make_detector(name, r.dictionary, options.params, true));
    int64_t index = 0, counted = 0;
    for (bool have = true; have; have = reader->read(&frame) == VideoReader::Read::frame, ++index) {
      if (index < r.first_frame) continue;
      if (r.last_frame >= 0 && index > r.last_frame) break;
      ++counted;
      for (size_t d = 0; d < list.size(); ++d) {
        DetectorTally& t = cell.detectors[d];
        ++t.frames;
        const auto s0 = std::chrono::steady_clock::now();
        const std::vector<Marker> found = list[d](frame);
        t.ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - s0).count());
        bool right = false, wrong = false;
        for (const Marker& m : found) (m.id == r.id ? right : wrong) = true;
        t.detected += right;
        t.wrong_id += wrong;
      }
    }
    if (!reader->error().empty()) warnings->push_back("videos.csv:" + std::to_string(r.line) + ": " + reader->error());
    if (r.last_frame >= 0 && index <= r.last_frame)
      warnings->push_back("videos.csv:" + std::to_string(r.line) + ": " + r.file + " ends at frame " +
                          std::to_string(index - 1) + ", before its span's last frame " + std::to_string(r.last_frame) +
                          "; " + std::to_string(counted) + " frames counted");
    if (progress) progress(int(i) + 1, int(rows.size()));
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace arwb::lab
