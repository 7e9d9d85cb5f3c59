// For targets whose entry point reads a named file (presets, dictionaries, scenes: their owners read them through
// the file checks of base/files.hpp, which are part of what is fuzzed): a scratch folder of this process, in
// memory when /dev/shm exists, removed at exit.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace arwb::fuzz {

inline const std::filesystem::path& scratch_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() {
      namespace fs = std::filesystem;
      std::error_code ec;
      const char* tmp = std::getenv("TMPDIR");
      fs::path base = fs::is_directory("/dev/shm", ec) && ::access("/dev/shm", W_OK) == 0 ? fs::path("/dev/shm")
                      : tmp ? fs::path(tmp) : fs::temp_directory_path();
      std::string templ = (base / "arwb-fuzz-XXXXXX").string();
      if (!::mkdtemp(templ.data())) std::abort();
      path = templ;
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static Dir dir;
  return dir.path;
}

// Replaces the file `name` in the scratch folder with these bytes; returns its path.
inline std::string write_scratch(const std::string& name, const uint8_t* data, size_t size) {
  const std::filesystem::path p = scratch_dir() / name;
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) std::abort();
  return p.string();
}

}  // namespace arwb::fuzz
