// `arwb [options]`: the workbench's command line, read into WorkbenchOptions and handed to the window. Its help is
// also `arwb --help`, so it lists the subcommands too.
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"
#include "base/version.hpp"
#include "base/data_dirs.hpp"

#include <cstdio>

namespace arwb {

int cmd_workbench(int argc, char** argv, int (*run)(const WorkbenchOptions&)) {
  CommandLine cl("arwb",
                 "Opens the workbench window; `arwb <subcommand> [options]` runs a command-line tool instead. "
                 "--frames N draws N frames and exits; --screenshot writes the window to a PNG then; --stats prints "
                 "one JSON line of figures at exit. --scene loads a Lua scene or XML database (docs/scene-api.md) and "
                 "reloads it whenever the file changes.",
                 "--actions runs steps at UI frame N, for demos and tests: open=PANEL|all, close=PANEL|all, "
                 "source=SPEC, source_wait[=S] (waits, 30 s unless given, until the worker has taken it), freeze, unfreeze, next (the next frame; of a video or folder the one after the "
                 "frame shown; waits up to 2 s until it is shown), speed=X (a video's or folder's pace, 0.1 to 8; a folder "
                 "plays one image a second at 1), snapshot, "
                 "stage=NAME, select=INDEX|marker, region=X,Y,W,H, "
                 "sweep, tour[=STEP] (a step's name, such as adaptive_threshold, or its number from 0), presentation, "
                 "fullscreen=on|off, preset=FILE, peers, scene=FILE, media=on|off, click=X,Y (image "
                 "pixels; opens a web card), labels=KINDS (what the live view shows, a comma list of ids, dict, "
                 "rejected, truth, peers, or all or none), add_dictionary=NAME (searched too, as the Why panel's button does), "
                 "drop=PATH (as dropped on the window), focus=script|source_path|preset_path, "
                 "type=TEXT (typed on the keyboard, \\n for Enter), undo, redo, set=PARAM=VALUE (a completed edit), "
                 "save_preset=NAME|PATH, "
                 "quit, answer=save|discard|cancel|write|browse (a dialog's button), browse=source|scene|preset, sheet (the "
                 "marker sheet dialog), help=shortcuts|first|about, "
                 "workspace=NAME, save_workspace=NAME, move=PANEL>PANEL (into the region of the second), "
                 "splitter=I,RATIO, calib_board=chessboard|charuco[,COLS,ROWS[,SQUARE_MM[,MARKER_MM]]], "
                 "calib_capture=on|off, calib_drop=N (the N-th view kept), calib_reset, calib_save=PATH, "
                 "calib_wait[=N] (waits until N views are kept and solved), "
                 "undistort=on|off, pose=KINDS (3D over each marker's pose: a comma list of axes, cube, alternative, "
                 "or all or none), marker_size=L (the printed marker's side: poses in its unit; 0: marker sides), "
                 "lab_plan=paper|FILE.yml, lab_frames=N (per cell), lab_axis=sizes_mm:65,39 (or distances_m:, lux:, or "
                 "an added axis: sides_px:, tilts_deg:, blurs_px:, noises:, occlusions:), "
                 "lab_detectors=arwb,opencv,..., lab_run, lab_stop, lab_wait[=CELLS] (waits until the run has that "
                 "many cells, or has ended), lab_cell=I[,K] (cell I of the run, frame K, in the live view), lab_why "
                 "(Why not detected? on the lab frame's marker), lab_save=DIR, lab_span=start|end|whole (the video "
                 "frame shown starts or ends the marker's span), lab_clip=ID,SIZE_MM,DISTANCE_M,LUX[,DIR] (the clip's "
                 "row saved to videos.csv), lab_record=ID,SIZE_MM,DISTANCE_M,LUX[,DIR] (Record: a clip of the source "
                 "with these conditions into DIR/clips, its row in DIR/videos.csv), lab_record=stop, lab_print (the "
                 "clip's marker at its size, a PDF in that folder), export_dialog[=PATH] (File > Export...; "
                 "answer=check|export|cancel|browse presses its buttons), export=PATH (File > Export...'s Export with "
                 "the dialog's values), export_title=T, export_size=MM, export_calibration=on|off, "
                 "export_force=on|off, export_web=on|off, export_convert=on|off (convert what phones cannot play), "
                 "serve=on|off (the Export dialog's Serve: the bundle just written with its web page, on 127.0.0.1), "
                 "export_wait[=S] (waits until the check, export or server start ends), play=BUNDLE (File > Play "
                 "bundle...: verified, then `arwb play` started as a process of its own), play_args=ARGS (more "
                 "arguments for it, e.g. --frames 30), play_wait[=S] (waits until the players started have ended).\n"
                 "Panels: live_view pipeline candidates inspector parameters timings dictionary peers source tour why "
                 "log scene script console calibrate calibration_views pose lab.\n"
                 "Keys: S snapshot, Space freeze, N next frame, T tour, F5 presentation mode, F11 full screen, Ctrl+1/2/3/4/5 workspaces Inspect/Script/Teach/Calibrate/Lab, Ctrl+Z undo, Ctrl+Shift+Z "
                 "redo, Ctrl+Q quit; none of them while typing in a text field. Help > Keyboard shortcuts lists them "
                 "all. Drop a scene (.lua, .xml), preset (.yml), image, video or folder on the window to open it.");
  std::vector<std::pair<std::string, std::string>> subcommands;
  for (const Subcommand& s : arwb_subcommands()) subcommands.emplace_back(s.name, s.summary);
  subcommands.emplace_back("play", kPlaySummary);   // dispatched by main, which passes it the player window
  cl.add_section("subcommands (`arwb <subcommand> --help` describes each one)", subcommands);
  // Where the presets, the tour and the example scenes are read from: an installed arwb's own share/arwb, or a
  // build tree's source tree (base/data_dirs.hpp). Said here so a packaged arwb can be seen to use its own.
  cl.add_section(data_dirs().installed ? "shipped data (installed beside arwb, in ../share/arwb)"
                                       : "shipped data (in the source tree arwb was built from)",
                 {{"assets", "presets, the tour, the sample image: " + data_dirs().assets},
                  {"examples", "the example scenes: " + data_dirs().examples}});

  cl.app.set_version_flag("--version", std::string("arwb ") + kVersion, "print the version and exit");
  WorkbenchOptions o;
  std::string source, dict = "ARUCO_ORIGINAL", params, size = "1600x900", resize = "640", actions;
  cl.app.add_option("--source", source,
                    "what to show (default: the first camera, else the built-in synthetic source; a camera that "
                    "fails falls back to the synthetic source, with a message)")
      ->type_name("synthetic|camera:N[@WxH]|PATH");
  cl.app.add_option("--frames", o.frames, "draw N frames, then exit; 0: run until closed")
      ->type_name("N")
      ->check(whole_number(0, 10'000'000));
  cl.app.add_option("--screenshot", o.screenshot, "write the window to this PNG before exiting")
      ->type_name("FILE.png");
  cl.app.add_flag("--stats", o.stats, "print one JSON line of figures at exit");
  cl.app.add_option("--dict", dict, "the detector's dictionaries, as for arwb detect")->type_name("NAME[,NAME...]");
  cl.app.add_option("--params", params, "a YAML preset of detector parameters")->type_name("FILE.yml");
  cl.app.add_option("--size", size, "the window's size")->type_name("WxH")->check(frame_size({320, 240}, {8192, 8192}));
  cl.app.add_option("--fps-cap", o.engine.acquisition.fps_cap, "frames per second taken from the source; 0: no cap")
      ->type_name("F")
      ->check(real_number(0, 240));
  add_resize_option(cl.app, resize);
  cl.app.add_flag("--fullscreen", o.fullscreen, "full screen on the primary monitor, at its own resolution (F11)");
  cl.app.add_flag("--presentation", o.presentation, "start in presentation mode (F5): fonts and sizes scaled to the window's height (30 px text at 1080 lines), the live view and stage large");
  cl.app.add_option("--config-dir", o.config_dir,
                    "layout and settings (default $XDG_CONFIG_HOME/arwb or ~/.config/arwb)")
      ->type_name("DIR");
  cl.app.add_option("--snapshot-dir", o.snapshot_dir, "where snapshots go")->type_name("DIR");
  cl.app.add_option("--tour", o.tour_path, "the guided tour (default " + data_dirs().assets + "/teaching/tour.txt)")
      ->type_name("FILE");
  cl.app.add_flag("--verbose", o.verbose, "every log line to stderr, not only warnings and errors");
  cl.app.add_option("--scene", o.engine.scene_file, "a Lua scene or the paper's XML database")
      ->type_name("FILE.lua|FILE.xml");
  cl.app.add_option("--calib", o.engine.calibration_file,
                    "a camera calibration (OpenCV's, its interactive app's, the paper's or ROS's file) for the "
                    "undistorted view; a bad one is reported and the workbench runs without it")
      ->type_name("FILE.xml|FILE.yml");
  cl.app.add_option("--marker-size", o.engine.marker_size,
                    "the printed marker's side, in the unit poses should be in (mm, cm, m); default: poses in "
                    "marker sides")
      ->type_name("L")
      ->check(CLI::Range(0.0, 1e6));
  cl.app.add_option("--synthetic-step", o.engine.synthetic_step_s,
                    "the synthetic source moves on S seconds per frame taken instead of with the clock, and the "
                    "Calibrate workspace judges every frame it gives (waiting for the board search): the same frames "
                    "on a slow machine as on a fast one, for scripted runs and tests; 0: with the clock")
      ->type_name("S")
      ->check(real_number(0, 10));
  cl.app.add_option("--actions", actions, "scripted steps 'N:verb[=arg];...', see below")->type_name("STEPS");
  if (const auto status = cl.parse(argc, argv)) return *status;

  if (!actions.empty()) o.actions.push_back(actions);
  std::string err;
  if (!parse_source_or_default(source, &o.engine.source, &err)) return cl.usage_error("--source " + err);
  o.window = *parse_frame_size(size);  // checked by frame_size
  apply_resize_option(resize, o.engine.acquisition);
  if (!dictionaries_option(dict, "arwb")) return 2;
  o.engine.dictionaries.clear();
  for (size_t start = 0; start <= dict.size();) {
    size_t end = dict.find(',', start);
    if (end == std::string::npos) end = dict.size();
    if (end > start) o.engine.dictionaries.push_back(dict.substr(start, end - start));
    start = end + 1;
  }
  if (!load_params_option(params, "arwb", o.engine.params)) return 2;
  return run(o);
}

}  // namespace arwb
