// `arwb [options]`: the workbench's command line, read into WorkbenchOptions and handed to the window.
#include "cli/cli_common.hpp"
#include "cli/commands.hpp"

#include <cstdio>

namespace arwb {

int cmd_workbench(int argc, char** argv, int (*run)(const WorkbenchOptions&)) {
  Args args(argc, argv);
  if (args.flag("--help")) {
    std::printf(
        "usage: arwb [--source synthetic|camera:N|PATH] [--frames N] [--screenshot FILE.png] [--stats]\n"
        "            [--dict NAME[,NAME]] [--params FILE.yml] [--size WxH] [--fps-cap F] [--resize WxH|off]\n"
        "            [--presentation] [--config-dir DIR] [--snapshot-dir DIR] [--tour FILE] [--verbose]\n"
        "            [--scene FILE.lua|FILE.xml] [--actions 'N:verb[=arg];...']\n\n"
        "Opens the workbench window. --frames N draws N frames and exits; --screenshot writes the window to a PNG\n"
        "then; --stats prints one JSON line of figures at exit. Without --source it shows the first camera, or the\n"
        "built-in synthetic source when there is none. --scene loads a Lua scene or XML database (docs/scene-api.md)\n"
        "and reloads it whenever the file changes.\n"
        "--actions runs steps at UI frame N, for demos and tests: open=PANEL|all, close=PANEL|all, source=SPEC,\n"
        "freeze, unfreeze, next, snapshot, stage=NAME, select=INDEX|marker, region=X,Y,W,H, sweep, tour[=STEP],\n"
        "presentation, preset=FILE, peers, scene=FILE, media=on|off, click=X,Y (image pixels; opens a web card).\n"
        "Panels: live_view pipeline candidates inspector parameters timings dictionary peers source tour why log\n"
        "scene script console.\n"
        "Keys: S snapshot, Space freeze, N next frame, T tour, F5 presentation mode, Ctrl+Q quit.\n");
    return 0;
  }
  WorkbenchOptions o;
  // No --source: the first camera when there is one (a failing one falls back to the synthetic source, with a
  // message), else the synthetic source.
  const std::vector<int> cameras = list_cameras();
  const std::string source =
      args.value("--source", cameras.empty() ? "synthetic" : "camera:" + std::to_string(cameras.front()));
  o.frames = args.int_value("--frames", 0, 0, 10'000'000);
  o.screenshot = args.value("--screenshot", "");
  o.stats = args.flag("--stats");
  o.verbose = args.flag("--verbose");
  o.presentation = args.flag("--presentation");
  o.config_dir = args.value("--config-dir", "");
  o.snapshot_dir = args.value("--snapshot-dir", "snapshots");
  o.tour_path = args.value("--tour", "");
  const std::string dict = args.value("--dict", "ARUCO_ORIGINAL");
  const std::string params = args.value("--params", "");
  const std::string size = args.value("--size", "1600x900");
  o.engine.acquisition.fps_cap = args.double_value("--fps-cap", 20, 0, 240);
  const std::string resize = args.value("--resize", "640x480");
  const std::string actions = args.value("--actions", "");
  o.engine.scene_file = args.value("--scene", "");
  if (!args.no_positional() || !args.ok()) return args.fail("arwb");
  if (!actions.empty()) o.actions.push_back(actions);
  std::string err;
  if (!parse_source_spec(source, &o.engine.source, &err)) {
    std::fprintf(stderr, "arwb: --source %s\n", err.c_str());
    return 2;
  }
  if (std::sscanf(size.c_str(), "%dx%d", &o.window.width, &o.window.height) != 2 || o.window.width < 320 ||
      o.window.height < 240 || o.window.width > 8192 || o.window.height > 8192) {
    std::fprintf(stderr, "arwb: --size '%s': expected WxH between 320x240 and 8192x8192\n", size.c_str());
    return 2;
  }
  if (resize == "off") {
    o.engine.acquisition.resize = false;
  } else if (std::sscanf(resize.c_str(), "%dx%d", &o.engine.acquisition.size.width,
                         &o.engine.acquisition.size.height) != 2 ||
             o.engine.acquisition.size.width < 16 || o.engine.acquisition.size.height < 16 ||
             o.engine.acquisition.size.width > 8192 || o.engine.acquisition.size.height > 8192) {
    std::fprintf(stderr, "arwb: --resize '%s': expected WxH (16..8192) or off\n", resize.c_str());
    return 2;
  }
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
