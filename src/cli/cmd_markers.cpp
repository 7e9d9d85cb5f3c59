// arwb markers: makes markers to use. A folder gets one PNG per marker, for documents, screens and test scenes; a
// .pdf or .svg file gets A4 sheets with the markers at a true physical size, which calibration and pose estimation
// rely on, plus a measuring bar to prove the printer kept that size. With --board, the calibration board `arwb
// calibrate` expects, at true size on A4 or A3, with the command that reads it printed under it.
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "synth/board_sheet.hpp"
#include "synth/marker_sheet.hpp"
#include "detect/dictionary.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace arwb {

namespace {

namespace fs = std::filesystem;

constexpr int kMinPx = 1, kMaxPx = 1000;
// Below this a printer's dot gain blurs a board's corners (and a ChArUco marker's cells) away.
constexpr double kMinBoardSquareMm = 2.0;

// A number as the user would type it back: as many digits as it has, no trailing zeros.
std::string format_g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

int fail(int status, const std::string& message) {
  print_problem("arwb markers: %s\n", message.c_str());
  return status;
}

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (auto& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

// One PNG per marker with a one-cell white quiet zone, since a detector needs white around the black border.
int write_pngs(const Dictionary& dict, const std::vector<int>& ids, int px, const std::string& dir) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    return fail(1, "cannot write PNGs to '" + dir + "': it exists and is not a folder");
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir, ec))
    return fail(1, "cannot create folder '" + dir + "': " + (ec ? ec.message() : "unknown reason"));
  int side = 0;
  for (int id : ids) {
    cv::Mat img;
    cv::copyMakeBorder(dict.render(id, px), img, px, px, px, px, cv::BORDER_CONSTANT, cv::Scalar(255));
    side = img.cols;
    char name[32];
    std::snprintf(name, sizeof name, "_%04d.png", id);
    const std::string file = (fs::path(dir) / (dict.name() + name)).string();
    bool ok = false;
    try {
      ok = cv::imwrite(file, img);
    } catch (const cv::Exception&) {
      ok = false;
    }
    if (!ok) return fail(1, "cannot write '" + file + "'");
  }
  std::printf("wrote %zu %s marker%s (%dx%d px) to %s\n", ids.size(), dict.name().c_str(), ids.size() == 1 ? "" : "s",
              side, side, dir.c_str());
  return 0;
}

// Runs a sheet's writer: nullopt when it wrote; else the status after the message, 2 for a sheet that cannot be
// made, 1 for a file that cannot be written.
template <typename Write>
std::optional<int> sheet_failure(Write write) {
  try {
    write();
  } catch (const std::invalid_argument& e) {
    return fail(2, e.what());
  } catch (const std::runtime_error& e) {
    return fail(1, e.what());
  }
  return std::nullopt;
}

int write_sheet(const Dictionary& dict, const std::vector<int>& ids, double size_mm, SheetFormat format,
                const std::string& path) {
  SheetResult r;
  if (const auto status = sheet_failure([&] { r = write_marker_sheet(dict, ids, size_mm, format, path); }))
    return *status;
  std::string files = r.files.front();
  if (r.files.size() == 2) files += ", " + r.files.back();
  if (r.files.size() > 2) files += ", " + r.files[1] + " ... " + r.files.back();
  std::printf("wrote %d page%s (%zu %s marker%s, %g mm) to %s\n", r.pages, r.pages == 1 ? "" : "s", ids.size(),
              dict.name().c_str(), ids.size() == 1 ? "" : "s", size_mm, files.c_str());
  return 0;
}

// The `arwb calibrate` line that looks for exactly this board (every board option spelt out).
std::string calibrate_line(const BoardSpec& b) {
  std::string line = "arwb calibrate --input VIDEO --board " + std::string(board_kind_name(b.kind)) + " --cols " +
                     std::to_string(b.cols) + " --rows " + std::to_string(b.rows) + " --square-mm " +
                     format_g(b.square_mm);
  if (b.kind == BoardKind::charuco) line += " --marker-mm " + format_g(b.marker_mm) + " --dict " + b.dictionary;
  return line + " --out camera.yml";
}

int write_board(const BoardSpec& board, PaperChoice paper, const std::string& out) {
  const std::string calibrate = calibrate_line(board);
  std::string problem;
  const auto layout = board_sheet_layout(board, paper, {board.describe(), "read it with: " + calibrate}, &problem);
  if (!layout) return fail(2, problem);
  const SheetFormat format = lower_extension(out) == ".svg" ? SheetFormat::svg : SheetFormat::pdf;
  if (const auto status = sheet_failure([&] { write_board_sheet(*layout, format, out); })) return *status;
  std::printf("wrote %s: %s, on %s\nread it with: %s\n", out.c_str(), board.describe().c_str(),
              layout->paper_name().c_str(), calibrate.c_str());
  return 0;
}

}  // namespace

