#include "base/data_dirs.hpp"

#include <system_error>

// The source tree, for a binary run where it was built; set by src/base/CMakeLists.txt for this file alone.
#ifndef ARWB_SOURCE_TREE
#define ARWB_SOURCE_TREE "."
#endif
#ifndef ARWB_BUILD_TREE
#define ARWB_BUILD_TREE "."
#endif

namespace arwb {

namespace fs = std::filesystem;

DataDirs find_data_dirs(const fs::path& exe, const fs::path& source_tree, const fs::path& build_tree) {
  if (!exe.empty()) {
    // bin/arwb -> share/arwb: the layout of /usr, /usr/local or any prefix `cmake --install` was given.
    const fs::path share = (exe.parent_path().parent_path() / "share" / "arwb").lexically_normal();
    std::error_code ec;
    if (fs::is_directory(share / "assets", ec))
      return {(share / "assets").string(), (share / "examples").string(), (share / "web").string(), true};
  }
  return {(source_tree / "assets").lexically_normal().string(), (source_tree / "scripts").lexically_normal().string(),
          (build_tree / "web" / "site").lexically_normal().string(), false};
}

const DataDirs& data_dirs() {
  static const DataDirs dirs = [] {
    std::error_code ec;
    // The real file: a link to it (a user's ~/bin/arwb -> /usr/bin/arwb) does not move its data.
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return find_data_dirs(ec ? fs::path() : exe, ARWB_SOURCE_TREE, ARWB_BUILD_TREE);
  }();
  return dirs;
}

}  // namespace arwb
