#include "calibration/calibration_file.hpp"

#include "calibration/camera_rule.hpp"
#include "detect/yaml_file.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <numeric>
#include <string_view>

namespace arwb {

namespace {

constexpr int kMaxXmlDepth = 32;
constexpr int kMaxValues = 64;   // the longest matrix a calibration holds is 3x3 or 1x14

// OpenCV's XML parser recurses once per nested element with no limit of its own, as its YAML parser does:
// deeper than our files ever go is refused before it parses. DOCTYPE and CDATA are refused too: calibration
// files never hold them, and entity tricks have no business in them.
Status check_xml_text(std::string_view text, const std::string& path) {
  int depth = 0, line = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n') ++line;
    if (text[i] != '<') continue;
    const auto where = [&] { return path + ":" + std::to_string(line) + ": "; };
    std::string_view rest = text.substr(i);
    size_t end;
    if (rest.substr(0, 4) == "<!--") {
      end = rest.find("-->");
    } else if (rest.substr(0, 2) == "<?") {
      end = rest.find("?>");
    } else if (rest.substr(0, 2) == "<!") {
      return fail(where() + "DOCTYPE and CDATA are not read in a calibration file");
    } else {
      end = rest.find('>');
      if (end != std::string_view::npos) {
        if (rest.substr(0, 2) == "</") --depth;
        else if (rest[end - 1] != '/' && ++depth > kMaxXmlDepth)
          return fail(where() + "nested deeper than " + std::to_string(kMaxXmlDepth) + " levels");
      }
    }
    if (end == std::string_view::npos) return fail(where() + "malformed XML (a tag that does not end)");
    for (size_t k = i; k < i + end; ++k)
      if (text[k] == '\n') ++line;
    i += end;
  }
  return {};
}

// OpenCV's parse errors end in "(LINE): Reason'"; we keep the reason.
std::string parse_reason(const std::string& what) {
  const size_t close = what.rfind("): ");
  if (close == std::string::npos) return "";
  std::string r = what.substr(close + 3);
  while (!r.empty() && (r.back() == '\'' || r.back() == '\n' || r.back() == ' ')) r.pop_back();
  return r.size() > 120 ? r.substr(0, 120) : r;
}

Status open_storage(const std::string& path, cv::FileStorage* fs) {
  Result<std::string> text = read_text_file(path, kCalibrationFile);
  if (!text) return fail(text.error());
  const size_t first = text->find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return fail(path + ": empty file");
  if ((*text)[first] != '<') return open_yaml_file(path, kCalibrationFile, fs);
  if (Status st = check_xml_text(*text, path); !st) return st;
  try {
    fs->open(*text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_XML);
  } catch (const cv::Exception& e) {
    const std::string r = parse_reason(e.what());
    return fail(path + ": malformed XML" + (r.empty() ? "" : " (" + r + ")"));
  } catch (const std::exception&) {
    return fail(path + ": malformed XML");
  }
  if (!fs->isOpened()) return fail(path + ": malformed XML");
  return {};
}

bool is_number(const cv::FileNode& n) { return n.isInt() || n.isReal(); }

struct Numbers {
  std::vector<double> values;
  int rows = -1, cols = -1;   // -1: a plain list, no shape given
};

// A matrix as OpenCV writes it (!!opencv-matrix / type_id="opencv-matrix": rows, cols, dt, data), as ROS writes
// it (rows, cols, data), or a plain list of numbers.
Result<Numbers> read_numbers(const cv::FileNode& n, const std::string& where) {
  Numbers out;
  cv::FileNode data = n;
  if (n.isMap()) {
    const cv::FileNode r = n["rows"], c = n["cols"];
    if (!r.isInt() || !c.isInt()) return fail(where + ": a matrix needs whole numbers rows and cols");
    out.rows = int(r);
    out.cols = int(c);
    if (out.rows < 1 || out.cols < 1 || out.rows > kMaxValues || out.cols > kMaxValues)
      return fail(where + ": rows and cols must be 1.." + std::to_string(kMaxValues));
    data = n["data"];
    if (data.empty() && !data.isSeq()) return fail(where + ": a matrix needs data");
  }
  if (is_number(data)) {
    out.values.push_back(double(data));
  } else if (data.isSeq()) {
    if (data.size() > size_t(kMaxValues)) return fail(where + ": more than " + std::to_string(kMaxValues) + " values");
    int i = 0;
    for (cv::FileNodeIterator it = data.begin(); it != data.end(); ++it, ++i) {
      const cv::FileNode v = *it;
      if (!is_number(v)) return fail(where + ": value " + std::to_string(i) + " is not a number");
      out.values.push_back(double(v));
    }
  } else {
    return fail(where + ": expected numbers");
  }
  for (size_t i = 0; i < out.values.size(); ++i)
    if (!std::isfinite(out.values[i])) return fail(where + ": value " + std::to_string(i) + " is not a finite number");
  if (out.rows > 0 && size_t(out.rows) * size_t(out.cols) != out.values.size())
    return fail(where + ": " + std::to_string(out.rows) + "x" + std::to_string(out.cols) + " declared, " +
                std::to_string(out.values.size()) + " values given");
  return out;
}

// The first of `keys` that the file has, or "".
std::string find_key(const cv::FileNode& root, std::initializer_list<const char*> keys) {
  for (const char* k : keys)
    if (!root[k].empty() || root[k].isSeq() || root[k].isMap()) return k;
  return "";
}

Status read_camera_matrix(const cv::FileNode& root, const std::string& path, const std::string& key,
                          Calibration* c) {
  const std::string where = path + ": " + key;
  Result<Numbers> m = read_numbers(root[key], where);
  if (!m) return fail(m.error());
  const int rows = m->rows < 0 ? 1 : m->rows, cols = m->rows < 0 ? int(m->values.size()) : m->cols;
  if (m->values.size() != 9 || (m->rows > 0 && (m->rows != 3 || m->cols != 3)))
    return fail(where + ": expected 3x3 values, found " + std::to_string(rows) + "x" + std::to_string(cols));
  const std::vector<double>& v = m->values;
  c->camera_matrix = cv::Matx33d(v.data());
  if (v[3] != 0 || v[6] != 0 || v[7] != 0 || std::abs(v[8] - 1) > 1e-9)
    return fail(where + ": not a camera matrix (its last row must be 0 0 1 and the value under fx 0)");
  if (const std::string why = camera_matrix_problem(c->camera_matrix); !why.empty()) return fail(where + ": " + why);
  return {};
}

Status read_distortion(const cv::FileNode& root, const std::string& path, const std::string& key, Calibration* c) {
  const std::string where = path + ": " + key;
  Result<Numbers> m = read_numbers(root[key], where);
  if (!m) return fail(m.error());
  const size_t n = m->values.size();
  if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
    return fail(where + ": " + std::to_string(n) + " values; expected 4, 5, 8, 12 or 14 (k1 k2 p1 p2 [k3 ...])");
  if (m->rows > 0 && m->rows != 1 && m->cols != 1)
    return fail(where + ": expected one row or one column, found " + std::to_string(m->rows) + "x" +
                std::to_string(m->cols));
  c->distortion = m->values;
  return {};
}

Result<Calibration> read_root(const cv::FileNode& root, const std::string& path, bool need_distortion) {
  Calibration c;
  c.source = path;
  if (!root.isMap()) return fail(path + ": not a calibration (no keys at the top level)");
  const cv::FileNode model = root["distortion_model"];
  if (model.isString()) {
    const std::string m = model.string();
    if (m != "plumb_bob" && m != "rational_polynomial")
      return fail(path + ": distortion_model: " + (m.size() > 40 ? m.substr(0, 40) + "..." : m) +
                  " is not read (plumb_bob and rational_polynomial are)");
  }
  const std::string k = find_key(root, {"camera_matrix", "cameraMatrix"});
  if (k.empty()) return fail(path + ": no camera matrix (looked for camera_matrix, cameraMatrix)");
  if (Status st = read_camera_matrix(root, path, k, &c); !st) return fail(st.error());
  const std::string d = find_key(root, {"distortion_coefficients", "dist_coeffs", "distCoeffs"});
  if (d.empty()) {
    if (need_distortion)
      return fail(path + ": no distortion (looked for distortion_coefficients, dist_coeffs, distCoeffs)");
  } else if (Status st = read_distortion(root, path, d, &c); !st) {
    return fail(st.error());
  }
  // The image size: image_width/image_height (OpenCV's samples, ROS) or cameraResolution [w, h] (the
  // interactive-calibration app). Optional, but when given it must make sense.
  const cv::FileNode w = root["image_width"], h = root["image_height"], res = root["cameraResolution"];
  long long iw = 0, ih = 0;
  if (!w.empty() || !h.empty()) {
    if (!w.isInt() || !h.isInt()) return fail(path + ": image_width and image_height must be whole numbers");
    iw = int(w);
    ih = int(h);
  } else if (!res.empty()) {
    if (!res.isSeq() || res.size() != 2 || !res[0].isInt() || !res[1].isInt())
      return fail(path + ": cameraResolution must be two whole numbers");
    iw = int(res[0]);
    ih = int(res[1]);
  }
  if (iw != 0 || ih != 0) {
    if (iw < 1 || ih < 1 || iw > 65536 || ih > 65536)
      return fail(path + ": image size " + std::to_string(iw) + "x" + std::to_string(ih) + " is not 1..65536");
    c.image_size = cv::Size(int(iw), int(ih));
    if (const std::string why = camera_picture_problem(c.camera_matrix, c.distortion, c.image_size); !why.empty())
      return fail(path + ": " + why);
  }
  return c;
}

Result<Calibration> read_one(const std::string& path, bool need_distortion) {
  cv::FileStorage fs;
  if (Status st = open_storage(path, &fs); !st) return fail(st.error());
  try {
    return read_root(fs.root(), path, need_distortion);
  } catch (const std::exception&) {   // OpenCV's accessors on a node of an unexpected kind
    return fail(path + ": not a calibration (unexpected structure)");
  }
}

std::string size_text(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }
std::string ratio_text(cv::Size s) {
  const int g = std::gcd(s.width, s.height);
  return std::to_string(s.width / g) + ":" + std::to_string(s.height / g);
}

}  // namespace

