// `arwb export`'s plan (docs/export.md): everything checked and computed, nothing written yet. The scene loads
// with every file it reads recorded, its ids and the marker size are checked, the calibration is read as the
// bundle will hold it, the self-test runs (self_test.cpp), and every file is listed with its size and digest,
// the marker sheet, the web cards, the README and the manifest last. write.cpp writes the plan.
#include "bundle/export_parts.hpp"

#include "bundle/bundle_files.hpp"
#include "base/files.hpp"
#include "base/version.hpp"
#include "media/media_path.hpp"
#include "synth/marker_sheet.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>
#include <string_view>

namespace arwb::bundle {

namespace fs = std::filesystem;

bool is_web_path(const std::string& path) {
  return path == "index.html" || path == "sw.js" || path.rfind("web/", 0) == 0;
}

void say(const ExportOptions& o, const std::string& line) {
  if (o.progress) o.progress(line);
}

std::vector<int> expand(const std::vector<std::pair<int, int>>& ranges) {
  std::set<int> ids;
  for (const auto& [a, b] : ranges)
    for (int id = a; id <= b; ++id) ids.insert(id);
  return {ids.begin(), ids.end()};
}

namespace {

// "0-2, 7" for a sorted list of ids.
std::string id_ranges(const std::vector<int>& ids) {
  std::string out;
  for (size_t i = 0; i < ids.size();) {
    size_t j = i;
    while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1) ++j;
    if (!out.empty()) out += ", ";
    out += std::to_string(ids[i]);
    if (j > i) {
      out += '-';   // (not "-" + to_string: GCC 12 warns of a false overflow in that inlined insert)
      out += std::to_string(ids[j]);
    }
    i = j + 1;
  }
  return out;
}

constexpr size_t kMaxTitleChars = 200;

// Characters of UTF-8 text (its bytes that do not continue a character), for the README's '=' underline.
size_t utf8_chars(const std::string& text) {
  size_t n = 0;
  for (const char c : text) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  return n;
}

// The bundle's name as a shell word for the README's "arwb play NAME": quoted when it holds a space, a quote
// or anything else the shell would act on.
std::string shell_word(const std::string& name) {
  const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("._-+,:@%=/").find(c) != std::string_view::npos;
  });
  if (plain) return name;
  std::string out = "'";
  for (const char c : name) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// --title goes into one line of the README and the player's window: no control characters, and not a page long.
Status check_title(const std::string& title) {
  for (const char c : title)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F)
      return fail("--title " + shown_name(title) + ": has a control character (a new line, tab or the like); a title "
                  "is one line");
  if (utf8_chars(title) > kMaxTitleChars)
    return fail("--title " + shown_name(title) + ": longer than " + std::to_string(kMaxTitleChars) + " characters");
  return {};
}

std::string readme_text(const Manifest& m, const std::string& bundle_name) {
  std::ostringstream s;
  s << m.title << "\n" << std::string(utf8_chars(m.title), '=') << "\n\n"
    << "An augmented-reality scene exported by " << m.generator << " (`arwb export`): the scene and its media,\n"
    << "the markers to print" << (m.calibration.empty() ? "" : " and the camera's calibration")
    << ", checked and listed with their digests in manifest.json.\n\n"
    << "To run it:   arwb play " << shell_word(bundle_name) << "\n\n"
    << "Print markers.pdf at 100 % (no \"fit to page\"): each marker's black square is " << m.marker_size_mm
    << " mm;\nthe bar at the bottom of each page is 100 mm when the printer kept the size.\n\n"
    << "Dictionary: " << m.dictionary << "\n"
    << "Camera:     " << (m.calibration.empty() ? std::string("default values (no calibration given)") : m.calibration)
    << "\n\nScene line  Markers      Media\n";
  // One row per mapping (its line and media), with the ids it covers.
  std::vector<std::pair<std::pair<int, std::string>, std::vector<int>>> rows;
  for (const SelfTestRow& r : m.self_test) {
    auto it = std::find_if(rows.begin(), rows.end(), [&](const auto& row) {
      return row.first == std::make_pair(r.mapping_line, r.media);
    });
    if (it == rows.end()) rows.push_back({{r.mapping_line, r.media}, {r.id}});
    else it->second.push_back(r.id);
  }
  std::sort(rows.begin(), rows.end());
  for (auto& [key, ids] : rows) {
    std::sort(ids.begin(), ids.end());
    char head[48];
    std::snprintf(head, sizeof head, "%10d  %-11s  ", key.first, id_ranges(ids).c_str());
    s << head << key.second << "\n";
  }
  if (!m.web_cards.empty()) {
    s << "\nLinks (a click on the card opens them):\n";
    for (const WebCard& c : m.web_cards) s << "  " << c.url << "\n";
  }
  return s.str();
}

