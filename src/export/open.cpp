// Opening a bundle someone sent, for playing: copied or extracted into a private temporary folder and verified
// there against its manifest, so what is checked is what runs (the original can change or vanish meanwhile).
#include "export/bundle.hpp"
#include "export/bundle_files.hpp"

#include <set>

namespace arwb::bundle {

namespace fs = std::filesystem;

namespace {

constexpr std::uint64_t kMaxManifestBytes = 16u << 20;

// Copies the folder `from` into `into` (empty), regular files and folders only, refusing symbolic links and
// anything else by name, within the limits.
Status copy_folder(const fs::path& from, const fs::path& into, const BundleLimits& limits) {
  std::error_code ec;
  std::size_t entries = 0;
  std::uint64_t total = 0;
  std::vector<std::pair<fs::path, std::string>> files;
  for (auto it = fs::recursive_directory_iterator(from, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    const std::string rel = it->path().lexically_relative(from).generic_string();
    if (++entries > limits.max_entries)
      return fail("more than " + std::to_string(limits.max_entries) + " files and folders, the limit");
    if (const std::string problem = bundle_path_problem(rel); !problem.empty()) return fail(rel + ": " + problem);
    const fs::file_status st = it->symlink_status(ec);
    if (ec) break;
    if (fs::is_symlink(st)) return fail(rel + ": is a symbolic link");
    if (fs::is_directory(st)) {
      fs::create_directory(into / rel, ec);
      if (ec) return fail(rel + ": cannot be copied (" + ec.message() + ")");
      continue;
    }
    if (!fs::is_regular_file(st)) return fail(rel + ": is not a regular file");
    Result<std::string> bytes = read_whole_file(it->path(), limits.max_file_bytes, true);
    if (!bytes) return fail(rel + ": " + bytes.error().substr(std::min(bytes.error().size(), it->path().string().size() + 2)));
    total += bytes->size();
    if (total > limits.max_total_bytes)
      return fail(rel + ": the bundle is larger than " + std::to_string(limits.max_total_bytes) + " bytes, the limit");
    if (Status s = write_new_file(into / rel, *bytes); !s) return fail(rel + ": cannot be copied (" + s.error() + ")");
  }
  if (ec) return fail("cannot be listed (" + ec.message() + ")");
  return {};
}

// The folder's files against the manifest: each listed one there with its size and digest, nothing else.
Status verify(const fs::path& dir, const Manifest& m) {
  std::set<std::string> listed{kManifestName};
  for (const BundleFile& f : m.files) {
    listed.insert(f.path);
    Result<std::string> bytes = read_whole_file(dir / f.path, ~std::uint64_t(0) >> 1, true);
    std::error_code ec;
    if (!bytes) {
      if (!fs::exists(fs::symlink_status(dir / f.path, ec))) return fail(f.path + ": missing (listed in the manifest)");
      return fail(f.path + ": " + bytes.error());
    }
    if (bytes->size() != f.size)
      return fail(f.path + ": changed since export (" + std::to_string(bytes->size()) + " bytes, the manifest says " +
                  std::to_string(f.size) + ")");
    if (sha256_hex(*bytes) != f.sha256) return fail(f.path + ": changed since export (SHA-256 differs)");
  }
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (it->is_directory(ec)) continue;
    const std::string rel = it->path().lexically_relative(dir).generic_string();
    if (!listed.count(rel)) return fail(rel + ": not in the manifest");
  }
  if (ec) return fail("cannot be listed (" + ec.message() + ")");
  return {};
}

}  // namespace

OpenedBundle::~OpenedBundle() {
  std::error_code ec;
  if (!dir_.empty()) fs::remove_all(dir_, ec);
}

OpenedBundle::OpenedBundle(OpenedBundle&& o) noexcept
    : dir_(std::move(o.dir_)), manifest_(std::move(o.manifest_)), source_(std::move(o.source_)) {
  o.dir_.clear();
}

OpenedBundle& OpenedBundle::operator=(OpenedBundle&& o) noexcept {
  if (this != &o) {
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
    dir_ = std::move(o.dir_);
    manifest_ = std::move(o.manifest_);
    source_ = std::move(o.source_);
    o.dir_.clear();
  }
  return *this;
}

const fs::path& OpenedBundle::dir() const { return dir_; }
const Manifest& OpenedBundle::manifest() const { return manifest_; }
std::string OpenedBundle::scene_path() const { return (dir_ / manifest_.scene).string(); }
std::string OpenedBundle::calibration_path() const {
  return manifest_.calibration.empty() ? std::string() : (dir_ / manifest_.calibration).string();
}
const std::string& OpenedBundle::source() const { return source_; }

Result<OpenedBundle> open_bundle(const std::string& path, const BundleLimits& limits) {
  const std::string where = path + ": ";
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) return fail(where + "no such file or folder");
  Result<TempDir> tmp = TempDir::make({}, "arwb-bundle");
  if (!tmp) return fail(where + tmp.error());
  if (fs::is_directory(st)) {
    if (Status s = copy_folder(path, tmp->path(), limits); !s) return fail(where + s.error());
  } else if (looks_like_zip(path)) {
    ZipLimits z{limits.max_entries, limits.max_file_bytes, limits.max_total_bytes, limits.max_ratio};
    // extract_zip names the zip itself.
    if (Status s = extract_zip(path, tmp->path(), z); !s) return fail(s.error());
  } else {
    return fail(where + "not a bundle (neither a folder nor a zip)");
  }
  Result<std::string> text = read_whole_file(tmp->path() / kManifestName, kMaxManifestBytes, true);
  if (!text) return fail(where + "no manifest.json (not a bundle made by arwb export)");
  Result<Manifest> m = parse_manifest(*text);
  if (!m) return fail(where + m.error());
  if (Status s = verify(tmp->path(), *m); !s) return fail(where + s.error());
  OpenedBundle b;
  b.dir_ = tmp->keep();
  b.manifest_ = std::move(*m);
  b.source_ = path;
  return b;
}

}  // namespace arwb::bundle
