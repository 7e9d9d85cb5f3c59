#include "cli/cli_common.hpp"

#include "base/text.hpp"

#include <cctype>
#include <cstdarg>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <vector>

namespace arwb {

namespace {

constexpr size_t kHelpWidth = 110;

// `text` wrapped at kHelpWidth, each line after the first indented by `indent` spaces; '\n' starts a new line.
std::string wrap(const std::string& text, size_t first_column, size_t indent) {
  std::string out;
  size_t column = first_column;
  std::istringstream lines(text);
  std::string line;
  bool first_line = true;
  while (std::getline(lines, line)) {
    if (!first_line) {
      out += "\n" + std::string(indent, ' ');
      column = indent;
    }
    first_line = false;
    std::istringstream words(line);
    std::string word;
    bool first_word = true;
    while (words >> word) {
      if (!first_word && column + 1 + word.size() > kHelpWidth) {
        out += "\n" + std::string(indent, ' ');
        column = indent;
      } else if (!first_word) {
        out += ' ';
        ++column;
      }
      out += word;
      column += word.size();
      first_word = false;
    }
  }
  return out;
}

std::string format_g(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace

// Help in the house style, made from the options: the usage line (required options and arguments spelled out),
// what the command does, each option with its value's name, description, range and default, then the notes.
class HelpFormatter : public CLI::Formatter {
 public:
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, std::string>>>> sections;

  std::string make_help(const CLI::App* app, std::string, CLI::AppFormatMode) const override {
    const auto options = app->get_options([](const CLI::Option* o) { return o->nonpositional(); });
    const auto arguments = app->get_options([](const CLI::Option* o) { return o->get_positional(); });
    std::string usage = "usage: " + app->get_name();
    for (const CLI::Option* o : options)
      if (o->get_required()) usage += " " + o->get_name() + " " + value_name(o);
    usage += " [options]";
    for (const CLI::Option* o : arguments) {
      std::string name = o->get_name();
      if (o->get_expected_max() > 1) name += "...";
      usage += " " + (o->get_required() ? name : "[" + name + "]");
    }
    std::string out = wrap(usage, 0, 7) + "\n";
    if (!app->get_description().empty()) out += "\n" + wrap(app->get_description(), 0, 0) + "\n";
    auto table = [&out](const char* title, const std::vector<std::pair<std::string, std::string>>& rows) {
      if (rows.empty()) return;
      size_t column = 0;
      for (const auto& [left, _] : rows) column = std::max(column, left.size());
      column = std::min<size_t>(column, 24) + 4;
      out += std::string("\n") + title + ":\n";
      for (const auto& [left, text] : rows) {
        out += "  " + left;
        if (left.size() + 4 > column) out += "\n" + std::string(column, ' ');
        else out += std::string(column - left.size() - 2, ' ');
        out += wrap(text, column, column) + "\n";
      }
    };
    for (const auto& [title, section] : sections) table(title.c_str(), section);
    std::vector<std::pair<std::string, std::string>> rows;
    for (const CLI::Option* o : arguments) rows.emplace_back(o->get_name(), o->get_description());
    table("arguments", rows);
    rows.clear();
    auto in_order = options;  // --help last
    std::stable_partition(in_order.begin(), in_order.end(),
                          [app](const CLI::Option* o) { return o != app->get_help_ptr(); });
    for (const CLI::Option* o : in_order) {
      const std::string value = value_name(o);
      std::string names;  // "-h,--help" as "-h, --help"
      for (const char c : o->get_name(false, true)) names += c == ',' ? std::string(", ") : std::string(1, c);
      rows.emplace_back(names + (value.empty() ? "" : " " + value), option_text(o));
    }
    table("options", rows);
    if (!app->get_footer().empty()) out += "\n" + wrap(app->get_footer(), 0, 0) + "\n";
    return out;
  }

 private:
  // CLI11 appends ":<description>" of each validator to the type name; the ranges are those descriptions. (CLI11
  // 2.1 has no const access to an option's validators, hence the cast; nothing is changed.)
  static std::vector<std::string> ranges(const CLI::Option* o) {
    std::vector<std::string> out;
    auto* opt = const_cast<CLI::Option*>(o);
    for (int i = 0;; ++i) {
      try {
        if (const std::string d = opt->get_validator(i)->get_description(); !d.empty()) out.push_back(d);
      } catch (const CLI::OptionNotFound&) {
        return out;
      }
    }
  }
  static std::string value_name(const CLI::Option* o) {
    std::string t = o->get_type_name();
    for (const auto& r : ranges(o))
      if (t.size() > r.size()) t = t.substr(0, t.size() - r.size() - 1);
    return t;
  }
  static std::string option_text(const CLI::Option* o) {
    std::string text = o->get_description();
    std::vector<std::string> notes = ranges(o);
    if (!o->get_type_name().empty() && !o->get_default_str().empty()) notes.push_back("default " + o->get_default_str());
    if (o->get_required()) notes.push_back("required");
    if (!notes.empty()) {
      text += " (";
      for (size_t i = 0; i < notes.size(); ++i) text += (i ? "; " : "") + notes[i];
      text += ")";
    }
    return text;
  }
};

CommandLine::CommandLine(std::string command, std::string about, std::string notes)
    : app(std::move(about), command), command_(std::move(command)) {
  help_ = std::make_shared<HelpFormatter>();
  app.formatter(help_);
  app.set_help_flag("-h,--help", "this help");
  app.footer(std::move(notes));
  // Every option's help shows its default value (options whose default is "nothing" show none).
  app.option_defaults()->always_capture_default();
}

std::optional<int> CommandLine::parse(int argc, char** argv) {
  std::vector<std::string> args(argv, argv + argc);
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  try {
    app.parse(args);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return 0;
  } catch (const CLI::CallForVersion& e) {   // --version, where a command has one: its text is the version
    std::printf("%s\n", e.what());
    return 0;
  } catch (const CLI::ParseError& e) {
    return usage_error(describe(e));
  }
  // A required option given as "" is as missing as one not given.
  for (const CLI::Option* o : app.get_options())
    if (o->get_required() && o->count() > 0 && o->results().back().empty())
      return usage_error(o->get_name() + " needs a value");
  return std::nullopt;
}

void CommandLine::add_section(std::string title, std::vector<std::pair<std::string, std::string>> rows) {
  help_->sections.emplace_back(std::move(title), std::move(rows));
}

int CommandLine::usage_error(const std::string& problem) const {
  print_problem("%s: %s (see %s --help)\n", command_.c_str(), problem.c_str(), command_.c_str());
  return 2;
}

// CLI11's messages say what it expected; ours name the option and the value given, as "--threads 0: ...".
std::string CommandLine::describe(const CLI::ParseError& e) {
  const std::string what = e.what();
  const std::string name = what.substr(0, what.find(':'));
  const CLI::Option* opt = app.get_option_no_throw(name);
  // An unknown option comes first: it is likely a misspelt one, which would also be the missing required option.
  if (const auto rest = app.remaining(); !rest.empty()) {
    const std::string& first = rest.front();
    if (first.size() > 1 && first[0] == '-') return "unknown option " + first.substr(0, first.find('='));
    return "unexpected argument '" + first + "'";
  }
  if (opt && dynamic_cast<const CLI::ValidationError*>(&e)) {
    const auto& given = opt->results();
    return name + (given.empty() ? "" : " " + given.back()) + what.substr(name.size());
  }
  if (opt && dynamic_cast<const CLI::ArgumentMismatch*>(&e))
    return opt->count() > 1 ? name + " is given more than once" : name + " needs a value";
  return what;
}

CLI::Validator whole_number(long long lo, long long hi) {
  const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) {
        long long v = 0;
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
        if (text.empty() || ec != std::errc() || end != text.data() + text.size() || v < lo || v > hi)
          return "expected a whole number in " + range;
        return std::string();
      },
      range);
}

CLI::Validator real_number(double lo, double hi) {
  const std::string range = format_g(lo) + ".." + format_g(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || *end || !(v >= lo && v <= hi)) return "expected a number in " + range;
        return std::string();
      },
      range);
}