// The calibration's bytes, checked as the bundle will hold them, and read back from the copy. One file is copied
// as calibration.EXT; the paper's pair (cameraMatrix.xml whose distortion is in distCoeffs.xml beside it) keeps
// its two names, which is how the reader finds the second file.
Status plan_calibration(const std::string& path, ExportPlan& plan, std::optional<Calibration>* read) {
  Result<Calibration> c = read_calibration(path);
  if (!c) return fail("--calib " + c.error());
  std::string ext = lower_ext(path);
  if (ext != ".xml" && ext != ".yml" && ext != ".yaml" && ext != ".json") ext = ".yml";
  Result<std::string> bytes = read_whole_file(path, kMaxManifestBytes, false);
  if (!bytes) return fail("--calib " + bytes.error());
  Result<TempDir> tmp = TempDir::make({}, "arwb-calib");
  if (!tmp) return fail("--calib " + path + ": " + tmp.error());
  std::string name = "calibration" + ext;
  if (Status s = write_new_file(tmp->path() / name, *bytes); !s) return fail("--calib " + s.error());
  std::vector<std::pair<std::string, std::string>> files{{name, fs::absolute(path).string()}};
  if (!read_calibration((tmp->path() / name).string())) {
    // Not whole on its own: the paper's pair, under the names the reader looks for.
    const fs::path sibling = fs::absolute(path).parent_path() / "distCoeffs.xml";
    Result<std::string> d = read_whole_file(sibling, kMaxManifestBytes, false);
    if (!d) return fail("--calib " + path + ": its distortion is in " + sibling.string() + ", which cannot be read");
    name = "cameraMatrix.xml";
    if (Status s = write_new_file(tmp->path() / name, *bytes); !s) return fail("--calib " + s.error());
    if (Status s = write_new_file(tmp->path() / "distCoeffs.xml", *d); !s) return fail("--calib " + s.error());
    if (Result<Calibration> again = read_calibration((tmp->path() / name).string()); !again)
      return fail("--calib " + path + ": does not read once copied (" + again.error() + ")");
    files = {{name, fs::absolute(path).string()}, {"distCoeffs.xml", sibling.string()}};
  }
  for (const auto& [bundle_path, source] : files) plan.sources.emplace_back(bundle_path, source);
  plan.manifest.calibration = name;
  *read = std::move(*c);
  return {};
}

// A load-time message ("scene.lua:2: media/nope.png: no such file; marker(2) skipped") as the export's error:
// the workbench skips such a mapping and goes on, the export stops, and says so ("cannot export: scene.lua:2:
// media/nope.png: no such file").
std::string stopped_by(std::string message) {
  const size_t at = message.rfind("; ");
  if (at != std::string::npos) {
    const std::string tail = message.substr(at + 2);
    const bool skipped = tail.size() > 8 && tail.compare(tail.size() - 8, 8, " skipped") == 0 &&
                         (tail.rfind("marker(", 0) == 0 || tail == "row skipped");
    if (skipped) message.erase(at);
  }
  return "cannot export: " + message;
}


// The scene's dictionary and the ids its mappings cover, each checked against it ("museum.lua:14: id 5000 is not a
// marker of ARUCO_ORIGINAL (ids 0 to 1023)").
struct SceneIds {
  std::string dict_name;
  std::optional<Dictionary> dict;
  std::set<int> ids;
};
Result<SceneIds> scene_ids(SceneStage& stage, const ExportOptions& options, const fs::path& scene_file) {
  SceneIds out;
  out.dict_name = stage.runtime().dictionary_name();
  std::string dict_error;
  out.dict = dictionary_by_name(out.dict_name, &dict_error);
  if (!out.dict) return fail(options.scene + ": dictionary " + out.dict_name + ": " + dict_error);
  const auto mapping_ids = stage.runtime().mapping_ids();
  for (size_t mi = 0; mi < mapping_ids.size(); ++mi)
    for (const int id : expand(mapping_ids[mi])) {
      if (id < 0 || id >= out.dict->size()) {
        const int line = mi < stage.status().mappings.size() ? stage.status().mappings[mi].line : 0;
        return fail(scene_file.filename().string() + ":" + std::to_string(line) + ": id " + std::to_string(id) +
                    " is not a marker of " + out.dict_name + " (ids 0 to " + std::to_string(out.dict->size() - 1) +
                    ")");
      }
      out.ids.insert(id);
    }
  if (out.ids.empty()) return fail(options.scene + ": maps no marker; there is nothing to export");
  return out;
}

