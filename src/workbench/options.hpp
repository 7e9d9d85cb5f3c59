// What the workbench is started with: the engine's configuration and the window's options (cli/cmd_workbench.cpp
// reads them from the command line; ui/window.hpp runs the window with them).
#pragma once

#include "workbench/engine.hpp"

#include <string>
#include <vector>

namespace arwb {

struct WorkbenchOptions {
  EngineConfig engine;
  int frames = 0;                 // > 0: draw this many UI frames, then exit (scripted runs, tests)
  std::string screenshot;         // write the window to this PNG before exiting
  bool stats = false;             // print one JSON line of figures at exit
  bool verbose = false;           // every log line to stderr, not only warnings and errors
  cv::Size window{1600, 900};
  bool presentation = false;
  bool fullscreen = false;        // on the primary monitor at its own resolution (F11 toggles)
  std::string config_dir;         // layout and settings (default $XDG_CONFIG_HOME/arwb or ~/.config/arwb)
  std::string snapshot_dir = "snapshots";
  std::string tour_path;          // default assets/teaching/tour.txt
  // Scripted actions for tests and demos: "N:verb[=arg]" run at UI frame N. Verbs: open=PANEL, close=PANEL,
  // source=SPEC, freeze, unfreeze, next, snapshot, stage=NAME, select=INDEX, region=X,Y,W,H, sweep, tour,
  // presentation, preset=FILE, peers, and the rest `arwb --help` lists.
  std::vector<std::string> actions;
};

// What the player (`arwb play BUNDLE`, ui/player.hpp) is started with: the engine's configuration filled from the
// bundle (its scene, calibration, dictionary and marker size) and the source, and the window's options.
struct PlayerOptions {
  EngineConfig engine;
  std::vector<int> ids;           // the bundle's ids: what the synthetic source shows, so the media appear without a camera
  std::string title;              // the bundle's title: the window's title and the overlay's first line
  // The bundle's private copy and the bundle as the user named it: messages say "museum.arwb/scene.lua:3: ..."
  // where the engine names "/tmp/arwb-bundle-Xa81Qz/scene.lua:3: ...", a folder the user never saw.
  std::string private_dir, bundle;
  int frames = 0;                 // > 0: draw this many frames, then exit (scripted runs, tests)
  std::string screenshot;         // write the window to this PNG before exiting
  bool stats = false;             // print one JSON line of figures at exit
  bool verbose = false;           // every log line to stderr, not only warnings and errors
  bool fullscreen = false;        // on the primary monitor at its own resolution
  cv::Size window{1280, 720};     // the window's size when not full screen
  // Scripted actions "N:verb[=arg]": overlay[=on|off], stage=NAME|next|previous, click=X,Y (image pixels),
  // fullscreen=on|off, quit.
  std::vector<std::string> actions;
};

// What `arwb play --error-window` shows when the bundle is refused (ui/message_window.hpp): the one-line message
// in a small window of its own, and the same --frames, --screenshot and --stats as the player for tests.
struct MessageWindowOptions {
  std::string title;              // the window's title
  std::string heading;            // a short first line ("This bundle cannot be played.")
  std::string message;            // the refusal, as printed on stderr
  int frames = 0;                 // > 0: draw this many frames, then close
  std::string screenshot;         // write the window to this PNG before closing
  bool stats = false;             // print one JSON line (what was shown, how it was closed) at exit
};

}  // namespace arwb