std::optional<cv::Size> parse_frame_size(std::string_view text) {
  const size_t x = text.find('x');
  if (x == std::string_view::npos) return std::nullopt;
  int w = 0, h = 0;
  const std::string_view ws = text.substr(0, x), hs = text.substr(x + 1);
  const auto a = std::from_chars(ws.data(), ws.data() + ws.size(), w);
  const auto b = std::from_chars(hs.data(), hs.data() + hs.size(), h);
  if (ws.empty() || hs.empty() || a.ec != std::errc() || a.ptr != ws.data() + ws.size() || b.ec != std::errc() ||
      b.ptr != hs.data() + hs.size() || w <= 0 || h <= 0)
    return std::nullopt;
  return cv::Size(w, h);
}

CLI::Validator frame_size(cv::Size lo, cv::Size hi, std::string word) {
  std::string range = std::to_string(lo.width) + "x" + std::to_string(lo.height) + ".." + std::to_string(hi.width) +
                      "x" + std::to_string(hi.height);
  const std::string expected = "expected WxH between " + std::to_string(lo.width) + "x" + std::to_string(lo.height) +
                               " and " + std::to_string(hi.width) + "x" + std::to_string(hi.height) +
                               (word.empty() ? "" : ", or " + word);
  if (!word.empty()) range += " or " + word;
  return CLI::Validator(
      [lo, hi, word, expected](std::string& text) {
        if (!word.empty() && text == word) return std::string();
        const auto s = parse_frame_size(text);
        if (!s || s->width < lo.width || s->height < lo.height || s->width > hi.width || s->height > hi.height)
          return expected;
        return std::string();
      },
      range);
}