Result<Calibration> read_calibration(const std::string& path) {
  Result<Calibration> c = read_one(path, false);
  if (!c) return c;
  if (!c->distortion.empty()) return c;
  // The paper's cameraMatrix.xml: its distortion is in distCoeffs.xml beside it.
  const std::filesystem::path sibling = std::filesystem::path(path).parent_path() / "distCoeffs.xml";
  std::error_code ec;
  if (std::filesystem::path(path).filename() == "cameraMatrix.xml" && std::filesystem::exists(sibling, ec))
    return read_calibration_pair(path, sibling.string());
  return fail(path + ": no distortion (looked for distortion_coefficients, dist_coeffs, distCoeffs)");
}

Result<Calibration> read_calibration_pair(const std::string& camera_matrix_path, const std::string& dist_coeffs_path) {
  Result<Calibration> k = read_one(camera_matrix_path, false);
  if (!k) return k;
  cv::FileStorage fs;
  if (Status st = open_storage(dist_coeffs_path, &fs); !st) return fail(st.error());
  Calibration c = *k;
  try {
    const cv::FileNode root = fs.root();
    if (!root.isMap()) return fail(dist_coeffs_path + ": not a calibration (no keys at the top level)");
    const std::string d = find_key(root, {"distCoeffs", "distortion_coefficients", "dist_coeffs"});
    if (d.empty())
      return fail(dist_coeffs_path + ": no distortion (looked for distCoeffs, distortion_coefficients, dist_coeffs)");
    if (Status st = read_distortion(root, dist_coeffs_path, d, &c); !st) return fail(st.error());
  } catch (const std::exception&) {
    return fail(dist_coeffs_path + ": not a calibration (unexpected structure)");
  }
  c.source = camera_matrix_path + " + " + dist_coeffs_path;
  return c;
}

