// `arwb markers`: PNGs that decode back to the dictionary's bits, sheets whose markers have the size asked for on
// paper, calibration boards (--board) on the paper they fit with the calibrate line that reads them, and one-line
// errors naming the bad value.
#include "synth/marker_sheet.hpp"
#include "detect/dictionary.hpp"
#include "support/support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

using arwb::test::run_arwb;
using arwb::test::TempDir;

constexpr double kMmPerPt = 25.4 / 72.0;

arwb::Dictionary dict(const std::string& name) {
  auto d = arwb::dictionary_by_name(name);
  EXPECT_TRUE(d.has_value()) << name;
  return *d;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + 1)) ++n;
  return n;
}

// An error is one line on stderr.
void expect_one_line_error(const arwb::test::RunResult& r, const std::string& names) {
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find(names), std::string::npos) << "stderr: " << r.err;
  EXPECT_EQ(count(r.err, "\n"), 1u) << "stderr: " << r.err;
  EXPECT_TRUE(r.out.empty()) << "stdout: " << r.out;
}

// ---- PNG output ---------------------------------------------------------------------------------------------------

// Samples a PNG at cell centres: a ring of quiet zone (white), a ring of border (black), then the inner bits.
void expect_png_is_marker(const std::string& file, const arwb::Dictionary& d, int id) {
  const cv::Mat img = cv::imread(file, cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(img.empty()) << file;
  const int cells = d.marker_size() + 4;  // quiet zone + border + bits + border + quiet zone
  ASSERT_EQ(img.cols, img.rows) << file;
  ASSERT_EQ(img.cols % cells, 0) << file;
  const int px = img.cols / cells;
  const cv::Mat bits = d.bits(id);
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) {
      const int v = img.at<uint8_t>(r * px + px / 2, c * px + px / 2);
      const int ring = std::min({r, c, cells - 1 - r, cells - 1 - c});
      int expected = 0;
      if (ring == 0) expected = 255;
      else if (ring == 1) expected = 0;
      else expected = bits.at<uint8_t>(r - 2, c - 2) ? 255 : 0;
      ASSERT_EQ(v, expected) << file << " cell (" << r << ", " << c << ")";
    }
}