CLI::Validator resize_value() {
  return CLI::Validator(
      [](std::string& t) {
        const CLI::Validator width = whole_number(16, 8192), size = frame_size({16, 16}, {8192, 8192}, "off");
        if (width(t).empty() || size(t).empty()) return std::string();
        return std::string("expected a width W in 16..8192, WxH between 16x16 and 8192x8192, or off");
      },
      "16..8192 or 16x16..8192x8192 or off");
}

CLI::Option* add_resize_option(CLI::App& app, std::string& text) {
  return app
      .add_option("--resize", text,
                  "the size each frame is resized to before detection: W (that width, the height from the source's "
                  "aspect), WxH (exactly, aspect not kept), or off (the source's own size)")
      ->type_name("W|WxH|off")
      ->check(resize_value());
}

CLI::Validator out_kinds(std::vector<std::string> files, bool folder) {
  std::string kinds;
  for (size_t i = 0; i < files.size(); ++i)
    kinds += std::string(i == 0 ? "" : (i + 1 == files.size() && !folder ? " or " : ", ")) + "FILE" + files[i];
  if (folder) kinds += std::string(files.empty() ? "" : " or ") + "a folder (a folder's name may end in '/')";
  return CLI::Validator(
      [files, folder, kinds](std::string& out) -> std::string {
        if (out.empty()) return "";   // said as "needs a value" by the command
        if (folder && out.back() == '/') return "";
        std::error_code ec;
        if (folder && std::filesystem::is_directory(out, ec)) return "";
        std::string ext = std::filesystem::path(out).extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        if (std::find(files.begin(), files.end(), ext) != files.end()) return "";
        // A folder may have a dot in its name; a suffix of letters and digits after it reads as a file's kind.
        const bool looks_like_a_file = ext.size() >= 2 && ext.size() <= 6 &&
                                       std::all_of(ext.begin() + 1, ext.end(), [](unsigned char c) { return std::isalnum(c); });
        if (folder && !looks_like_a_file) return "";
        return "a " + (ext.empty() ? std::string("name without an extension") : ext + " file") +
               " is not written here; expected " + kinds;
      },
      "", "output kind");
}

void apply_resize_option(const std::string& text, AcquisitionSettings& a) {
  a.resize = text != "off";
  if (!a.resize) return;
  if (const auto size = parse_frame_size(text)) a.size = *size;
  else a.size = {std::stoi(text), 0};   // checked: a width
}

