// Writing a bundle (export_parts.hpp): where it goes (--out), what an existing one there must be to be replaced,
// and write_export, which builds the whole bundle beside --out and renames it into place, so that a failure
// leaves nothing behind and the old bundle whole.
#include "bundle/export_parts.hpp"

#include "bundle/bundle_files.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <set>

namespace arwb::bundle {

namespace fs = std::filesystem;

bool is_zip_name(const std::string& out) {
  std::string ext = fs::path(out).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".zip" || ext == ".arwb";
}

fs::path out_path(const std::string& out) {
  fs::path p = fs::absolute(out).lexically_normal();
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();
  return p;
}

std::string lower_ext(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

namespace {

// Whether `out` is something this export may replace: a bundle arwb wrote, holding nothing else. `as_zip`: the
// new bundle is a zip (its name ends in .arwb or .zip), so a plain file there was at least meant as one.
Status replaceable(const fs::path& out, bool as_zip) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(out, ec);
  const std::string shown = out.string();
  if (fs::is_symlink(st)) return fail(shown + " is a symbolic link; not replacing it");
  if (fs::is_directory(st)) {
    Result<std::string> text = read_whole_file(out / kManifestName, kMaxManifestBytes, true);
    if (!text) return fail(shown + " is not a bundle (no readable manifest.json); not replacing it");
    Result<Manifest> m = parse_manifest(*text);
    if (!m) return fail(shown + " is not a bundle arwb can read (" + m.error() + "); not replacing it");
    std::set<std::string> listed{kManifestName};
    std::set<std::string> folders;
    for (const BundleFile& f : m->files) {
      listed.insert(f.path);
      for (size_t slash = f.path.find('/'); slash != std::string::npos; slash = f.path.find('/', slash + 1))
        folders.insert(f.path.substr(0, slash));
    }
    for (auto it = fs::recursive_directory_iterator(out, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
      const std::string rel = it->path().lexically_relative(out).generic_string();
      const bool folder = it->is_directory(ec) && !it->is_symlink(ec);
      if (folder ? !folders.count(rel) : !listed.count(rel))
        return fail(shown + " holds " + rel + ", which is not part of its bundle; not replacing it");
    }
    if (ec) return fail(shown + ": cannot be listed (" + ec.message() + ")");
    return {};
  }
  if (fs::is_regular_file(st)) {
    if (!as_zip) return fail(shown + " is a file, not a bundle folder; not replacing it");
    if (!looks_like_zip(out)) return fail(shown + " is not a zip; not replacing it");
    Result<std::string> text = read_zip_entry(out, kManifestName, kMaxManifestBytes);
    if (!text) return fail(shown + " is not a bundle (" + text.error() + "); not replacing it");
    if (Result<Manifest> m = parse_manifest(*text); !m)
      return fail(shown + " is not a bundle arwb can read (" + m.error() + "); not replacing it");
    return {};
  }
  return fail(shown + " is not a file or folder; not replacing it");
}

}  // namespace

Status check_out(const ExportOptions& o) {
  if (o.out.empty()) return fail("--out: no bundle named");
  if (const std::string problem = out_name_problem(o.out); !problem.empty()) return fail("--out " + o.out + ": " + problem);
  const fs::path out = out_path(o.out);
  std::error_code ec;
  const fs::path parent = out.parent_path();
  if (!fs::is_directory(parent, ec)) return fail("--out " + o.out + ": the folder " + parent.string() + " does not exist");
  if (fs::symlink_status(out, ec).type() != fs::file_type::not_found) {
    if (!o.force) return fail("--out " + o.out + " exists; add --force to replace it");
    if (Status s = replaceable(out, is_zip_name(o.out)); !s) return fail("--out " + s.error());
  }
  return {};
}

std::string out_name_problem(const std::string& out) {
  // ".arwb" alone has no extension to the file system, and was written as a folder of that name.
  const std::string file = out_path(out).filename().string();
  if (const std::string ext = lower_ext(fs::path("x" + file)); (ext == ".arwb" || ext == ".zip") && file.size() == ext.size())
    return "the bundle has no name before " + file + " (write NAME" + file + ")";
  // "mz.arwb/" once replaced the zip mz.arwb with a folder of that name: a zip's name stays a zip's name.
  if (!out.empty() && !is_zip_name(out) && is_zip_name(out_path(out).string()))
    return "a name ending in " + lower_ext(out_path(out)) +
           " is a zip bundle; drop the trailing '/' (or name a folder without .arwb or .zip)";
  return "";
}

Status write_export(const ExportPlan& plan) {
  const ExportOptions& o = plan.options;
  if (Status s = check_out(o); !s) return s;
  const fs::path out = out_path(o.out);
  std::error_code ec;
  const bool exists = fs::symlink_status(out, ec).type() != fs::file_type::not_found;

  // Every byte in memory first, the sources checked against their planned digests: a file changed since the
  // plan is named, and nothing is written.
  std::vector<std::pair<std::string, std::string>> entries;
  std::map<std::string, std::string> planned;
  for (const BundleFile& f : plan.manifest.files) planned[f.path] = f.sha256;
  for (const auto& [path, source] : plan.sources) {
    Result<std::string> bytes = read_whole_file(source, kMaxSourceBytes, false);
    if (!bytes) return fail(bytes.error());
    if (sha256_hex(*bytes) != planned[path]) return fail(source + ": changed since it was checked; export again");
    entries.emplace_back(path, std::move(*bytes));
  }
  for (const auto& g : plan.generated) entries.push_back(g);
  std::sort(entries.begin(), entries.end());

  say(o, "writing " + o.out);
  // Built by appending: GCC 12 warns wrongly (-Wrestrict) on "." + a temporary string here.
  std::string stem = ".";
  stem.append(out.filename().string()).append(".partial");
  Result<TempDir> tmp = TempDir::make(out.parent_path(), stem);
  if (!tmp) return fail("--out " + o.out + ": " + tmp.error());
  const fs::path made = tmp->path() / "bundle";
  if (is_zip_name(o.out)) {
    if (Status s = write_zip(made, entries); !s) return s;
  } else {
    fs::create_directory(made, ec);
    if (ec) return fail(made.string() + ": cannot be created (" + ec.message() + ")");
    for (const auto& [path, bytes] : entries) {
      const fs::path target = made / path;
      fs::create_directories(target.parent_path(), ec);
      if (ec) return fail(target.string() + ": cannot be created (" + ec.message() + ")");
      if (Status s = write_new_file(target, bytes); !s) return s;
    }
    ::chmod(made.c_str(), 0755);   // mkdtemp's 0700 is for the unfinished bundle only
  }
  // Into place: the old bundle (checked to be one) moves into the temporary folder and goes with it.
  const fs::path old = tmp->path() / "old";
  if (exists) {
    if (Status s = replaceable(out, is_zip_name(o.out)); !s) return fail("--out " + s.error());
    fs::rename(out, old, ec);
    if (ec) return fail("--out " + o.out + ": cannot be replaced (" + ec.message() + ")");
  }
  fs::rename(made, out, ec);
  if (ec) {
    std::error_code ignored;
    if (exists) fs::rename(old, out, ignored);
    return fail("--out " + o.out + ": cannot be written (" + ec.message() + ")");
  }
  if (!is_zip_name(o.out)) ::chmod(out.c_str(), 0755);
  else ::chmod(out.c_str(), 0644);
  return {};
}

}  // namespace arwb::bundle