// The scene and every file it read, at their paths relative to the scene's folder, none outside it.
Status add_scene_files(const std::set<std::string>& read, const fs::path& scene_dir, const fs::path& scene_file,
                       ExportPlan& plan) {
  std::set<std::string> used = read;
  used.insert(scene_file.string());
  const std::string prefix = scene_dir.string() + "/";
  for (const std::string& file : used) {
    if (file.compare(0, prefix.size(), prefix) != 0) return fail(file + ": outside the scene's folder " + scene_dir.string());
    const std::string rel = file.substr(prefix.size());
    if (const std::string problem = bundle_path_problem(rel); !problem.empty()) return fail(rel + ": " + problem);
    // Media were resolved to their real paths; the scene file may be a link, and its target's bytes go in.
    struct stat st {};
    if (::stat(file.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return fail(rel + ": not a regular file");
    plan.sources.emplace_back("scene/" + rel, file);
  }
  return {};
}

// The marker sheet: exactly the scene's ids at the printed size.
Status add_marker_sheet(const Dictionary& dict, ExportPlan& plan) {
  Result<TempDir> tmp = TempDir::make({}, "arwb-sheet");
  if (!tmp) return fail("markers.pdf: " + tmp.error());
  const fs::path pdf = tmp->path() / "markers.pdf";
  try {
    write_marker_sheet(dict, plan.manifest.ids, plan.manifest.marker_size_mm, SheetFormat::pdf, pdf.string());
  } catch (const std::exception& e) {
    return fail(std::string("markers.pdf: ") + e.what());
  }
  Result<std::string> bytes = read_whole_file(pdf, kMaxSourceBytes, true);
  if (!bytes) return fail(bytes.error());
  plan.generated.emplace_back("markers.pdf", std::move(*bytes));
  return {};
}

// The phone player's site (--web), every regular file of it at the same path in the bundle (is_web_path). A
// site without its page, service worker or core is not one: the build (web_core) or the package makes them.
Status add_web_site(const std::string& site, ExportPlan& plan) {
  std::error_code ec;
  for (const char* need : {"index.html", "sw.js", "web/arwb_core.wasm"})
    if (!fs::is_regular_file(fs::path(site) / need, ec))
      return fail("--web: the phone player's " + std::string(need) + " is missing from " + site +
                  " (a build tree makes it with the target web_core; an installed arwb has it in share/arwb/web)");
  std::vector<std::pair<std::string, std::string>> files;
  for (fs::recursive_directory_iterator it(site, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    const std::string rel = fs::relative(it->path(), site, ec).generic_string();
    if (!is_web_path(rel)) return fail(it->path().string() + ": not part of the phone player's site");
    files.emplace_back(rel, it->path().string());
  }
  if (ec) return fail(site + ": " + ec.message());
  std::sort(files.begin(), files.end());
  for (auto& f : files) plan.sources.push_back(std::move(f));
  return {};
}

// Sizes and digests of everything but the manifest, the README written from them, and the manifest last.
Status list_files(const fs::path& scene_file, ExportPlan& plan) {
  Manifest& m = plan.manifest;
  for (const auto& [path, source] : plan.sources) {
    Result<std::string> bytes = read_whole_file(source, kMaxSourceBytes, false);
    if (!bytes) return fail(bytes.error());
    std::string role = "media";
    if (source == scene_file.string()) role = "scene";
    else if (is_web_path(path)) role = "web";
    else if (path.rfind("scene/", 0) != 0) role = "calibration";
    m.files.push_back({path, bytes->size(), sha256_hex(*bytes), role});
  }
  const std::string bundle_name = out_path(plan.options.out).filename().string();
  plan.generated.emplace_back("README.txt", readme_text(m, bundle_name.empty() ? std::string("BUNDLE") : bundle_name));
  for (const auto& [path, bytes] : plan.generated) {
    const std::string role = path == "markers.pdf"  ? "sheet"
                             : path == "README.txt" ? "readme"
                             : is_web_path(path)    ? "web"
                                                    : "card";
    m.files.push_back({path, bytes.size(), sha256_hex(bytes), role});
  }
  std::sort(m.files.begin(), m.files.end(), [](const BundleFile& a, const BundleFile& b) { return a.path < b.path; });
  for (size_t i = 1; i < m.files.size(); ++i)
    if (m.files[i].path == m.files[i - 1].path) return fail(m.files[i].path + ": two files of the bundle have this path");
  plan.generated.emplace_back(kManifestName, manifest_json(m));
  return {};
}

}  // namespace

Result<ExportPlan> plan_export(const ExportOptions& options) {
  ExportPlan plan;
  plan.options = options;
  Manifest& m = plan.manifest;
  if (options.scene.empty()) return fail("--scene: no scene named");
  if (Status s = check_title(options.title); !s) return fail(s.error());
  if (Status s = check_out(options); !s) return fail(s.error());
  if (Status s = check_input_file(options.scene, {"a scene", 16u << 20}); !s) return fail(s.error());
  // The scene's folder as the runtime sees it (the folder the path names, its links resolved): media resolve
  // inside it, and the scene file goes beside them under the name it was given.
  std::error_code ec;
  const fs::path parent = fs::absolute(options.scene, ec).parent_path();
  const fs::path scene_dir = fs::canonical(parent, ec);
  if (ec) return fail(options.scene + ": " + ec.message());
  const fs::path scene_file = scene_dir / fs::path(options.scene).filename();
  const double marker_mm = options.marker_size_mm;
  if (!std::isfinite(marker_mm)) return fail("--marker-size-mm: not a number");

  // The scene loads, and every file it reads is recorded: at the load and during the self-test.
  media::ResolvedFilesRecorder recorder;
  say(options, "loading " + options.scene);
  SceneStage stage(media::StoreMode::offline);
  if (!stage.load(options.scene)) return fail(stage.status().error);
  for (const MappingRow& row : stage.status().mappings)
    if (row.health == MappingHealth::skipped) return fail(stopped_by(row.reason));
  if (const std::vector<std::string> errors = stage.take_errors(); !errors.empty()) return fail(stopped_by(errors.front()));

  Result<SceneIds> scene = scene_ids(stage, options, scene_file);
  if (!scene) return fail(scene.error());
  const Dictionary& dict = *scene->dict;
  const double largest = max_sheet_marker_mm(dict.marker_size());
  if (marker_mm < kSheetMinMarkerMm || marker_mm > largest) {
    char text[160];
    std::snprintf(text, sizeof text, "--marker-size-mm %g: markers of %s are printed from %g to %g mm", marker_mm,
                  scene->dict_name.c_str(), kSheetMinMarkerMm, largest);
    return fail(text);
  }

  std::optional<Calibration> calib;
  if (options.calibration.empty())
    plan.warnings.push_back("no --calib: the player uses the paper's default camera values, so poses and 3D media "
                            "are approximate");
  if (!options.calibration.empty()) {
    say(options, "reading the calibration " + options.calibration);
    if (Status s = plan_calibration(options.calibration, plan, &calib); !s) return fail(s.error());
  }

  say(options, "self-test: " + std::to_string(scene->ids.size()) + " ids, each drawn, detected and run through the scene");
  Result<TestResult> test = self_test(stage, dict, calib, options);
  if (!test) return fail(test.error());
  for (const SelfTestRow& row : test->rows)
    if (!row.fired)
      return fail(scene_file.filename().string() + ":" + std::to_string(row.mapping_line) + ": marker " +
                  std::to_string(row.id) + " does not fire its mapping in the self-test: " + row.detail);

  m.format_version = kFormatVersion;
  m.title = options.title.empty() ? scene_file.stem().string() : options.title;
  m.generator = std::string("arwb ") + kVersion;
  m.dictionary = scene->dict_name;
  m.ids.assign(scene->ids.begin(), scene->ids.end());
  m.marker_size_mm = marker_mm;
  m.scene = "scene/" + scene_file.filename().string();
  m.self_test = test->rows;
  m.self_test_passed = test->passed;

  if (Status s = add_scene_files(recorder.files(), scene_dir, scene_file, plan); !s) return fail(s.error());
  if (Status s = add_marker_sheet(dict, plan); !s) return fail(s.error());
  if (!options.web_site.empty()) {
    say(options, "adding the phone player's site from " + options.web_site);
    if (Status s = add_web_site(options.web_site, plan); !s) return fail(s.error());
    if (Status s = add_phone_media(plan); !s) return fail(s.error());
  }
  for (size_t i = 0; i < test->cards.size(); ++i) {
    WebCard card = test->cards[i];
    card.picture = "cards/web-" + std::to_string(i + 1) + ".png";
    m.web_cards.push_back(card);
    plan.generated.emplace_back(card.picture, test->card_png[i]);
  }
  if (Status s = list_files(scene_file, plan); !s) return fail(s.error());
  return plan;
}

}  // namespace arwb::bundle