void print_problem(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string line(n > 0 ? static_cast<size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(line.data(), line.size() + 1, format, again);
  va_end(again);
  if (!line.empty() && line.back() == '\n') line.pop_back();
  std::fputs((printable(line) + "\n").c_str(), stderr);
}

std::optional<std::vector<Dictionary>> dictionaries_option(const std::string& list, const char* command) {
  std::string err;
  auto dicts = parse_dictionaries(list, &err);
  if (!dicts) print_problem("%s: --dict %s\n", command, err.c_str());
  return dicts;
}

bool load_params_option(const std::string& path, const char* command, DetectorParams& p) {
  if (path.empty()) return true;
  std::vector<std::string> errors, notes;
  const bool ok = load_params_yaml(path, p, &errors, &notes);
  for (const auto& n : notes) print_problem("%s: --params %s\n", command, n.c_str());
  if (ok) return true;
  for (const auto& e : errors) print_problem("%s: --params %s\n", command, e.c_str());
  return false;
}

namespace {

// A whole string as a number of type T, or nullopt.
template <typename T>
std::optional<T> parse_number(std::string_view s) {
  T v{};
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

}  // namespace

std::optional<std::vector<int>> parse_id_list(std::string_view spec, const Dictionary& dict, std::string* error) {
  const long long size = dict.size();
  const std::string range = dict.name() + " has ids 0-" + std::to_string(size - 1);
  std::vector<int> ids;
  std::vector<bool> seen(static_cast<size_t>(size), false);
  size_t pos = 0;
  while (true) {
    const size_t comma = std::min(spec.find(',', pos), spec.size());
    const std::string_view item = spec.substr(pos, comma - pos);
    // Unsigned parsing rejects signs, so "-3" or "3--5" cannot slip through as a range.
    const size_t dash = item.find('-');
    const auto first = parse_number<unsigned long long>(item.substr(0, dash));
    const auto last = dash == std::string_view::npos ? first : parse_number<unsigned long long>(item.substr(dash + 1));
    if (!first || !last) {
      *error = "bad id list '" + std::string(spec) + "' at '" + std::string(item) + "' (expected e.g. 0-49 or 3,7,10-12)";
      return std::nullopt;
    }
    if (*first > *last) {
      *error = "bad id range '" + std::string(item) + "' in --ids (the first id is larger than the last)";
      return std::nullopt;
    }
    for (const unsigned long long id : {*first, *last})
      if (id >= static_cast<unsigned long long>(size)) {
        *error = "id " + std::to_string(id) + " is outside the dictionary: " + range;
        return std::nullopt;
      }
    for (auto id = *first; id <= *last; ++id)
      if (!seen[id]) {
        seen[id] = true;
        ids.push_back(static_cast<int>(id));
      }
    if (comma == spec.size()) break;
    pos = comma + 1;
  }
  return ids;
}


bool open_video_writer(cv::VideoWriter& writer, const std::string& path, double fps, cv::Size size,
                       std::string* codec) {
  const std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  const bool avi = ext == ".avi" || ext == ".AVI";
  for (const char* cc : avi ? std::vector<const char*>{"MJPG"} : std::vector<const char*>{"avc1", "mp4v"}) {
    if (writer.open(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc(cc[0], cc[1], cc[2], cc[3]), fps, size, true)) {
      if (codec) *codec = cc;
      return true;
    }
  }
  return false;
}

void add_board_options(CLI::App& app, BoardOptions& o, bool with_dict) {
  app.add_option("--board", o.kind, "the calibration board (default chessboard, the paper's)")
      ->type_name("chessboard|charuco")->check(CLI::IsMember({"chessboard", "charuco"}));
  // Their defaults depend on --board and are in the descriptions; the 0 each holds until given is not one.
  app.add_option("--cols", o.cols, "chessboard: inner corners across (9); charuco: squares across (5)")
      ->type_name("N")->check(whole_number(3, 40))->default_str("");
  app.add_option("--rows", o.rows, "chessboard: inner corners down (6); charuco: squares down (7)")
      ->type_name("N")->check(whole_number(3, 40))->default_str("");
  app.add_option("--square-mm", o.square_mm, "a square's side as printed (25; charuco 35)")->type_name("S")
      ->check(real_number(0.1, 1000))->default_str("");
  app.add_option("--marker-mm", o.marker_mm, "charuco: a marker's side, less than a square's (26)")->type_name("M")
      ->check(real_number(0.1, 1000))->default_str("");
  if (with_dict) app.add_option("--dict", o.dict, "charuco: the markers' dictionary (DICT_5X5_100)")->type_name("NAME");
}

std::optional<BoardSpec> board_from_options(const BoardOptions& o, std::string* problem) {
  BoardSpec b = default_board(o.kind == "charuco" ? BoardKind::charuco : BoardKind::chessboard);
  if (b.kind == BoardKind::chessboard && (o.marker_mm > 0 || !o.dict.empty())) {
    *problem = std::string(o.marker_mm > 0 ? "--marker-mm" : "--dict") + " is for a ChArUco board (--board charuco)";
    return std::nullopt;
  }
  if (o.cols > 0) b.cols = o.cols;
  if (o.rows > 0) b.rows = o.rows;
  if (o.square_mm > 0) b.square_mm = o.square_mm;
  if (o.marker_mm > 0) b.marker_mm = o.marker_mm;
  if (b.kind == BoardKind::charuco && o.square_mm > 0 && o.marker_mm <= 0) b.marker_mm = 0.75 * b.square_mm;
  if (!o.dict.empty()) {
    std::string error;
    const std::optional<Dictionary> d = dictionary_by_name(o.dict, &error);
    if (!d) {
      *problem = "--dict " + o.dict + ": " + error;
      return std::nullopt;
    }
    b.dictionary = d->name();
  }
  if (std::string p = b.problem(); !p.empty()) {
    *problem = p;
    return std::nullopt;
  }
  return b;
}

}  // namespace arwb
