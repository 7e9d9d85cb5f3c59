// The paper's Code Generator: a scene, its media, the camera's calibration and a marker sheet as one bundle that
// runs on its own (`arwb export`, `arwb play`, File > Export... and File > Play bundle). docs/export.md.
#pragma once

#include "base/result.hpp"
#include "base/temp_dir.hpp"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace arwb::bundle {

inline constexpr int kFormatVersion = 1;
inline constexpr const char* kManifestName = "manifest.json";

// One file of the bundle, as the manifest lists it. `path` is relative to the bundle's root, '/'-separated, never
// absolute, no "..", no symbolic link.
struct BundleFile {
  std::string path;
  std::uint64_t size = 0;
  std::string sha256;      // 64 lowercase hex digits
  std::string role;        // "scene", "media", "calibration", "sheet", "readme", "card", "web"
};

// The phone player's files (role "web"): index.html and sw.js at the root, whose scope the service worker controls,
// and everything under web/.
bool is_web_path(const std::string& path);

// The self-test: each id of the scene drawn synthetically, detected, and run through the scene.
struct SelfTestRow {
  int id = -1;
  int mapping_line = 0;        // the marker(...) call or database row that covers it
  std::string media;           // MediaSpec::describe() of what it showed, or "callbacks only"
  bool detected = false;       // the detector read the id on its synthetic frame
  bool fired = false;          // the mapping made an overlay (or its callbacks ran) for it
  std::string detail;          // why not, one line ("" when it passed)
};

struct WebCard {
  std::string url;
  std::string title;
  std::string picture;         // bundle path of the card's PNG ("cards/web-1.png")
};

// A scene file a phone's browser would not show as it is, and the copy made for phones (--convert-for-phones).
struct PhoneCopy {
  std::string path;        // the original's bundle path ("scene/media/clip.avi"), which the desktop plays
  std::string phone;       // the copy's ("web/phone/scene/media/clip.avi.mp4"), role "web"
  std::string reason;      // why the original would not do ("not an MP4 file (FMP4): ...")
};

// "" when a phone's browser shows or plays `file` as it is, or it is no picture or video; else why not, naming
// what it is: "a TIFF picture: phones' browsers show PNG, JPEG and WebP", "not an MP4 file (FMP4): phones'
// browsers play MP4 with H.264", "H.264 in 444P: phones' browsers play 8-bit 4:2:0 (yuv420p)".
std::string phone_problem(const std::string& file);

struct Manifest {
  int format_version = kFormatVersion;
  std::string title;
  std::string generator;               // "arwb 0.1.0"
  std::string dictionary;              // the detector's dictionary
  std::vector<int> ids;                // every id the scene maps, ascending
  double marker_size_mm = 0;           // the printed side
  std::string scene;                   // bundle path of the scene file ("scene/museum.lua")
  std::string calibration;             // bundle path of the calibration, "" when none (the default camera)
  std::vector<BundleFile> files;       // every file but manifest.json itself
  std::vector<SelfTestRow> self_test;
  bool self_test_passed = false;
  std::vector<WebCard> web_cards;
  std::vector<PhoneCopy> phone_media;  // with --web --convert-for-phones; absent from older manifests
};

// manifest.json's text, and back. parse_manifest checks every field (types, format version, relative paths, hex
// digests, that the scene, calibration and card pictures are among the files, nesting at most 16 deep) and names
// the first bad one: "manifest.json: files[3].sha256: not 64 lowercase hex digits"; a newer format_version is
// "manifest.json: format_version 2: made by a newer arwb (...)". docs/export.md lists the fields.
std::string manifest_json(const Manifest& m);
Result<Manifest> parse_manifest(const std::string& text);

// A bundle's printed marker side, in mm: what arwb export and the workbench's dialog take, and so all a manifest may
// say (within that, the marker sheet's own limit for the dictionary applies).
inline constexpr double kMinMarkerSizeMm = 1, kMaxMarkerSizeMm = 1000;

