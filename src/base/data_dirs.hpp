// Where this arwb's shipped data lies: the presets, the guided tour and the sample image (assets), the example
// scenes and the web player's site. An installed arwb (the Debian package: /usr/bin/arwb) finds them beside itself,
// in ../share/arwb; a binary in a build tree finds them in the source tree it was built from (the site, which the
// build assembles, in that build tree). One lookup, so every reader of shipped
// data agrees on the folder, and `arwb --help` names it.
#pragma once

#include <filesystem>
#include <string>

namespace arwb {

struct DataDirs {
  std::string assets;       // presets/, teaching/tour.txt, samples/
  std::string examples;     // the example scenes, one folder each (the source tree's scripts/)
  std::string web;          // the phone player's site that `arwb export --web` copies (a build tree's web/site)
  bool installed = false;   // found in ../share/arwb beside the executable, not in the source tree
};

// The lookup itself, for a given executable and source tree: `exe`'s folder's ../share/arwb when it holds an
// assets folder (share/arwb/assets and share/arwb/examples), else `source_tree`/assets and `source_tree`/scripts.
// `exe` is the real file (symbolic links resolved, as /proc/self/exe gives it); an empty `exe` (unknown) means the
// source tree. The web site is share/arwb/web, else `build_tree`/web/site. Nothing is read but whether that one
// folder exists.
DataDirs find_data_dirs(const std::filesystem::path& exe, const std::filesystem::path& source_tree,
                        const std::filesystem::path& build_tree = {});

// This process's: /proc/self/exe and the source tree this file was compiled in, looked up once.
const DataDirs& data_dirs();

}  // namespace arwb
