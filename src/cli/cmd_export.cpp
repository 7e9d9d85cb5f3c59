// arwb export: the paper's Code Generator. A scene, its media, the camera's calibration and a marker sheet as one
// bundle that runs on its own (`arwb play`), checked before anything is written: the scene loads, every file it
// reads lies inside its folder, every id is valid, the calibration reads, and each marker drawn synthetically
// makes its mapping fire. docs/export.md.
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "bundle/bundle.hpp"
#include "base/data_dirs.hpp"
#include "base/text.hpp"

#include <cstdio>
#include <string>

namespace arwb {

int cmd_export(int argc, char** argv) {
  CommandLine cl("arwb export",
                 "Exports a scene as a bundle that runs on its own with `arwb play`: manifest.json (every file with "
                 "its size and SHA-256, the self-test), the scene and the media it uses, the calibration, "
                 "markers.pdf (the scene's markers at the printed size), pictures of its web cards and a README. "
                 "A folder, or a zip when OUT ends in .arwb or .zip.",
                 "Before writing, the scene is loaded and each of its markers is drawn, detected and run through "
                 "the scene; any failure names the file, line or id, exits 1, and writes nothing. An existing OUT "
                 "is replaced with --force, and only when it is a bundle.");
  bundle::ExportOptions o;
  bool quiet = false;
  cl.app.add_option("--scene", o.scene, "a Lua scene or the paper's XML database (docs/scene-api.md)")
      ->type_name("FILE.lua|FILE.xml")
      ->required();
  cl.app.add_option("--out", o.out, "the bundle: a folder, or a zip (FILE.arwb, FILE.zip)")
      ->type_name("DIR|FILE.arwb|FILE.zip")
      ->required()
      ->check(CLI::Validator([](std::string& out) { return bundle::out_name_problem(out); }, "", "bundle name"))
      ->check(out_kinds({".arwb", ".zip"}, true));
  cl.app.add_option("--calib", o.calibration,
                    "the camera's calibration (XML or YAML, as arwb calibrate writes); without it the player uses "
                    "the paper's default values")
      ->type_name("FILE");
  cl.app.add_option("--title", o.title, "the bundle's title (default: the scene file's name)")->type_name("T");
  // The range here is only a sanity bound; the sheet's own limits for the dictionary (from 5 mm up to what
  // fits a page) are checked with the scene loaded, naming them.
  cl.app.add_option("--marker-size-mm", o.marker_size_mm, "the printed markers' side")
      ->type_name("S")
      ->check(real_number(bundle::kMinMarkerSizeMm, bundle::kMaxMarkerSizeMm));
  bool web = false;
  cl.app.add_flag("--web", web,
                  "add the phone player: a web page (index.html) that runs the bundle's detector in the browser "
                  "(docs/export.md, \"On a phone\")");
  cl.app.add_flag("--convert-for-phones", o.convert_for_phones,
                  "with --web: copies phones play of the media they would not (pictures as PNG; videos as MP4/H.264, "
                  "with ffmpeg); without it those files are named in warnings")
      ->needs("--web");
  cl.app.add_flag("--force", o.force, "replace an existing OUT (only a bundle arwb wrote)");
  cl.app.add_flag("--quiet", quiet, "print only the last line");
  if (const auto status = cl.parse(argc, argv)) return *status;
  if (!quiet) o.progress = [](const std::string& line) { std::printf("  %s\n", printable(line).c_str()); };
  if (web) o.web_site = data_dirs().web;

  Result<bundle::ExportPlan> plan = bundle::plan_export(o);
  if (!plan) {
    print_problem("arwb export: %s\n", plan.error().c_str());
    return 1;
  }
  const bundle::Manifest& m = plan->manifest;
  if (!quiet) {
    std::uint64_t total = 0;
    std::printf("files:\n");
    for (const bundle::BundleFile& f : m.files) {
      std::printf("  %-40s %10s  %s\n", printable(f.path).c_str(), human_bytes(f.size).c_str(), f.role.c_str());
      total += f.size;
    }
    std::printf("  %zu files, %s (and manifest.json)\n", m.files.size(), human_bytes(total).c_str());
    std::printf("self-test (%s, %zu ids):\n", m.dictionary.c_str(), m.ids.size());
    std::printf("  %6s  %5s  %-8s  %-5s  %s\n", "id", "line", "detected", "fired", "media");
    // A whole dictionary is 1024 rows: the first ones, then a count.
    constexpr size_t kShown = 40;
    for (size_t i = 0; i < m.self_test.size() && i < kShown; ++i) {
      const bundle::SelfTestRow& r = m.self_test[i];
      std::printf("  %6d  %5d  %-8s  %-5s  %s\n", r.id, r.mapping_line, r.detected ? "yes" : "no",
                  r.fired ? "yes" : "no", printable(r.media).c_str());
    }
    if (m.self_test.size() > kShown) std::printf("  ... %zu more rows, all passed\n", m.self_test.size() - kShown);
  }
  if (!quiet)
    for (const std::string& w : plan->warnings) std::printf("note: %s\n", printable(w).c_str());
  if (Status s = bundle::write_export(*plan); !s) {
    print_problem("arwb export: %s\n", s.error().c_str());
    return 1;
  }
  std::printf("exported %s (%zu marker%s of %s, %g mm) to %s\n", printable(m.title).c_str(), m.ids.size(),
              m.ids.size() == 1 ? "" : "s", m.dictionary.c_str(), m.marker_size_mm, printable(o.out).c_str());
  return 0;
}

}  // namespace arwb