Result<Calibration> calibration_for_size(const Calibration& c, cv::Size size) {
  Calibration out = c;
  if (!c.image_size.empty() && c.image_size != size) {   // empty(), not area(): 65536x65536 overflows an int
    const double a = double(c.image_size.width) * size.height, b = double(size.width) * c.image_size.height;
    if (std::abs(a - b) > 0.005 * std::max(a, b))
      return fail(c.source + ": made for " + size_text(c.image_size) + " (" + ratio_text(c.image_size) +
                  "), the source is " + size_text(size) + " (" + ratio_text(size) + "); calibrate at this size");
    const double sx = double(size.width) / c.image_size.width, sy = double(size.height) / c.image_size.height;
    // Pixel centres sit at integers, so the principal point scales about the image's corner at (-0.5, -0.5).
    out.camera_matrix(0, 0) *= sx;
    out.camera_matrix(0, 1) *= sx;
    out.camera_matrix(0, 2) = (c.camera_matrix(0, 2) + 0.5) * sx - 0.5;
    out.camera_matrix(1, 1) *= sy;
    out.camera_matrix(1, 2) = (c.camera_matrix(1, 2) + 0.5) * sy - 0.5;
    out.image_size = size;
    // Scaled, the focal length may leave the rule's range.
    if (std::string why = camera_matrix_problem(out.camera_matrix); !why.empty())
      return fail(c.source + ": at " + size_text(size) + ", " + why);
  }
  // Over the source's picture, whatever the reader checked: a file that names no size, and the paper's pair, whose
  // distortion is read from the second file after the size, are first checked here.
  if (std::string why = camera_picture_problem(out.camera_matrix, out.distortion, size); !why.empty())
    return fail(c.source + ": " + why);
  return out;
}

