// Opening a bundle someone sent, for playing: copied or extracted into a private temporary folder and verified
// there against its manifest, so what is checked is what runs (the original can change or vanish meanwhile).
#include "bundle/bundle.hpp"
#include "bundle/bundle_files.hpp"
#include "bundle/export_parts.hpp"

#include "base/files.hpp"
#include "calibration/calibration_file.hpp"
#include "detect/dictionary.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <set>

namespace arwb::bundle {

namespace fs = std::filesystem;

namespace {

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
    const std::string shown = shown_name(rel);   // a long name cut for the message
    if (const std::string problem = bundle_path_problem(rel); !problem.empty()) return fail(shown + ": " + problem);
    const fs::file_status st = it->symlink_status(ec);
    if (ec) break;
    if (fs::is_symlink(st)) return fail(shown + ": is a symbolic link");
    if (fs::is_directory(st)) {
      fs::create_directory(into / rel, ec);
      if (ec) return fail(shown + ": cannot be copied (" + ec.message() + ")");
      continue;
    }
    if (!fs::is_regular_file(st)) return fail(shown + ": is not a regular file");
    Result<std::string> bytes = read_whole_file(it->path(), limits.max_file_bytes, true);
    if (!bytes) return fail(shown + ": " + bytes.error().substr(std::min(bytes.error().size(), it->path().string().size() + 2)));
    total += bytes->size();
    if (total > limits.max_total_bytes)
      return fail(shown + ": the bundle is larger than " + std::to_string(limits.max_total_bytes) + " bytes, the limit");
    if (Status s = write_new_file(into / rel, *bytes); !s) return fail(shown + ": cannot be copied (" + s.error() + ")");
  }
  if (ec) return fail("cannot be listed (" + ec.message() + ")");
  return {};
}

// The folder's files against the manifest: each listed one there with its size and digest, nothing else.
Status verify(const fs::path& dir, const Manifest& m) {
  std::set<std::string> listed{kManifestName};
  for (const BundleFile& f : m.files) {
    listed.insert(f.path);
    const std::string shown = shown_name(f.path);
    Result<std::string> bytes = read_whole_file(dir / f.path, ~std::uint64_t(0) >> 1, true);
    std::error_code ec;
    if (!bytes) {
      if (!fs::exists(fs::symlink_status(dir / f.path, ec))) return fail(shown + ": missing (listed in the manifest)");
      // The reader's message names the private copy: only its reason is kept.
      const std::string why = bytes.error().substr(std::min(bytes.error().size(), (dir / f.path).string().size() + 2));
      return fail(shown + ": " + why);
    }
    if (bytes->size() != f.size)
      return fail(shown + ": changed since export (" + std::to_string(bytes->size()) + " bytes, the manifest says " +
                  std::to_string(f.size) + ")");
    if (sha256_hex(*bytes) != f.sha256) return fail(shown + ": changed since export (SHA-256 differs)");
  }
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (it->is_directory(ec)) continue;
    const std::string rel = it->path().lexically_relative(dir).generic_string();
    if (!listed.count(rel)) return fail(shown_name(rel) + ": not in the manifest");
  }
  if (ec) return fail("cannot be listed (" + ec.message() + ")");
  return {};
}

const char* const kRoles[] = {"scene", "media", "calibration", "sheet", "readme", "card", "web"};

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

Status bad(const std::string& field, const std::string& why) {
  return fail(std::string(kManifestName) + ": " + field + ": " + why);
}

// What the manifest says, beyond its syntax (parse_manifest): only what arwb export could have written. A hand
// edit that points the scene at a picture, names an unknown dictionary or an id it does not have, or marks a
// failed self-test is refused here, naming the field, rather than played as something else.
Status check_meaning(const Manifest& m) {
  std::string roles;
  for (const char* r : kRoles) roles += std::string(roles.empty() ? "" : ", ") + r;
  const BundleFile* scene = nullptr;
  const BundleFile* calibration = nullptr;
  for (size_t i = 0; i < m.files.size(); ++i) {
    const BundleFile& f = m.files[i];
    if (std::find(std::begin(kRoles), std::end(kRoles), f.role) == std::end(kRoles))
      return bad("files[" + std::to_string(i) + "].role", quoted_name(f.role) + " is not one of " + roles);
    if (f.path == m.scene) scene = &f;
    if (f.path == m.calibration) calibration = &f;
  }
  const std::string scene_ext = lower(std::filesystem::path(m.scene).extension().string());
  if (!scene || scene->role != "scene")
    return bad("scene", quoted_name(m.scene) + " is not listed as the scene (its role is " +
                            quoted_name(scene ? scene->role : std::string("none")) + ")");
  if (scene_ext != ".lua" && scene_ext != ".xml")
    return bad("scene", quoted_name(m.scene) + " is not a Lua scene or an XML database (.lua, .xml)");
  if (!m.calibration.empty() && (!calibration || calibration->role != "calibration"))
    return bad("calibration", quoted_name(m.calibration) + " is not listed as a calibration (its role is " +
                                  quoted_name(calibration ? calibration->role : std::string("none")) + ")");
  std::string dict_error;
  const std::optional<Dictionary> dict = dictionary_by_name(m.dictionary, &dict_error);
  if (!dict) return bad("dictionary", quoted_name(m.dictionary) + " is not a known dictionary");
  // arwb writes the scene's dictionary by its own name; another spelling was typed by hand, and the player
  // would detect with it whatever the scene uses.
  if (dict->name() != m.dictionary)
    return bad("dictionary", quoted_name(m.dictionary) + " is not how arwb names a dictionary (" + dict->name() + ")");
  if (m.ids.empty()) return bad("ids", "empty (a bundle maps at least one marker)");
  for (size_t i = 0; i < m.ids.size(); ++i) {
    if (m.ids[i] >= dict->size())
      return bad("ids[" + std::to_string(i) + "]", std::to_string(m.ids[i]) + " is not a marker of " + dict->name() +
                                                       " (ids 0 to " + std::to_string(dict->size() - 1) + ")");
    if (i > 0 && m.ids[i] <= m.ids[i - 1]) return bad("ids[" + std::to_string(i) + "]", "not in ascending order");
  }
  if (!m.self_test_passed)
    return bad("self_test_passed", "false (arwb export writes only bundles whose self-test passed)");
  return {};
}

