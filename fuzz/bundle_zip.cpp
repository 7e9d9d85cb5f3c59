// Fuzz target: opening a bundle that arrives as a zip (src/bundle/open.cpp: open_bundle, with
// bundle_files.cpp's extract_zip), the player's first step on a file someone sent. Small limits (64 entries,
// 1 MiB a file, 4 MiB in all, the default ratio) keep every input quick. What it promises: a refusal is one line
// naming the zip, and leaves nothing behind in the temporary folder; an opened bundle's folder holds exactly the
// manifest's files and is gone once the bundle is.
#include "bundle/bundle.hpp"
#include "fuzz_files.hpp"

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fs = std::filesystem;
  // open_bundle's private folders go into a scratch TMPDIR of this process, which must be empty after each input.
  static const fs::path tmp = [] {
    const fs::path p = arwb::fuzz::scratch_dir() / "tmp";
    fs::create_directories(p);
    setenv("TMPDIR", p.c_str(), 1);
    return p;
  }();
  const std::string zip = arwb::fuzz::write_scratch("bundle.arwb", data, size);
  arwb::bundle::BundleLimits limits;
  limits.max_entries = 64;
  limits.max_file_bytes = 1u << 20;
  limits.max_total_bytes = 4u << 20;
  {
    arwb::Result<arwb::bundle::OpenedBundle> b = arwb::bundle::open_bundle(zip, limits);
    if (!b) {
      if (b.error().rfind(zip, 0) != 0 || b.error().find('\n') != std::string::npos) std::abort();
    } else {
      size_t files = 0;
      for (const auto& e : fs::recursive_directory_iterator(b->dir()))
        if (!e.is_directory()) ++files;
      if (files != b->manifest().files.size() + 1) std::abort();   // and manifest.json
    }
  }
  if (!fs::is_empty(tmp)) std::abort();
  return 0;
}
