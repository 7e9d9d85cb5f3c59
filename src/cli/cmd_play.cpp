// `arwb play BUNDLE`: the application the paper generated. The bundle (a folder, or a .arwb / .zip file made by
// `arwb export`) is opened and verified against its manifest first (bundle/bundle.hpp): a bundle that is refused
// says which entry and why in one line, and no window opens (with --error-window, a small one saying the same line,
// passed in by main like the player). Then the player (ui/player.hpp, passed in by main)
// runs with the bundle's scene, calibration, dictionary and marker size.
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "base/text.hpp"
#include "bundle/bundle.hpp"

#include <algorithm>
#include <filesystem>
#include <string>

namespace arwb {

int cmd_play(int argc, char** argv, int (*run)(const PlayerOptions&),
             int (*show_error)(const MessageWindowOptions&)) {
  CommandLine cl("arwb play",
                 "Plays a bundle made by `arwb export` (or File > Export... in the workbench): the camera view with "
                 "the scene's media, filling the window, without the workbench's panels. The bundle is verified "
                 "first: a file missing, changed or added since the export is named and the bundle refused.",
                 "Keys: F1 or I shows a small overlay (fps, markers in view, the scene's title, one stage of the "
                 "pipeline; Left/Right change the stage), F11 full screen on and off, Esc leaves full screen or "
                 "quits, q quits. A click on a web card opens its link.\n"
                 "--actions runs steps at UI frame N, for demos and tests: overlay[=on|off], stage=NAME|next|previous, "
                 "click=X,Y (image pixels), fullscreen=on|off, quit.");
  PlayerOptions o;
  std::string bundle_path, source, window = "1280x720", resize = "640", actions;
  cl.app.add_option("BUNDLE", bundle_path, "the bundle: a folder, or a .arwb or .zip file")->required();
  cl.app.add_option("--source", source,
                    "what to show (default: the first camera, else the synthetic source showing the bundle's own "
                    "markers)")
      ->type_name("camera:N[@WxH]|VIDEO|DIR|IMAGE|synthetic");
  add_resize_option(cl.app, resize);
  cl.app.add_flag("--fullscreen", o.fullscreen, "full screen on the primary monitor, at its own resolution");
  cl.app.add_option("--window", window, "the window's size when not full screen")
      ->type_name("WxH")
      ->check(frame_size({320, 240}, {8192, 8192}));
  cl.app.add_option("--frames", o.frames, "draw N frames, then exit; 0: run until closed")
      ->type_name("N")
      ->check(whole_number(0, 10'000'000));
  cl.app.add_option("--screenshot", o.screenshot, "write the window to this PNG before exiting")->type_name("FILE.png");
  cl.app.add_flag("--stats", o.stats, "print one JSON line of figures at exit");
  bool error_window = false;
  cl.app.add_flag("--error-window", error_window,
                  "a refused bundle is also said in a small window with a Close button (exit status 1 once it is "
                  "closed), for starts without a terminal such as opening the bundle from the file manager");
  cl.app.add_flag("--verbose", o.verbose, "every log line to stderr, not only warnings and errors");
  cl.app.add_option("--actions", actions, "scripted steps 'N:verb[=arg];...', see below")->type_name("STEPS");
  if (const auto status = cl.parse(argc, argv)) return *status;

  // Verified before anything else: a refused bundle opens no window.
  Result<bundle::OpenedBundle> opened = bundle::open_bundle(bundle_path);
  if (!opened) {
    print_problem("arwb play: %s\n", opened.error().c_str());
    if (!error_window) return 1;
    // Started from the desktop, stderr goes nowhere: the same line in a window, or nothing would be seen.
    MessageWindowOptions w;
    w.title = "arwb play: " + printable(std::filesystem::path(bundle_path).filename().string());
    w.heading = "This bundle cannot be played.";
    w.message = printable(opened.error());
    w.frames = o.frames;
    w.screenshot = o.screenshot;
    w.stats = o.stats;
    return show_error(w);
  }
  const bundle::Manifest& m = opened->manifest();

  if (!actions.empty()) o.actions.push_back(actions);
  std::string err;
  if (!parse_source_or_default(source, &o.engine.source, &err)) return cl.usage_error("--source " + err);
  o.window = *parse_frame_size(window);  // checked by frame_size
  apply_resize_option(resize, o.engine.acquisition);
  o.engine.scene_file = opened->scene_path();
  o.engine.calibration_file = opened->calibration_path();
  if (!m.dictionary.empty()) o.engine.dictionaries = {m.dictionary};
  // Poses in millimetres, as printed on the bundle's marker sheet.
  o.engine.marker_size = m.marker_size_mm;
  o.ids = m.ids;
  o.title = m.title;
  o.private_dir = opened->dir().string();
  o.bundle = bundle_path;
  return run(o);   // `opened` lives until the player ends: its folder holds the scene and media
}

}  // namespace arwb