// A reader's message about a file of the private copy, with the copy's folder taken out: the bundle's own path,
// which the caller puts first, says more ("scene/scene.lua:3: ..." rather than "/tmp/arwb-bundle-X/scene/...").
std::string without_copy_folder(std::string text, const fs::path& dir) {
  const std::string prefix = dir.string() + "/";
  for (size_t at = text.find(prefix); at != std::string::npos; at = text.find(prefix)) text.erase(at, prefix.size());
  return text;
}

// The scene, loaded as the player loads it (offline, from the copy): its dictionary and the markers it maps must be
// the manifest's, which the player's synthetic source shows. A manifest edited to list others is refused, naming
// the first id that differs.
Status check_scene(const std::filesystem::path& dir, const Manifest& m) {
  SceneStage stage(media::StoreMode::offline);
  if (!stage.load((dir / m.scene).string()))
    return bad("scene", quoted_name(m.scene) + " does not load (" + without_copy_folder(stage.status().error, dir) + ")");
  if (stage.runtime().dictionary_name() != m.dictionary)
    return bad("dictionary", quoted_name(m.dictionary) + " is not the scene's (" + stage.runtime().dictionary_name() + ")");
  std::set<int> mapped;
  for (const auto& ranges : stage.runtime().mapping_ids())
    for (const int id : expand(ranges)) mapped.insert(id);
  for (const int id : m.ids)
    if (!mapped.count(id)) return bad("ids", std::to_string(id) + " is not a marker the scene maps");
  for (const int id : mapped)
    if (!std::binary_search(m.ids.begin(), m.ids.end(), id))
      return bad("ids", "the scene maps " + std::to_string(id) + ", which is not listed");
  return {};
}

}  // namespace

OpenedBundle::~OpenedBundle() = default;
OpenedBundle::OpenedBundle(OpenedBundle&&) noexcept = default;
OpenedBundle& OpenedBundle::operator=(OpenedBundle&&) noexcept = default;

const fs::path& OpenedBundle::dir() const { return dir_.path(); }
const Manifest& OpenedBundle::manifest() const { return manifest_; }
std::string OpenedBundle::scene_path() const { return (dir_.path() / manifest_.scene).string(); }
std::string OpenedBundle::calibration_path() const {
  return manifest_.calibration.empty() ? std::string() : (dir_.path() / manifest_.calibration).string();
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
    // Every entry's name and kind first; then the manifest, from the zip itself: only the files it lists, at
    // their sizes, are inflated (a zip of other entries wrote gigabytes before it was refused).
    ZipLimits z{limits.max_entries, limits.max_file_bytes, limits.max_total_bytes, limits.max_ratio};
    if (Status s = check_zip(path, z); !s) return fail(s.error());
    Result<std::string> text = read_zip_entry(path, kManifestName, kMaxManifestBytes);
    if (!text) return fail(where + "no manifest.json (not a bundle made by arwb export)");
    Result<Manifest> m = parse_manifest(*text);
    if (!m) return fail(where + m.error());
    if (Status s = check_meaning(*m); !s) return fail(where + s.error());
    std::map<std::string, std::uint64_t> listed{{kManifestName, text->size()}};
    for (const BundleFile& f : m->files) listed[f.path] = f.size;
    z.listed = &listed;
    // extract_zip names the zip itself.
    if (Status s = extract_zip(path, tmp->path(), z); !s) return fail(s.error());
  } else {
    return fail(where + "not a bundle (neither a folder nor a zip)");
  }
  Result<std::string> text = read_whole_file(tmp->path() / kManifestName, kMaxManifestBytes, true);
  if (!text) return fail(where + "no manifest.json (not a bundle made by arwb export)");
  Result<Manifest> m = parse_manifest(*text);
  if (!m) return fail(where + m.error());
  if (Status s = check_meaning(*m); !s) return fail(where + s.error());
  if (Status s = verify(tmp->path(), *m); !s) return fail(where + s.error());
  // The calibration, now known to be the file that was exported, must read (with its distCoeffs.xml when it is
  // the paper's pair), as the player will read it.
  if (!m->calibration.empty())
    if (Result<Calibration> c = read_calibration((tmp->path() / m->calibration).string()); !c)
      return fail(where + std::string(kManifestName) + ": calibration: " + quoted_name(m->calibration) + " does not read (" +
                  without_copy_folder(c.error(), tmp->path()) + ")");
  if (Status s = check_scene(tmp->path(), *m); !s) return fail(where + s.error());
  OpenedBundle b;
  b.dir_ = std::move(*tmp);
  b.manifest_ = std::move(*m);
  b.source_ = path;
  return b;
}

}  // namespace arwb::bundle
