// Argument handling shared by the subcommands: options are `--name value` or `--name=value`; every option a
// command does not ask for is reported as unknown, so a typo never passes silently.
#pragma once

#include "detect/dictionary.hpp"
#include "detect/params.hpp"

#include <opencv2/videoio.hpp>

#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace arwb {

class Args {
 public:
  Args(int argc, char** argv);
  bool flag(const std::string& name);  // present without a value
  std::string value(const std::string& name, const std::string& fallback);
  int int_value(const std::string& name, int fallback, int lo, int hi);
  double double_value(const std::string& name, double fallback, double lo, double hi);
  // Arguments that are not options (or everything after "--").
  std::vector<std::string> positional();
  // For commands that take none: each one is an error ("unexpected argument 'x'"). True when there were none.
  bool no_positional();
  // False when a value was bad or an option was not asked for; then fail() prints the first reason in one line.
  bool ok();
  int fail(const char* command);

 private:
  std::vector<std::string> items_;
  std::vector<bool> used_;
  std::vector<std::string> errors_;
  std::set<std::string> known_;
  int find(const std::string& name);
};

// --dict NAME[,NAME...]: the dictionaries, or nullopt after printing "<command>: --dict <problem>".
std::optional<std::vector<Dictionary>> dictionaries_option(const std::string& list, const char* command);

// --params FILE.yml: loads the preset into p (an empty path changes nothing). On problems prints each as
// "<command>: --params <file>: <problem>" and returns false, leaving p as it was.
bool load_params_option(const std::string& path, const char* command, DetectorParams& p);

// "0-49", "3,7,10-12": ids in the order given, each once, all in the dictionary. nullopt and a message naming the
// bad part (and the dictionary's range) otherwise.
std::optional<std::vector<int>> parse_id_list(std::string_view spec, const Dictionary& dict, std::string* error);

// Opens `writer` on `path` through FFmpeg for 8-bit BGR frames: MJPG for .avi; otherwise H.264 ("avc1"), which
// plays in browsers and phones, else MPEG-4 part 2 ("mp4v"), which every FFmpeg build has. False when FFmpeg
// refused all; *codec names the one used.
bool open_video_writer(cv::VideoWriter& writer, const std::string& path, double fps, cv::Size size,
                       std::string* codec = nullptr);

}  // namespace arwb
