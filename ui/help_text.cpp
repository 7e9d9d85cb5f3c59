#include "ui/help_text.hpp"

namespace arwb::ui {
namespace {

constexpr Shortcut kShortcuts[] = {
    {"S", "snapshot: the frame, every stage's image and the trace"},
    {"Space", "freeze / unfreeze the frame"},
    {"N", "next frame (when frozen): a video's or folder's next one"},
    {"T", "the guided tour"},
    {"F5", "presentation mode"},
    {"F11", "full screen"},
    {"Ctrl+Z", "undo a parameter, preset or dictionary change"},
    {"Ctrl+Shift+Z", "redo"},
    {"Ctrl+S", "save the scene file ('Script editor')"},
    {"Ctrl+Q", "quit (asks first when the 'Script editor' has unsaved edits)"},
    {"Enter", "in a path field: open what is typed"},
    {"Ctrl+click", "a slider: type a value"},
    {"Wheel, right-drag", "zoom and pan an image; right double-click fits it"},
};

constexpr const char* kDeveloper[] = {
    "The live view outlines every marker found in green and every rejected candidate in the colour of the stage "
    "that dropped it.",
    "'Pipeline' shows each stage's image; click one to see it large with the live view's zoom.",
    "'Candidates' lists every candidate and its fate; click a row and the 'Inspector' shows its contour, frontal "
    "view, histogram and bits.",
    "A marker not found? Tick 'Why? (drag)' in the live view and drag a rectangle over it: 'Why not detected?' "
    "names the stage and the parameter, and 'Find the smallest change that detects it' tries the parameter table "
    "there.",
    "'Parameters': every slider says what raising it trades; Ctrl+Z undoes a change, presets save your tuning.",
    "Space freezes the frame, S writes a snapshot of every stage for a bug report.",
};
constexpr const char* kAuthor[] = {
    "File > 'Open scene...' loads a .lua scene or the paper's .xml database; or drop the file on the window.",
    "The 'Scene' panel lists the mappings (marker id -> media) and the markers in view; the example scenes are a "
    "click away there.",
    "The 'Script editor' shows the scene file: edit, Ctrl+S saves and the scene reloads by itself; an error's "
    "line is marked in red.",
    "The 'Console' shows the scene's print output and errors. docs/scene-api.md is the reference.",
    "File > 'Print marker sheet...' writes the markers your scene maps, at a true size.",
};
constexpr const char* kTeacher[] = {
    "F5 (or --presentation) enlarges everything for a projector.",
    "T starts the guided tour: it freezes the frame and walks through the pipeline one stage at a time, with the "
    "stage's image; 'Next frame' moves on.",
    "File > 'Synthetic source' shows markers moving in 3D with exact truth: its sliders add blur, noise, tilt and "
    "poor light, so a class sees each stage fail and recover.",
    "File > 'Print marker sheet...' writes markers at a true size for the class to hold up to the camera.",
};

constexpr FirstStepsPage kPages[] = {
    {"Developer: inspect detection", kDeveloper},
    {"Author: script scenes", kAuthor},
    {"Teacher", kTeacher},
};

}  // namespace

std::span<const Shortcut> shortcuts() { return kShortcuts; }
std::span<const FirstStepsPage> first_steps_pages() { return kPages; }

}  // namespace arwb::ui