namespace {

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

Result<int> storage_format(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".xml") return int(cv::FileStorage::FORMAT_XML);
  if (ext == ".yml" || ext == ".yaml") return int(cv::FileStorage::FORMAT_YAML);
  return fail(path + ": the file name must end in .xml, .yml or .yaml");
}

// The text of a FileStorage that `fill` writes, in `format`.
Result<std::string> storage_text(const std::string& path, int format,
                                 const std::function<void(cv::FileStorage&)>& fill) {
  try {
    cv::FileStorage fs(".", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | format);
    fill(fs);
    return fs.releaseAndGetString();
  } catch (const cv::Exception&) {
    return fail(path + ": cannot write (OpenCV could not format the values)");
  }
}

using Files = std::vector<std::pair<std::string, std::string>>;

// The paper's cameraMatrix.xml and distCoeffs.xml in `dir`, added to `files`.
Status add_paper_files(const std::string& dir, const Calibration& c, Files* files) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return fail(dir + ": no such folder");
  const cv::Mat K(c.camera_matrix), D(1, int(c.distortion.size()), CV_64F, const_cast<double*>(c.distortion.data()));
  const std::string base = (std::filesystem::path(dir) / "").string();
  Result<std::string> k = storage_text(base + "cameraMatrix.xml", cv::FileStorage::FORMAT_XML,
                                       [&](cv::FileStorage& fs) { fs << "cameraMatrix" << K; });
  if (!k) return fail(k.error());
  Result<std::string> d = storage_text(base + "distCoeffs.xml", cv::FileStorage::FORMAT_XML,
                                       [&](cv::FileStorage& fs) { fs << "distCoeffs" << D; });
  if (!d) return fail(d.error());
  files->emplace_back(base + "cameraMatrix.xml", std::move(*k));
  files->emplace_back(base + "distCoeffs.xml", std::move(*d));
  return {};
}

Status write_together(const Files& files) {
  std::string failed, error;
  if (!write_files_atomically(files, &failed, &error)) return fail(failed + ": cannot write (" + error + ")");
  return {};
}

}  // namespace

Status write_calibration(const std::string& path, const Calibration& c, const CalibrationFileExtras& x,
                         const std::string& paper_dir) {
  Result<int> format = storage_format(path);
  if (!format) return fail(format.error());
  const cv::Mat K(c.camera_matrix), D(1, int(c.distortion.size()), CV_64F, const_cast<double*>(c.distortion.data()));
  Result<std::string> text = storage_text(path, *format, [&](cv::FileStorage& fs) {
    fs << "calibration_date" << (x.date.empty() ? utc_now() : x.date);
    fs << "image_width" << c.image_size.width << "image_height" << c.image_size.height;
    fs << "board" << x.board << "view_count" << x.view_count;
    fs << "camera_matrix" << K << "distortion_coefficients" << D;
    fs << "avg_reprojection_error" << x.avg_reprojection_error;
    fs << "per_view_reprojection_errors" << cv::Mat(x.per_view_reprojection_errors, true);
    fs << "std_dev_intrinsics_fx_fy_cx_cy" << cv::Mat(x.std_intrinsics, true);
    fs << "std_dev_distortion" << cv::Mat(x.std_distortion, true);
    fs << "notes" << "[";
    for (const std::string& n : x.notes) fs << n;
    fs << "]";
    // The paper's names, so its code reads this file unchanged.
    fs << "cameraMatrix" << K << "distCoeffs" << D;
  });
  if (!text) return fail(text.error());
  Files files{{path, std::move(*text)}};
  if (!paper_dir.empty())
    if (Status st = add_paper_files(paper_dir, c, &files); !st) return st;
  return write_together(files);
}

Status write_paper_files(const std::string& dir, const Calibration& c) {
  Files files;
  if (Status st = add_paper_files(dir, c, &files); !st) return st;
  return write_together(files);
}

}  // namespace arwb
