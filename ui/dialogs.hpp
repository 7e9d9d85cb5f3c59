// The window's dialogs' own state (ui/dialogs.cpp draws them): the file browsers, the unsaved-edits question, the
// marker sheet dialog, the Help windows, and a script's keyboard and button presses (--actions type=, answer=).
#pragma once

#include "ui/file_browser.hpp"
#include "ui/request.hpp"

#include <deque>
#include <optional>
#include <string>

namespace arwb {

struct Dialogs {
  ui::FileBrowser browser;                 // File > Open source / scene / preset, Play bundle
  std::optional<ui::FileKind> browse;      // the browser opens for this kind at the next draw (ui::Browse)
  ui::FileBrowser calibration_browser;     // the Calibrate panel's Save...
  bool save_calibration = false;           // that browser opens at the next draw (ui::SaveCalibrationAs)
  // The unsaved-edits question: what waits for the answer.
  struct Unsaved {
    bool ask = false;                      // open the modal at the next draw
    bool quit_waiting = false;             // a quit waits
    std::optional<ui::Request> deferred;   // a source or scene change waits
    bool quit_confirmed = false;           // the user chose: quit for real
    int save_wait = -1;                    // frames since "Save" was chosen, while the editor's save is awaited
  } unsaved;
  // File > Print marker sheet...
  struct Sheet {
    bool opening = false;
    std::string dictionary;
    char ids[256] = "0-11";
    double size_mm = 50;
    char path[1024] = "";
    ui::FileBrowser browser;
  } sheet;
  bool show_shortcuts = false, show_first_steps = false, show_about = false;   // the Help menu's windows
  std::string modal;                       // the modal shown this frame ("Unsaved edits"), for --stats
  // A script's input: a dialog's button pressed at its next draw, and text typed one character a frame, its key
  // held for one frame, then released.
  std::optional<ui::DialogButton> answer;
  std::deque<int> typing;
  int key_down = -1;
};

}  // namespace arwb
