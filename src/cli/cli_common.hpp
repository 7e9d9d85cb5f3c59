// The command line shared by the subcommands and the workbench: options are declared once with CLI11 (name, type,
// description, default, range), and the help is made from them. Options are `--name value` or `--name=value`; an
// option nobody declared is an error, so a typo never passes silently.
#pragma once

#include "calibration/board.hpp"
#include "capture/acquisition.hpp"
#include "detect/dictionary.hpp"
#include "detect/params.hpp"

#include <CLI/CLI.hpp>
#include <opencv2/videoio.hpp>

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace arwb {

class HelpFormatter;  // the help's layout (cli_common.cpp)

// One command's line: declare options on `app`, then parse(). Errors are one line on stderr,
// "<command>: <problem> (see <command> --help)", with exit status 2; --help prints the help to stdout, status 0.
class CommandLine {
 public:
  // command: as typed ("arwb detect"); about: what it does (the help's first paragraph); notes: after the options.
  CommandLine(std::string command, std::string about, std::string notes = "");
  CLI::App app;
  // nullopt when the command should run; otherwise the exit status, the help or the error already printed.
  std::optional<int> parse(int argc, char** argv);
  // A table in the help before the options, e.g. the subcommands: rows of name and summary.
  void add_section(std::string title, std::vector<std::pair<std::string, std::string>> rows);
  // A problem found after parsing (a file, a combination of options): the same one-line shape, status 2.
  int usage_error(const std::string& problem) const;

 private:
  std::string command_;
  std::shared_ptr<HelpFormatter> help_;
  std::string describe(const CLI::ParseError& e);
};

// The one place where values are checked against their ranges; the range shows in the help (e.g. "1..64").
CLI::Validator whole_number(long long lo, long long hi);          // "expected a whole number in lo..hi"
CLI::Validator real_number(double lo, double hi);                 // "expected a number in lo..hi" (never NaN)
// WxH with each side in [lo, hi]; `word` (e.g. "off", "mixed"), when given, is accepted too.
CLI::Validator frame_size(cv::Size lo, cv::Size hi, std::string word = "");
// "640x480" as a size; nullopt unless the whole text is WxH of positive whole numbers.
std::optional<cv::Size> parse_frame_size(std::string_view text);

// --resize W|WxH|off, the acquisition's resize, declared once for every command that detects frames: W gives that
// width and the height of the source's aspect, WxH exactly that size (a picture of another aspect is squashed), off
// the source's own size. `text` holds the default and then what was given; apply_resize_option sets `a` from it.
CLI::Option* add_resize_option(CLI::App& app, std::string& text);
CLI::Validator resize_value();   // what --resize accepts, for an option of another name that means the same
void apply_resize_option(const std::string& text, AcquisitionSettings& a);   // text as checked by the option

// --out: a file of one of the kinds `files` (lower-case extensions with their dot, ".mp4"), or a folder when
// `folder`. A name with another extension (x.gif, x.txt) is refused naming the kinds accepted, not made into a
// folder of that name; a folder that exists, or a name ending in '/', is a folder whatever its name.
CLI::Validator out_kinds(std::vector<std::string> files, bool folder);

// Prints one line to stderr, formatted as printf does, with control characters escaped (base/text's printable):
// every problem the command line reports goes through here, so a file name holding "\x1B[31m", "\r" or a newline
// can neither act on the terminal nor forge a line. A trailing newline in the format is the line's own.
void print_problem(const char* format, ...) __attribute__((format(printf, 1, 2)));

// --dict NAME[,NAME...]: the dictionaries, or nullopt after printing "<command>: --dict <problem>".
std::optional<std::vector<Dictionary>> dictionaries_option(const std::string& list, const char* command);

// --params FILE.yml: loads the preset into p (an empty path changes nothing). On problems prints each as
// "<command>: --params <file>: <problem>" and returns false, leaving p as it was.
bool load_params_option(const std::string& path, const char* command, DetectorParams& p);

// "0-49", "3,7,10-12": ids in the order given, each once, all in the dictionary. nullopt and a message naming the
// bad part (and the dictionary's range) otherwise.
std::optional<std::vector<int>> parse_id_list(std::string_view spec, const Dictionary& dict, std::string* error);

// --board chessboard|charuco, --cols, --rows, --square-mm, --marker-mm, --dict: a calibration board, declared once
// for `arwb calibrate` and `arwb markers --board`. Defaults: the paper's chessboard (9x6 inner corners, 25 mm);
// for charuco, 5x7 squares of 35 mm with 26 mm markers of DICT_5X5_100 (fits A4), each unless given.
struct BoardOptions {
  std::string kind;
  int cols = 0, rows = 0;
  double square_mm = 0, marker_mm = 0;
  std::string dict;
};
// with_dict false leaves --dict to the command, which then fills o.dict itself (`arwb markers` has its own --dict).
void add_board_options(CLI::App& app, BoardOptions& o, bool with_dict = true);
// The board the options describe, or nullopt with *problem naming the option at fault.
std::optional<BoardSpec> board_from_options(const BoardOptions& o, std::string* problem);

// Opens `writer` on `path` through FFmpeg for 8-bit BGR frames: MJPG for .avi; otherwise H.264 ("avc1"), which
// plays in browsers and phones, else MPEG-4 part 2 ("mp4v"), which every FFmpeg build has. False when FFmpeg
// refused all; *codec names the one used.
bool open_video_writer(cv::VideoWriter& writer, const std::string& path, double fps, cv::Size size,
                       std::string* codec = nullptr);

}  // namespace arwb
