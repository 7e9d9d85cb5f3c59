// The Help menu's words: the keyboard shortcuts and the "First five minutes" pages. Data, drawn by dialogs.cpp;
// a name in 'quotes' is the label of a control or panel exactly as the window shows it (tests/ui/test_help_text.cpp
// checks each one).
#pragma once

#include <span>

namespace arwb::ui {

struct Shortcut {
  const char* keys;
  const char* what;
};
std::span<const Shortcut> shortcuts();

struct FirstStepsPage {
  const char* tab;                       // "Developer: inspect detection"
  std::span<const char* const> lines;    // one bullet each
};
std::span<const FirstStepsPage> first_steps_pages();

}  // namespace arwb::ui