int cmd_markers(int argc, char** argv) {
  std::string dicts;  // the names, for the help
  for (const auto& n : dictionary_names()) dicts += (dicts.empty() ? "" : ", ") + n;
  CommandLine cl("arwb markers",
                 "Writes markers as PNG images or as printable A4 sheets at true size; with --board, the calibration "
                 "board `arwb calibrate` expects, at true size on A4 or A3.");
  std::string dict_name, id_spec = "0-9", out, paper = "auto";
  double size_mm = 50;
  int px = 20;
  BoardOptions board_options;
  cl.app.add_option("--dict", dict_name,
                    "dictionary, case-insensitive (markers: ARUCO_ORIGINAL; --board charuco: DICT_5X5_100): " + dicts)
      ->type_name("NAME");
  cl.app.add_option("--ids", id_spec, "ids such as 0-49 or 3,7,10-12")->type_name("LIST");
  cl.app.add_option("--out", out,
                    "DIR: one PNG per marker, DIR/<dict>_<id>.png (id in 4 digits), with a one-cell white quiet zone; "
                    "DIR is created if needed.\n"
                    "FILE.pdf: A4 pages of markers at --size-mm, each in a one-cell quiet zone with a cut outline and "
                    "a label, and a 100 mm bar to check that the printer did not scale.\n"
                    "FILE.svg: the same as SVG, one file per page: FILE.svg, FILE-2.svg, ...\n"
                    "With --board: FILE.pdf or FILE.svg, one page with the board, what it is, the `arwb calibrate` "
                    "line that reads it and the 100 mm bar.")
      ->type_name("DIR|FILE.pdf|FILE.svg")
      ->required()
      ->check(out_kinds({".pdf", ".svg"}, true));
  cl.app.add_option("--size-mm", size_mm,
                    "sheets: the outer black edge of each marker, small enough to fit on the page with its quiet zone")
      ->type_name("MM")
      ->check(real_number(kSheetMinMarkerMm, kSheetMaxMarkerMm));
  cl.app.add_option("--px", px, "PNGs: pixels per cell")->type_name("N")->check(whole_number(kMinPx, kMaxPx));
  add_board_options(cl.app, board_options, false);
  cl.app.add_option("--paper", paper,
                    "--board: the paper; auto is the smallest of A4 and A3 that holds the board, portrait or "
                    "landscape")
      ->type_name("a4|a3|auto")
      ->check(CLI::IsMember({"a4", "a3", "auto"}));
  if (const auto status = cl.parse(argc, argv)) return *status;

  if (!board_options.kind.empty()) {
    for (const char* marker_only : {"--ids", "--size-mm", "--px"})
      if (cl.app.count(marker_only) > 0)
        return cl.usage_error(std::string(marker_only) + " is for marker sheets, not for --board");
    const std::string ext = lower_extension(out);
    if (ext != ".pdf" && ext != ".svg")
      return cl.usage_error("--out " + out + ": a board is printed to FILE.pdf or FILE.svg");
    board_options.dict = dict_name;
    std::string problem;
    const std::optional<BoardSpec> board = board_from_options(board_options, &problem);
    if (!board) return fail(2, problem);
    if (board->square_mm < kMinBoardSquareMm)
      return fail(2, "--square-mm " + format_g(board->square_mm) + " is too small to print and find; at least " +
                         format_g(kMinBoardSquareMm));
    const PaperChoice choice = paper == "a4"   ? PaperChoice::a4
                               : paper == "a3" ? PaperChoice::a3
                                               : PaperChoice::automatic;
    return write_board(*board, choice, out);
  }
  for (const char* board_only : {"--cols", "--rows", "--square-mm", "--marker-mm", "--paper"})
    if (cl.app.count(board_only) > 0)
      return cl.usage_error(std::string(board_only) + " is for a calibration board (--board chessboard|charuco)");
  if (dict_name.empty()) dict_name = "ARUCO_ORIGINAL";

  std::string error;
  const auto dict = dictionary_by_name(dict_name, &error);
  if (!dict) return fail(2, error);
  const auto ids = parse_id_list(id_spec, *dict, &error);
  if (!ids) return fail(2, error);

  const std::string ext = lower_extension(out);
  if (ext != ".pdf" && ext != ".svg") return write_pngs(*dict, *ids, px, out);

  if (!sheet_layout(size_mm, dict->marker_size()).fits())
    return fail(2, "--size-mm " + format_g(size_mm) + " does not fit on an A4 page: with a one-cell quiet zone and " +
                       format_g(kSheetMarginMm) + " mm margins, " + dict->name() + " markers can be at most " +
                       format_g(max_sheet_marker_mm(dict->marker_size())) + " mm");
  return write_sheet(*dict, *ids, size_mm, ext == ".pdf" ? SheetFormat::pdf : SheetFormat::svg, out);
}

}  // namespace arwb
