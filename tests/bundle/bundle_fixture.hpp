// Shared by the bundle tests: a private TMPDIR, a folder's listing, an example copied and exported.
#pragma once

#include "bundle/bundle.hpp"

#include "support/support.hpp"

#include <filesystem>
#include <set>
#include <string>

namespace arwb::bundle::fixture {

namespace fs = std::filesystem;

inline const fs::path kScripts = fs::path(ARWB_SOURCE_DIR) / "scripts";

// Every file and folder under `dir`, relative, '/'-separated.
std::set<std::string> listing(const fs::path& dir);

// A private TMPDIR for the test's process, so the temporary folders open_bundle makes can be counted.
class PrivateTmp {
 public:
  PrivateTmp();
  ~PrivateTmp();
  std::set<std::string> contents() const { return listing(dir_.path()); }

 private:
  arwb::test::TempDir dir_;
  std::string old_;
  bool had_ = false;
};

// A copy of an example's folder in `into`.
fs::path copy_example(const std::string& name, const fs::path& into);

Status export_to(const fs::path& scene, const fs::path& out, const std::string& calib = "", bool force = false);

// The museum exported to `out` from a copy that is then removed.
void export_museum(const fs::path& out);

}  // namespace arwb::bundle::fixture
