// `arwb export`: the checks and the self-test (plan_export), then the bundle written all or nothing
// (write_export). docs/export.md.
#include "bundle/bundle.hpp"
#include "bundle/bundle_files.hpp"
#include "base/version.hpp"

#include "base/files.hpp"
#include "calibration/calibration_file.hpp"
#include "detect/detector.hpp"
#include "detect/dictionary.hpp"
#include "inspect/trace_view.hpp"
#include "media/media_path.hpp"
#include "synth/marker_sheet.hpp"
#include "synth/synth.hpp"
#include "workbench/scene_stage.hpp"

#include <opencv2/imgcodecs.hpp>

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <string_view>


namespace arwb::bundle {

namespace fs = std::filesystem;

namespace {

constexpr std::uint64_t kMaxSourceBytes = 4ull << 30;   // one file of the scene, read whole to digest it
constexpr std::uint64_t kMaxManifestBytes = 16u << 20;
// The self-test's frame: one marker, upright and frontal, well inside a small frame, one second apart so each
// id enters alone (the tracker holds a missed marker for a quarter second). With a calibration that names its
// image size the frame takes that size's aspect (see test_frame), since a calibration fits only frames of its
// own shape.
const cv::Size kTestFrame{320, 240};
constexpr int kCalibratedTestWidth = 640;
constexpr double kTestMarkerPx = 120;

bool is_zip_name(const std::string& out) {
  std::string ext = fs::path(out).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".zip" || ext == ".arwb";
}

// --out as an absolute path without a trailing '/' ("museum/" names the folder museum).
fs::path out_path(const std::string& out) {
  fs::path p = fs::absolute(out).lexically_normal();
  if (!p.has_filename() && p.has_parent_path()) p = p.parent_path();
  return p;
}

void say(const ExportOptions& o, const std::string& line) {
  if (o.progress) o.progress(line);
}

std::string lower_ext(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// The ids of the mapping as a sorted list (ranges expanded).
std::vector<int> expand(const std::vector<std::pair<int, int>>& ranges) {
  std::set<int> ids;
  for (const auto& [a, b] : ranges)
    for (int id = a; id <= b; ++id) ids.insert(id);
  return {ids.begin(), ids.end()};
}

// "0-2, 7" for a sorted list of ids.
std::string id_ranges(const std::vector<int>& ids) {
  std::string out;
  for (size_t i = 0; i < ids.size();) {
    size_t j = i;
    while (j + 1 < ids.size() && ids[j + 1] == ids[j] + 1) ++j;
    if (!out.empty()) out += ", ";
    out += std::to_string(ids[i]);
    if (j > i) out += "-" + std::to_string(ids[j]);
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

// The self-test's frame for a calibration: its own image size scaled to a 640-pixel width (a 16:9 camera's
// 1280x720 gives 640x360), or the size itself when rounding the height would change the aspect more than
// calibration_for_size allows (a very wide strip); the small default frame when it names no size.
cv::Size test_frame(const Calibration& c) {
  const cv::Size own = c.image_size;
  if (own.width <= 0 || own.height <= 0) return kTestFrame;
  const int height = std::max(1, int(std::lround(double(kCalibratedTestWidth) * own.height / own.width)));
  const cv::Size scaled{kCalibratedTestWidth, height};
  const double a = double(own.width) * scaled.height, b = double(scaled.width) * own.height;
  const bool same_aspect = std::abs(a - b) <= 0.004 * std::max(a, b);
  // The marker (kTestMarkerPx) must fit well inside the frame either way.
  if (same_aspect && height >= 2 * kTestMarkerPx) return scaled;
  if (own.width >= 2 * kTestMarkerPx && own.height >= 2 * kTestMarkerPx && own.area() <= 4096 * 4096) return own;
  return scaled;
}

struct TestResult {
  std::vector<SelfTestRow> rows;
  std::vector<WebCard> cards;                       // picture: the PNG's bytes until the paths are given
  std::vector<std::string> card_png;
  bool passed = true;
};

// Each id the scene maps, drawn alone on a frame, detected with the scene's dictionary and run through the
// scene as the workbench does (SceneStage, offline media): every mapping that covers it must fire.
Result<TestResult> self_test(SceneStage& stage, const Dictionary& dict, const std::optional<Calibration>& calib,
                             const ExportOptions& options) {
  const auto mapping_ids = stage.runtime().mapping_ids();
  std::map<int, std::vector<size_t>> by_id;   // id -> the mappings that cover it
  for (size_t mi = 0; mi < mapping_ids.size(); ++mi)
    for (const int id : expand(mapping_ids[mi])) by_id[id].push_back(mi);
  Detector detector({dict});
  std::shared_ptr<const Calibration> camera;
  const cv::Size frame_size = calib ? test_frame(*calib) : kTestFrame;
  if (calib) {
    Result<Calibration> fitted = calibration_for_size(*calib, frame_size);
    if (!fitted) return fail("calibration: " + fitted.error());
    camera = std::make_shared<const Calibration>(std::move(*fitted));
  }
  TestResult out;
  std::set<std::pair<std::string, std::string>> cards_seen;
  double t = 0;
  size_t done = 0;
  for (const auto& [id, mappings] : by_id) {
    if (++done % 100 == 0) say(options, "self-test: " + std::to_string(done) + " of " + std::to_string(by_id.size()) + " ids");
    cv::Mat raw(frame_size, CV_8UC3, cv::Scalar(200, 200, 200));
    const Quad corners = project_square({frame_size.width / 2.0, frame_size.height / 2.0}, kTestMarkerPx, 0, 0, 0, 500);
    draw_marker(raw, dict, id, corners, 1.5);
    Frame f;
    f.index = done;
    f.time_s = t;
    detector.detect(raw, &f.trace, TraceLevel::full, 1, &f.image);
    render_stage_views(f.image, f.trace, f.views);
    f.loaded_calibration = camera;
    f.pose_marker_side = 1;
    stage.run(f, t, 1e9);
    t += 1.0;
    const std::vector<std::string> errors = stage.take_errors();
    bool detected = false;
    for (const Marker& m : f.trace.markers) detected = detected || m.id == id;
    for (const size_t mi : mappings) {
      SelfTestRow row;
      row.id = id;
      const MappingRow* mrow = mi < f.scene.mappings.size() ? &f.scene.mappings[mi] : nullptr;
      row.mapping_line = mrow ? mrow->line : 0;
      row.media = mrow ? mrow->media : "?";
      row.detected = detected;
      const bool callbacks_only = mrow && mrow->media == "callbacks only";
      const Overlay* shown = nullptr;
      for (const Overlay& o : f.overlays)
        if (o.marker_id == id && o.mapping == int(mi) && (o.content || o.solid)) shown = &o;
      const bool healthy = mrow && mrow->health == MappingHealth::ok;
      row.fired = detected && healthy && (shown || callbacks_only);
      if (!detected) {
        row.detail = "not detected on its synthetic frame";
        if (!unambiguous(dict, id)) row.detail += " (it reads the same as a marker turned: it cannot be told apart)";
      } else if (!healthy) {
        row.detail = mrow ? mrow->reason : "no such mapping";
      } else if (!row.fired) {
        row.detail = errors.empty() ? "no media shown for it" : errors.front();
      }
      if (row.media.empty() && shown) row.media = shown->media.describe();
      if (shown && shown->media.kind == MediaKind::web &&
          cards_seen.insert({shown->media.url, shown->media.title}).second) {
        uint64_t version = 0;
        const std::shared_ptr<const cv::Mat> picture = shown->content ? shown->content->current(&version) : nullptr;
        std::vector<unsigned char> png;
        if (picture && !picture->empty() && cv::imencode(".png", *picture, png)) {
          out.cards.push_back({shown->media.url, shown->media.title, ""});
          out.card_png.emplace_back(png.begin(), png.end());
        }
      }
      out.passed = out.passed && row.fired;
      out.rows.push_back(std::move(row));
    }
  }
  return out;
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

}  // namespace

std::string out_name_problem(const std::string& out) {
  // "mz.arwb/" once replaced the zip mz.arwb with a folder of that name: a zip's name stays a zip's name.
  if (!out.empty() && !is_zip_name(out) && is_zip_name(out_path(out).string()))
    return "a name ending in " + lower_ext(out_path(out)) +
           " is a zip bundle; drop the trailing '/' (or name a folder without .arwb or .zip)";
  return "";
}

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

  const std::string dict_name = stage.runtime().dictionary_name();
  std::string dict_error;
  const std::optional<Dictionary> dict = dictionary_by_name(dict_name, &dict_error);
  if (!dict) return fail(options.scene + ": dictionary " + dict_name + ": " + dict_error);
  std::set<int> ids;
  const auto mapping_ids = stage.runtime().mapping_ids();
  for (size_t mi = 0; mi < mapping_ids.size(); ++mi)
    for (const int id : expand(mapping_ids[mi])) {
      if (id < 0 || id >= dict->size()) {
        const int line = mi < stage.status().mappings.size() ? stage.status().mappings[mi].line : 0;
        return fail(scene_file.filename().string() + ":" + std::to_string(line) + ": id " + std::to_string(id) +
                    " is not a marker of " + dict_name + " (ids 0 to " + std::to_string(dict->size() - 1) + ")");
      }
      ids.insert(id);
    }
  if (ids.empty()) return fail(options.scene + ": maps no marker; there is nothing to export");
  const double largest = max_sheet_marker_mm(dict->marker_size());
  if (marker_mm < kSheetMinMarkerMm || marker_mm > largest) {
    char text[160];
    std::snprintf(text, sizeof text, "--marker-size-mm %g: markers of %s are printed from %g to %g mm", marker_mm,
                  dict_name.c_str(), kSheetMinMarkerMm, largest);
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

  say(options, "self-test: " + std::to_string(ids.size()) + " ids, each drawn, detected and run through the scene");
  Result<TestResult> test = self_test(stage, *dict, calib, options);
  if (!test) return fail(test.error());
  for (const SelfTestRow& row : test->rows)
    if (!row.fired)
      return fail(scene_file.filename().string() + ":" + std::to_string(row.mapping_line) + ": marker " +
                  std::to_string(row.id) + " does not fire its mapping in the self-test: " + row.detail);

  m.format_version = kFormatVersion;
  m.title = options.title.empty() ? scene_file.stem().string() : options.title;
  m.generator = std::string("arwb ") + kVersion;
  m.dictionary = dict_name;
  m.ids.assign(ids.begin(), ids.end());
  m.marker_size_mm = marker_mm;
  m.scene = "scene/" + scene_file.filename().string();
  m.self_test = test->rows;
  m.self_test_passed = test->passed;

  // The scene and every file it read, at their paths relative to the scene's folder, none outside it.
  std::set<std::string> used = recorder.files();
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

  // The marker sheet: exactly the scene's ids at the printed size.
  {
    Result<TempDir> tmp = TempDir::make({}, "arwb-sheet");
    if (!tmp) return fail("markers.pdf: " + tmp.error());
    const fs::path pdf = tmp->path() / "markers.pdf";
    try {
      write_marker_sheet(*dict, m.ids, marker_mm, SheetFormat::pdf, pdf.string());
    } catch (const std::exception& e) {
      return fail(std::string("markers.pdf: ") + e.what());
    }
    Result<std::string> bytes = read_whole_file(pdf, kMaxSourceBytes, true);
    if (!bytes) return fail(bytes.error());
    plan.generated.emplace_back("markers.pdf", std::move(*bytes));
  }
  for (size_t i = 0; i < test->cards.size(); ++i) {
    WebCard card = test->cards[i];
    card.picture = "cards/web-" + std::to_string(i + 1) + ".png";
    m.web_cards.push_back(card);
    plan.generated.emplace_back(card.picture, test->card_png[i]);
  }

  // Sizes and digests of everything but the manifest.
  for (const auto& [path, source] : plan.sources) {
    Result<std::string> bytes = read_whole_file(source, kMaxSourceBytes, false);
    if (!bytes) return fail(bytes.error());
    std::string role = "media";
    if (source == scene_file.string()) role = "scene";
    else if (path.rfind("scene/", 0) != 0) role = "calibration";
    m.files.push_back({path, bytes->size(), sha256_hex(*bytes), role});
  }
  const std::string bundle_name = out_path(options.out).filename().string();
  plan.generated.emplace_back("README.txt", readme_text(m, bundle_name.empty() ? std::string("BUNDLE") : bundle_name));
  for (const auto& [path, bytes] : plan.generated) {
    const std::string role = path == "markers.pdf" ? "sheet" : path == "README.txt" ? "readme" : "card";
    m.files.push_back({path, bytes.size(), sha256_hex(bytes), role});
  }
  std::sort(m.files.begin(), m.files.end(), [](const BundleFile& a, const BundleFile& b) { return a.path < b.path; });
  for (size_t i = 1; i < m.files.size(); ++i)
    if (m.files[i].path == m.files[i - 1].path) return fail(m.files[i].path + ": two files of the bundle have this path");
  plan.generated.emplace_back(kManifestName, manifest_json(m));
  return plan;
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
  Result<TempDir> tmp = TempDir::make(out.parent_path(), "." + out.filename().string() + ".partial");
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