struct ExportOptions {
  std::string scene;             // FILE.lua or FILE.xml
  std::string out;               // a folder, or FILE.arwb / FILE.zip (a zip)
  std::string calibration;       // "" : none (the bundle then uses the default camera, marked so in the manifest)
  std::string title;             // "" : the scene file's stem
  double marker_size_mm = 50;    // the printed side, within the marker sheet's limits for the dictionary
  std::string web_site;          // --web: the phone player's site to add (DataDirs::web); "" : none
  bool convert_for_phones = false;   // with web_site: copies phones play of the media they would not (else warnings)
  bool force = false;            // replace an existing out
  std::function<void(const std::string&)> progress;   // one line per step, may be null
};

// "" when `out` may name a bundle; else why not, one line (the caller names --out). A name ending in .arwb or .zip
// is always a zip, so such a name with a trailing '/' is refused rather than read as a folder.
std::string out_name_problem(const std::string& out);

// Everything checked and computed, nothing written yet: what File > Export... shows before the user confirms.
struct ExportPlan {
  ExportOptions options;
  Manifest manifest;                                   // files listed with sizes and digests
  std::vector<std::pair<std::string, std::string>> sources;   // bundle path <- absolute source path (scene, media, calibration)
  std::vector<std::pair<std::string, std::string>> generated; // bundle path <- bytes (README, sheet, cards, manifest.json last)
  std::vector<std::string> warnings;                   // worth saying, not stopping for ("no calibration: ...")
};
// The checks of `arwb export` (docs/export.md): out may be written (an existing one only with force, and only when
// it is a bundle); the scene loads with no mapping skipped; every file it reads (recorded while it loads and runs)
// lies inside the scene's folder; every id is valid for the dictionary; the marker size fits a sheet; the
// calibration reads; and the self-test passes (each mapped id drawn, detected and run through SceneStage). An
// error is one line naming the file, line or id ("museum.lua:14: marker 1 does not fire its mapping in the
// self-test: ..."). Nothing is written, except scratch files in the system's temporary folder.
Result<ExportPlan> plan_export(const ExportOptions& options);
// Writes the plan: all of it or nothing (built in a private folder beside out, then renamed into place; an old
// bundle it replaces goes only then). The sources are read again and must still have their planned digests.
Status write_export(const ExportPlan& plan);

// Limits for reading a bundle someone sent.
struct BundleLimits {
  std::size_t max_entries = 10'000;
  std::uint64_t max_file_bytes = 1ull << 30;     // one file, uncompressed
  std::uint64_t max_total_bytes = 4ull << 30;    // all of them
  double max_ratio = 1000;                       // uncompressed / compressed, per entry (zip bombs)
};

// A bundle opened for playing: copied or extracted into a private temporary folder (0700), verified there against its
// manifest, removed when this is destroyed. Refused, with the entry named, when: manifest.json is missing or bad, or
// says what arwb export never writes (the scene not a listed .lua or .xml of role "scene", the calibration not a listed
// file of role "calibration" that reads, an unknown dictionary or a spelling of it arwb does not write, no ids or one
// the dictionary lacks, an unknown role, a failed self-test); a listed file is missing, has another size or digest
// ("scene/media/logo.png: changed since export (SHA-256 differs)"); a file is not listed ("scene/extra.lua: not in the
// manifest"); a zip entry is absolute, has "..", is a symbolic link or device, is duplicated, or is past the limits
// (counted on the bytes really inflated); a folder holds a link or device. Nothing is ever written outside the
// temporary folder, which is removed at once on a refusal. The folder or zip is told by its bytes, not its name. Errors
// read "<path>: <entry>: <reason>".
class OpenedBundle {
 public:
  ~OpenedBundle();   // removes the folder
  OpenedBundle(OpenedBundle&&) noexcept;
  OpenedBundle& operator=(OpenedBundle&&) noexcept;
  const std::filesystem::path& dir() const;   // absolute: $TMPDIR (or /tmp)/arwb-bundle-XXXXXX, locked
  const Manifest& manifest() const;
  std::string scene_path() const;          // absolute
  std::string calibration_path() const;    // absolute, "" when none
  const std::string& source() const;       // the folder or zip it was opened from, as given

 private:
  friend Result<OpenedBundle> open_bundle(const std::string& path, const BundleLimits& limits);
  OpenedBundle() = default;
  arwb::TempDir dir_;   // qualified: a file that includes this may have a TempDir of its own in scope
  Manifest manifest_;
  std::string source_;
};
Result<OpenedBundle> open_bundle(const std::string& path, const BundleLimits& limits = {});

}  // namespace arwb::bundle
