// Fuzz target: a bundle's manifest.json (src/bundle/manifest.cpp: parse_manifest), which arrives in a bundle
// someone sent. What it promises: a refusal is one line naming manifest.json; an accepted manifest has only
// relative paths that stay inside the bundle and 64-hex-digit digests, and writes back (manifest_json) to a text
// that reads again to the same manifest.
#include "bundle/bundle.hpp"
#include "bundle/bundle_files.hpp"

#include <cstdint>
#include <cstdlib>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace arwb::bundle;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const arwb::Result<Manifest> m = parse_manifest(text);
  if (!m) {
    if (m.error().rfind("manifest.json: ", 0) != 0 || m.error().find('\n') != std::string::npos) std::abort();
    return 0;
  }
  if (m->format_version > kFormatVersion) std::abort();
  for (const BundleFile& f : m->files)
    if (!bundle_path_problem(f.path).empty() || f.sha256.size() != 64) std::abort();
  if (!bundle_path_problem(m->scene).empty()) std::abort();
  const std::string again = manifest_json(*m);
  const arwb::Result<Manifest> back = parse_manifest(again);
  if (!back || manifest_json(*back) != again) std::abort();
  return 0;
}