std::set<std::string> files_in(const std::filesystem::path& dir) {
  std::set<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

TEST(MarkersCli, PngsOfArucoOriginalDecodeToTheirBits) {
  TempDir tmp;
  const std::string out = tmp.str("png/nested");  // created with its parents
  const auto r = run_arwb("markers --dict ARUCO_ORIGINAL --ids 0-9 --out '" + out + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote 10 "), std::string::npos) << r.out;
  EXPECT_EQ(count(r.out, "\n"), 1u) << r.out;
  const auto d = dict("ARUCO_ORIGINAL");
  std::set<std::string> expected;
  for (int id = 0; id <= 9; ++id) expected.insert("ARUCO_ORIGINAL_000" + std::to_string(id) + ".png");
  ASSERT_EQ(files_in(out), expected);
  for (int id = 0; id <= 9; ++id) {
    const std::string file = out + "/ARUCO_ORIGINAL_000" + std::to_string(id) + ".png";
    expect_png_is_marker(file, d, id);
    EXPECT_EQ(cv::imread(file, cv::IMREAD_GRAYSCALE).cols, (5 + 4) * 20) << "default 20 px per cell";
  }
}

TEST(MarkersCli, PngsOf4x4ForAListOfIdsAtAPixelSize) {
  TempDir tmp;
  const auto r = run_arwb("markers --dict 4x4_50 --ids 3,7 --px 7 --out '" + tmp.str("m") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(files_in(tmp.str("m")), (std::set<std::string>{"4X4_50_0003.png", "4X4_50_0007.png"}));
  const auto d = dict("4X4_50");
  for (int id : {3, 7}) {
    const std::string file = tmp.str("m") + "/4X4_50_000" + std::to_string(id) + ".png";
    expect_png_is_marker(file, d, id);
    EXPECT_EQ(cv::imread(file, cv::IMREAD_GRAYSCALE).cols, (4 + 4) * 7);
  }
}

TEST(MarkersCli, PngNamesArePaddedToFourDigits) {
  TempDir tmp;
  const auto r = run_arwb("markers --dict aruco_original --ids 1023,12 --out '" + tmp.str() + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(files_in(tmp.str()), (std::set<std::string>{"ARUCO_ORIGINAL_1023.png", "ARUCO_ORIGINAL_0012.png"}));
  expect_png_is_marker(tmp.str("ARUCO_ORIGINAL_1023.png"), dict("ARUCO_ORIGINAL"), 1023);
}

// ---- SVG sheets ---------------------------------------------------------------------------------------------------

std::string attribute(const std::string& element, const std::string& name) {
  const std::string key = " " + name + "=\"";
  const size_t pos = element.find(key);
  if (pos == std::string::npos) return "";
  const size_t start = pos + key.size();
  return element.substr(start, element.find('"', start) - start);
}

// An SVG length in millimetres; no unit means CSS pixels (96 per inch).
double length_mm(const std::string& value) {
  char* end = nullptr;
  const double v = std::strtod(value.c_str(), &end);
  const std::string unit = end;
  if (unit == "pt") return v * kMmPerPt;
  if (unit == "mm") return v;
  if (unit == "cm") return v * 10;
  if (unit == "in") return v * 25.4;
  if (unit == "px" || unit.empty()) return v * 25.4 / 96;
  ADD_FAILURE() << "unknown unit in " << value;
  return 0;
}

struct Box {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  double w() const { return x1 - x0; }
  double h() const { return y1 - y0; }
  bool contains(double x, double y) const { return x > x0 && x < x1 && y > y0 && y < y1; }
};

struct SvgPath {
  std::string style;
  std::vector<Box> subpaths;  // bounding boxes in millimetres on the page, degenerate ones left out
};

struct Svg {
  double width_mm = 0, height_mm = 0;
  std::vector<SvgPath> paths;  // the page's paths, glyph definitions left out
};

// Reads what cairo writes: a root with width, height and viewBox, glyphs in <defs>, then <path style d> elements with
// M, L, C and Z commands in absolute coordinates and an optional transform="matrix(...)".
Svg parse_svg(const std::string& text) {
  Svg svg;
  const size_t root = text.find("<svg");
  if (root == std::string::npos) {
    ADD_FAILURE() << "no <svg> element";
    return svg;
  }
  const std::string root_tag = text.substr(root, text.find('>', root) - root);
  svg.width_mm = length_mm(attribute(root_tag, "width"));
  svg.height_mm = length_mm(attribute(root_tag, "height"));
  std::istringstream vb(attribute(root_tag, "viewBox"));
  double vx = 0, vy = 0, vw = 0, vh = 0;
  vb >> vx >> vy >> vw >> vh;
  EXPECT_GT(vw, 0);
  const double sx = svg.width_mm / vw, sy = svg.height_mm / vh;

  const size_t defs_end = text.find("</defs>");
  for (size_t pos = text.find("<path", defs_end == std::string::npos ? 0 : defs_end); pos != std::string::npos;
       pos = text.find("<path", pos + 1)) {
    const std::string tag = text.substr(pos, text.find("/>", pos) - pos);
    // cairo writes fills in page coordinates and strokes with a transform (the line width is in user units).
    double m[6] = {1, 0, 0, 1, 0, 0};
    if (const std::string t = attribute(tag, "transform"); !t.empty()) {
      EXPECT_EQ(std::sscanf(t.c_str(), "matrix(%lf,%lf,%lf,%lf,%lf,%lf)", &m[0], &m[1], &m[2], &m[3], &m[4], &m[5]), 6)
          << t;
    }
    SvgPath p;
    p.style = attribute(tag, "style");
    std::istringstream d(attribute(tag, "d"));
    std::string tok;
    Box box;
    int points = 0;
    auto close_subpath = [&] {
      if (points >= 3) p.subpaths.push_back(box);
      box = Box{};
      points = 0;
    };
    while (d >> tok) {
      if (tok == "M") close_subpath();
      if (tok == "M" || tok == "L" || tok == "C") {
        for (int k = 0; k < (tok == "C" ? 3 : 1); ++k) {
          double ux = 0, uy = 0;
          d >> ux >> uy;
          const double x = (m[0] * ux + m[2] * uy + m[4] - vx) * sx;
          const double y = (m[1] * ux + m[3] * uy + m[5] - vy) * sy;
          box.x0 = std::min(box.x0, x), box.x1 = std::max(box.x1, x);
          box.y0 = std::min(box.y0, y), box.y1 = std::max(box.y1, y);
          ++points;
        }
      }
    }
    close_subpath();
    svg.paths.push_back(p);
  }
  return svg;
}

bool is_black_fill(const SvgPath& p) { return p.style.find("fill:rgb(0%,0%,0%)") != std::string::npos; }

// The sheet draws each marker as one black even-odd path: the outer black edge, then the white cells as holes.
std::vector<SvgPath> marker_paths(const Svg& svg) {
  std::vector<SvgPath> out;
  for (const auto& p : svg.paths)
    if (is_black_fill(p) && p.style.find("fill-rule:evenodd") != std::string::npos) out.push_back(p);
  return out;
}

// Reads the bits back from a marker path: a cell is white when its centre is inside an odd number of holes.
cv::Mat bits_of(const SvgPath& p, int marker_size) {
  const Box& outer = p.subpaths.front();
  const double cell = outer.w() / (marker_size + 2);
  cv::Mat bits(marker_size, marker_size, CV_8UC1);
  for (int r = 0; r < marker_size; ++r)
    for (int c = 0; c < marker_size; ++c) {
      const double x = outer.x0 + (c + 1.5) * cell, y = outer.y0 + (r + 1.5) * cell;
      int inside = 0;
      for (size_t k = 1; k < p.subpaths.size(); ++k) inside += p.subpaths[k].contains(x, y) ? 1 : 0;
      bits.at<uint8_t>(r, c) = static_cast<uint8_t>(inside % 2);
    }
  return bits;
}

void expect_same_bits(const cv::Mat& a, const cv::Mat& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_EQ(cv::countNonZero(a != b), 0) << what;
}

TEST(MarkersCli, SvgSheetIsA4WithOneMarkerPerIdAtTrueSize) {
  TempDir tmp;
  const std::string file = tmp.str("sheet.svg");
  const auto r = run_arwb("markers --dict 4X4_50 --ids 3,7,10-12 --size-mm 30 --out '" + file + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote 1 page"), std::string::npos) << r.out;
  const Svg svg = parse_svg(arwb::test::read_file(file));
  EXPECT_NEAR(svg.width_mm, 210.0, 0.1);
  EXPECT_NEAR(svg.height_mm, 297.0, 0.1);

  const auto markers = marker_paths(svg);
  ASSERT_EQ(markers.size(), 5u);
  const auto d = dict("4X4_50");
  const int ids[] = {3, 7, 10, 11, 12};
  for (size_t i = 0; i < markers.size(); ++i) {
    const Box& outer = markers[i].subpaths.front();
    EXPECT_NEAR(outer.w(), 30.0, 0.01) << "marker " << i;
    EXPECT_NEAR(outer.h(), 30.0, 0.01) << "marker " << i;
    // Inside the page margins.
    EXPECT_GE(outer.x0, 10.0);
    EXPECT_GE(outer.y0, 10.0);
    EXPECT_LE(outer.x1, 200.0);
    EXPECT_LE(outer.y1, 287.0);
    expect_same_bits(bits_of(markers[i], d.marker_size()), d.bits(ids[i]), "id " + std::to_string(ids[i]));
  }
}

TEST(MarkersCli, SvgMarkerOuterEdgeIs50mmAndQuietZoneIsClear) {
  TempDir tmp;
  const std::string file = tmp.str("one.svg");
  const auto r = run_arwb("markers --ids 7 --out '" + file + "'");  // ARUCO_ORIGINAL, 50 mm by default
  ASSERT_EQ(r.status, 0) << r.err;
  const Svg svg = parse_svg(arwb::test::read_file(file));
  const auto markers = marker_paths(svg);
  ASSERT_EQ(markers.size(), 1u);
  const Box outer = markers[0].subpaths.front();
  EXPECT_NEAR(outer.w(), 50.0, 0.01);
  EXPECT_NEAR(outer.h(), 50.0, 0.01);
  EXPECT_NEAR(outer.w() / kMmPerPt, 141.732, 0.01 / kMmPerPt);
  expect_same_bits(bits_of(markers[0], 5), dict("ARUCO_ORIGINAL").bits(7), "id 7");

  // Nothing else black comes within one cell of the black edge (the cut outline is grey, the label further down).
  const double cell = 50.0 / 7;
  for (const auto& p : svg.paths) {
    if (!is_black_fill(p) || p.style.find("fill-rule:evenodd") != std::string::npos) continue;
    for (const Box& b : p.subpaths) {
      const bool apart = b.x1 <= outer.x0 - cell || b.x0 >= outer.x1 + cell || b.y1 <= outer.y0 - cell ||
                         b.y0 >= outer.y1 + cell;
      EXPECT_TRUE(apart) << "black shape at " << b.x0 << "," << b.y0 << " is inside the quiet zone";
    }
  }

  // The measuring bar: a black rectangle exactly 100 mm long.
  bool bar = false;
  for (const auto& p : svg.paths)
    for (const Box& b : p.subpaths)
      if (is_black_fill(p) && std::abs(b.w() - 100.0) < 0.01 && b.h() < 3) bar = true;
  EXPECT_TRUE(bar) << "no 100 mm bar";
}

TEST(MarkersCli, SvgSheetOfManyMarkersIsOneFilePerPage) {
  TempDir tmp;
  const auto r = run_arwb("markers --ids 0-9 --size-mm 50 --out '" + tmp.str("s.svg") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto lay = arwb::sheet_layout(50, 5);
  ASSERT_EQ(lay.pages(10), 2);
  EXPECT_EQ(files_in(tmp.str()), (std::set<std::string>{"s.svg", "s-2.svg"}));
  const auto first = marker_paths(parse_svg(arwb::test::read_file(tmp.str("s.svg"))));
  const auto second = marker_paths(parse_svg(arwb::test::read_file(tmp.str("s-2.svg"))));
  EXPECT_EQ(static_cast<int>(first.size()), lay.per_page());
  EXPECT_EQ(first.size() + second.size(), 10u);
  expect_same_bits(bits_of(second.back(), 5), dict("ARUCO_ORIGINAL").bits(9), "last id on page 2");
}

// ---- PDF sheets ---------------------------------------------------------------------------------------------------

TEST(MarkersCli, A4HoldsSix50mmArucoOriginalMarkersTwoAcrossThreeDown) {
  // 50 mm with 7 cells: a 7.14 mm quiet zone each side and a 0.2 mm outline make a 64.7 mm piece, so two fit in the
  // 190 mm between the margins and three do not; 64.7 + 4.8 mm of label is 69.5 mm, and three such rows with 3 mm
  // gaps fit in the 263 mm above the measuring bar.
  const auto lay = arwb::sheet_layout(50, 5);
  EXPECT_EQ(lay.cols, 2);
  EXPECT_EQ(lay.rows, 3);
  EXPECT_EQ(lay.pages(50), 9);
  EXPECT_GE(lay.quiet_mm, lay.cell_mm);
}

TEST(MarkersCli, PdfSheetHasOnePagePerLayoutPage) {
  TempDir tmp;
  const std::string file = tmp.str("sheet.pdf");
  const auto r = run_arwb("markers --dict ARUCO_ORIGINAL --ids 0-49 --size-mm 50 --out '" + file + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string pdf = arwb::test::read_file(file);
  ASSERT_EQ(pdf.rfind("%PDF", 0), 0u);
  const int expected = arwb::sheet_layout(50, 5).pages(50);
  // Page objects say "/Type /Page"; the page tree says "/Type /Pages".
  const int pages = static_cast<int>(count(pdf, "/Type /Page")) - static_cast<int>(count(pdf, "/Type /Pages"));
  EXPECT_EQ(pages, expected);
  EXPECT_NE(r.out.find("wrote " + std::to_string(expected) + " pages"), std::string::npos) << r.out;
}

TEST(MarkersCli, SizesThatFitExactlyAndTheLargestAreAccepted) {
  const double largest = arwb::max_sheet_marker_mm(4);
  EXPECT_GT(largest, 100.0);
  EXPECT_LT(largest, 190.0);
  TempDir tmp;
  char size[32];
  std::snprintf(size, sizeof size, "%g", largest);
  EXPECT_EQ(run_arwb("markers --dict 4X4_50 --ids 0 --size-mm " + std::string(size) + " --out '" + tmp.str("a.pdf") +
                     "'").status, 0);
  EXPECT_EQ(run_arwb("markers --dict 4X4_50 --ids 0-3 --size-mm 5 --out '" + tmp.str("b.pdf") + "'").status, 0);
}

// ---- errors -------------------------------------------------------------------------------------------------------

TEST(MarkersCli, UnknownDictionaryIsNamed) {
  TempDir tmp;
  const auto r = run_arwb("markers --dict NO_SUCH_DICT --out '" + tmp.str("x") + "'");
  EXPECT_EQ(r.status, 2);
  expect_one_line_error(r, "NO_SUCH_DICT");
}

TEST(MarkersCli, IdOutsideTheDictionaryIsNamedWithTheRange) {
  TempDir tmp;
  const auto r = run_arwb("markers --dict 4X4_50 --ids 1,2000 --out '" + tmp.str("x") + "'");
  EXPECT_EQ(r.status, 2);
  expect_one_line_error(r, "2000");
  EXPECT_NE(r.err.find("0-49"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(tmp.str("x"))) << "nothing is written on an error";
}

TEST(MarkersCli, MalformedIdListsAreRejected) {
  TempDir tmp;
  for (const std::string ids : {"5-3", "a", "3,,4", "-3", "1-2-3", ""}) {
    const auto r = run_arwb("markers --ids '" + ids + "' --out '" + tmp.str("x") + "'");
    EXPECT_EQ(r.status, 2) << "--ids '" << ids << "'";
    expect_one_line_error(r, ids);
  }
}

TEST(MarkersCli, SizeOutsideTheRangeOrTooLargeForThePageIsNamed) {
  TempDir tmp;
  for (const std::string size : {"0", "4.9", "191", "abc", "nan"}) {
    const auto r = run_arwb("markers --size-mm " + size + " --out '" + tmp.str("s.pdf") + "'");
    EXPECT_EQ(r.status, 2) << size;
    expect_one_line_error(r, "--size-mm " + size);
  }
  const auto r = run_arwb("markers --size-mm 190 --out '" + tmp.str("s.svg") + "'");
  EXPECT_EQ(r.status, 2);
  expect_one_line_error(r, "--size-mm 190");
  EXPECT_FALSE(std::filesystem::exists(tmp.str("s.svg")));
}

TEST(MarkersCli, UnwritableOutputsAreNamed) {
  TempDir tmp;
  const std::string blocker = tmp.str("a_file");
  arwb::test::write_file(blocker, "not a folder");
  for (const std::string& out : {blocker, blocker + "/sub", blocker + "/sheet.pdf", blocker + "/sheet.svg",
                                std::string("/proc/x/sheet.pdf"), std::string("/proc/x")}) {
    const auto r = run_arwb("markers --ids 0-2 --out '" + out + "'");
    EXPECT_EQ(r.status, 1) << out;
    expect_one_line_error(r, "'" + out + "'");
  }
}

TEST(MarkersCli, UnknownOptionsAndHelp) {
  auto r = run_arwb("markers --frobnicate 3 --out x");
  EXPECT_EQ(r.status, 2);
  expect_one_line_error(r, "--frobnicate");

  r = run_arwb("markers --ids 0-3");
  EXPECT_EQ(r.status, 2);
  expect_one_line_error(r, "--out");

  r = run_arwb("markers --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("usage: arwb markers"), std::string::npos);
  EXPECT_NE(r.out.find("--size-mm"), std::string::npos);
  EXPECT_TRUE(r.err.empty());
}

// ---- calibration boards (--board) -------------------------------------------------------------------------------

// The page size of a one-page PDF in points, from its /MediaBox.
cv::Size2d media_box_pt(const std::string& pdf) {
  const size_t at = pdf.find("/MediaBox");
  if (at == std::string::npos) return {};
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  if (std::sscanf(pdf.c_str() + at, "/MediaBox [ %lf %lf %lf %lf ]", &x0, &y0, &x1, &y1) != 4) return {};
  return {x1 - x0, y1 - y0};
}

void expect_page_mm(const std::string& pdf_file, double w_mm, double h_mm) {
  const std::string pdf = arwb::test::read_file(pdf_file);
  ASSERT_EQ(pdf.rfind("%PDF", 0), 0u);
  const int pages = static_cast<int>(count(pdf, "/Type /Page")) - static_cast<int>(count(pdf, "/Type /Pages"));
  EXPECT_EQ(pages, 1);
  const cv::Size2d pt = media_box_pt(pdf);
  EXPECT_NEAR(pt.width, w_mm / kMmPerPt, 0.01);
  EXPECT_NEAR(pt.height, h_mm / kMmPerPt, 0.01);
}

TEST(MarkersBoard, ThePapersChessboardIsPrintedOnA3LandscapeWithTheLineThatReadsIt) {
  TempDir tmp;
  const auto r = run_arwb("markers --board chessboard --out '" + tmp.str("board.pdf") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_NE(r.out.find("chessboard 9x6 inner corners (10x7 squares), 25.00 mm squares, on A3 landscape"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("read it with: arwb calibrate --input VIDEO --board chessboard --cols 9 --rows 6 "
                       "--square-mm 25 --out camera.yml\n"), std::string::npos) << r.out;
  expect_page_mm(tmp.str("board.pdf"), 420, 297);
}

TEST(MarkersBoard, TheCalibrateLinePrintedIsOneCalibrateAccepts) {
  TempDir tmp;
  const auto r = run_arwb("markers --board chessboard --cols 7 --rows 5 --square-mm 22.5 --out '" + tmp.str("b.pdf") +
                          "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string key = "read it with: arwb ";
  const size_t at = r.out.find(key);
  ASSERT_NE(at, std::string::npos) << r.out;
  std::string line = r.out.substr(at + key.size());
  line = line.substr(0, line.find('\n'));
  EXPECT_NE(line.find("--cols 7 --rows 5 --square-mm 22.5"), std::string::npos) << line;
  // With a video that is not there, calibrate gets past its options and stops at the input.
  line.replace(line.find("VIDEO"), 5, "'" + tmp.str("no-such-video.mp4") + "'");
  line.replace(line.find("camera.yml"), 10, "'" + tmp.str("camera.yml") + "'");
  const auto c = run_arwb(line);
  EXPECT_NE(c.status, 0);
  EXPECT_NE(c.err.find("no-such-video.mp4"), std::string::npos) << c.err;
  EXPECT_EQ(c.err.find("--board"), std::string::npos) << c.err;
  EXPECT_EQ(c.err.find("--square-mm"), std::string::npos) << c.err;
}

TEST(MarkersBoard, TheDefaultChArUcoBoardFitsA4Portrait) {
  TempDir tmp;
  const auto r = run_arwb("markers --board charuco --out '" + tmp.str("charuco.pdf") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("ChArUco 5x7 squares (4x6 inner corners), 35.00 mm squares, 26.00 mm markers, DICT_5X5_100"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("on A4 portrait"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--board charuco --cols 5 --rows 7 --square-mm 35 --marker-mm 26 --dict DICT_5X5_100"),
            std::string::npos) << r.out;
  expect_page_mm(tmp.str("charuco.pdf"), 210, 297);
}

TEST(MarkersBoard, PaperCanBeChosenAndSvgIsOnePageAtTrueSize) {
  TempDir tmp;
  auto r = run_arwb("markers --board charuco --paper a3 --out '" + tmp.str("a3.pdf") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_page_mm(tmp.str("a3.pdf"), 297, 420);

  r = run_arwb("markers --board charuco --dict 4x4_50 --cols 6 --rows 4 --square-mm 30 --out '" +
               tmp.str("b.svg") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(files_in(tmp.str()), (std::set<std::string>{"a3.pdf", "b.svg"}));
  const Svg svg = parse_svg(arwb::test::read_file(tmp.str("b.svg")));
  EXPECT_NEAR(svg.width_mm, 210, 0.1) << "6x4 squares of 30 mm: 180 mm across, A4 portrait";
  EXPECT_NEAR(svg.height_mm, 297, 0.1);
  // The 12 markers, 22.5 mm (--marker-mm defaults to 3/4 of the square), with the bits of ids 0..11.
  const auto markers = marker_paths(svg);
  ASSERT_EQ(markers.size(), 12u);
  for (size_t i = 0; i < markers.size(); ++i) {
    EXPECT_NEAR(markers[i].subpaths.front().w(), 22.5, 0.01);
    expect_same_bits(bits_of(markers[i], 4), dict("4X4_50").bits(int(i)), "marker " + std::to_string(i));
  }
}

TEST(MarkersBoard, ABoardTooLargeIsRefusedWithTheLargestSquareAndNothingIsWritten) {
  TempDir tmp;
  const std::string file = tmp.str("big.pdf");
  arwb::test::write_file(file, "an older file");
  auto r = run_arwb("markers --board chessboard --square-mm 60 --out '" + file + "'");
  EXPECT_EQ(r.status, 2);
  expect_one_line_error(r, "the largest --square-mm that fits is ");
  EXPECT_EQ(arwb::test::read_file(file), "an older file");

  r = run_arwb("markers --board chessboard --paper a4 --out '" + tmp.str("a4.pdf") + "'");
  EXPECT_EQ(r.status, 2);
  expect_one_line_error(r, "--paper a4");
  EXPECT_FALSE(std::filesystem::exists(tmp.str("a4.pdf")));
}

TEST(MarkersBoard, BadOptionsAreNamedAndNothingIsWritten) {
  TempDir tmp;
  const std::string out = "--out '" + tmp.str("b.pdf") + "'";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--board circles " + out, "--board circles"},
      {"--board charuco --marker-mm 40 " + out, "--marker-mm 40"},
      {"--board chessboard --marker-mm 5 " + out, "--marker-mm is for a ChArUco board"},
      {"--board chessboard --dict 4X4_50 " + out, "--dict is for a ChArUco board"},
      {"--board charuco --dict NO_SUCH " + out, "--dict NO_SUCH"},
      {"--board charuco --dict 4X4_50 --cols 11 --rows 11 --square-mm 10 " + out,
       "--dict 4X4_50 has 50 markers; a 11x11 ChArUco board needs 60"},
      {"--board chessboard --cols 2 " + out, "--cols 2"},
      {"--board chessboard --square-mm 1.5 " + out, "--square-mm 1.5"},
      {"--board chessboard --square-mm -3 " + out, "--square-mm"},
      {"--board chessboard --paper a5 " + out, "--paper a5"},
      {"--board chessboard --ids 3 " + out, "--ids is for marker sheets"},
      {"--board chessboard --size-mm 30 " + out, "--size-mm is for marker sheets"},
      {"--cols 5 " + out, "--cols is for a calibration board"},
      {"--paper a3 " + out, "--paper is for a calibration board"},
      {"--board chessboard --out '" + tmp.str("folder") + "'", "a board is printed to FILE.pdf or FILE.svg"},
  };
  for (const auto& [args, names] : cases) {
    const auto r = run_arwb("markers " + args);
    EXPECT_EQ(r.status, 2) << args;
    expect_one_line_error(r, names);
  }
  EXPECT_TRUE(files_in(tmp.str()).empty());
}

TEST(MarkersBoard, AFailedWriteLeavesTheOlderFileAsItWas) {
  // The new page goes to a temporary file beside the old one first; here that name is taken by a folder.
  TempDir tmp;
  const std::string file = tmp.str("board.pdf");
  arwb::test::write_file(file, "an older board");
  std::filesystem::create_directory(file + ".arwb-saving");
  const auto r = run_arwb("markers --board chessboard --out '" + file + "'");
  EXPECT_EQ(r.status, 1);
  expect_one_line_error(r, "cannot write '" + file + "'");
  EXPECT_EQ(arwb::test::read_file(file), "an older board");
}

TEST(MarkersCli, AFailedPageOfAnSvgSheetLeavesEveryOlderPageAsItWas) {
  TempDir tmp;
  arwb::test::write_file(tmp.str("s.svg"), "old page 1");
  arwb::test::write_file(tmp.str("s-2.svg"), "old page 2");
  std::filesystem::create_directory(tmp.str("s-2.svg.arwb-page.arwb-saving"));   // page 2 cannot be made
  const auto r = run_arwb("markers --ids 0-9 --size-mm 50 --out '" + tmp.str("s.svg") + "'");
  EXPECT_EQ(r.status, 1);
  expect_one_line_error(r, "cannot write '" + tmp.str("s-2.svg") + "'");
  EXPECT_EQ(arwb::test::read_file(tmp.str("s.svg")), "old page 1");
  EXPECT_EQ(arwb::test::read_file(tmp.str("s-2.svg")), "old page 2");
  EXPECT_EQ(files_in(tmp.str()), (std::set<std::string>{"s.svg", "s-2.svg", "s-2.svg.arwb-page.arwb-saving"}));
}

TEST(MarkersBoard, AnUnwritableOutputIsNamed) {
  const auto r = run_arwb("markers --board chessboard --out /proc/x/board.pdf");
  EXPECT_EQ(r.status, 1);
  expect_one_line_error(r, "'/proc/x/board.pdf'");
}

}  // namespace
