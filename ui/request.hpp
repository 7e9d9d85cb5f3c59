// What the window can be asked to do: one struct per thing, with named, typed fields, and ui::Request, any one of
// them. Panels and dialogs append requests to Context::requests; the window's menus, its keys, a file dropped on it
// and an --actions step (ui/actions.hpp turns "N:verb=arg" into one) make the same structs. App::carry_out
// (ui/requests.cpp) is the one place each is carried out.
#pragma once

#include "board/board_spec.hpp"
#include "detect/trace.hpp"
#include "ui/panel_id.hpp"
#include "ui/recent_files.hpp"

#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace arwb {
struct ParamInfo;
}
namespace arwb::lab {
struct PlanAxis;
}

namespace arwb::ui {

// [SECTION] Panels and workspaces
struct SetPanelOpen {
  std::optional<Panel> panel;   // none: every panel
  bool open = true;             // opening one panel also brings its tab to the front
};
struct SwitchWorkspace {
  std::string name;
};
struct SaveWorkspace {
  std::string name;   // the current arrangement, under this name
};
struct MovePanel {   // what dragging a tab onto another region does
  Panel panel;
  Panel beside;      // into the region that shows this one
};
struct SetSplitter {   // what dragging a splitter does
  int index = 0;       // the current workspace's splits, depth first
  float ratio = 0.5f;
};
struct TogglePresentation {};
struct SetFullscreen {          // full screen on the primary monitor, or back to a window
  std::optional<bool> on;       // nullopt: the other of the two (F11)
};
enum class HelpPage { shortcuts, first_steps, about };
struct ShowHelp {
  HelpPage page;
  bool on = true;
};
struct StartTour {   // freezes the frame and opens the Tour panel
  std::string step;    // a step's name ("adaptive_threshold") or number from 0; "" keeps the step shown
};

// [SECTION] What the live view shows
struct ShowStage {
  std::optional<Stage> stage;   // shown large in the Pipeline panel; none: the input frame
};
struct SelectCandidate {
  std::optional<int> index;   // none: the candidate that became the frame's first marker
};
struct SetRegion {   // the "why not detected?" rectangle, in working-image pixels
  cv::Rect2f region;
};
struct ShowMedia {
  bool on = true;
};
struct SetLabels {   // the live view's labels and overlays
  bool ids = false, dictionary = false, rejected = false, truth = false, peers = false;
};
struct SetPoseDrawing {   // 3D over each marker's pose
  bool axes = false, cube = false, alternative = false;
};
struct ClickLiveView {   // a click on the live view, at image pixels: a web card there opens
  cv::Point2d at;
};

// [SECTION] Sources and frames
struct OpenSource {
  std::string spec;     // as --source takes it
  bool asked = false;   // the unsaved-edits question was answered already
};
struct StepFrames {   // a video's frames or a folder's images
  int by = 1;
};
struct Seek {
  int position = 0;
};
struct SetSpeed {   // a video's or folder's playback speed (a folder plays one image a second at 1)
  double speed = 1;
};
struct NextFrame {     // frozen: one new frame from the source
  bool wait = false;   // a script's: a video or folder steps past the frame shown, and the window waits to show it
};
struct Freeze {
  bool on = true;
};
struct Snapshot {};   // the frame, every stage's image and the trace, into a folder
struct Drop {         // a file dropped on the window: opened as what it is
  std::string path;
};
struct OpenRecent {   // File > Recent: opened as its kind, and first in the list again
  FileKind kind;
  std::string path;
};
struct OpenUrl {   // a web card's link, in the system's browser
  std::string url;
};

// [SECTION] Files: presets, scenes, the file browser
struct LoadPreset {
  std::string path;   // a bare name is the user's (config_dir/presets)
};
struct SavePreset {
  std::string path;
};
struct ListPresets {};   // into Status::presets
struct LoadScene {
  std::string path;     // "" unloads the scene
  bool asked = false;   // as for OpenSource
};
struct ListExamples {};   // into Status::examples
struct SaveScript {       // the scene then reloads by itself
  std::string path;
  std::string text;
};
struct WatchFile {         // read into Status::script_file and looked at again twice a second
  std::string path;        // "" none
  bool reread = false;     // read it even when unchanged (Revert)
};
struct Browse {   // the file browser, to open a file of this kind
  FileKind kind;
};
struct ListDir {   // into Status::listing
  std::string path;
};
struct OpenFile {   // typed or picked in the file browser: a folder is listed, a file opened as `kind`
  std::string path;
  FileKind kind;
  bool folder_itself = false;   // a folder opened as it is (a folder of images as the source), not listed
};
struct ToggleFavourite {
  std::string folder;
};

// [SECTION] The detector
struct SetParam {   // a completed edit, as letting go of a slider is
  const ParamInfo* param = nullptr;
  double value = 0;
};
struct AddDictionary {   // searched too, as the Why panel's button does
  std::string name;
};
struct ComputeDictionaryStats {   // into Status::dictionary_stats, off the UI thread
  std::string dictionary;
};
struct EnablePeers {};   // OpenCV's and AprilTag's detectors on the same frames
struct Undo {};
struct Redo {};
struct Sweep {};   // the parameter sweep over the region drawn (View::region)

// [SECTION] Dialogs and input
struct OpenSheetDialog {   // File > Print marker sheet...
  std::string dictionary;  // "": the first searched, the ids as last typed; else twelve ids from first_id
  int first_id = 0;
};
struct WriteMarkerSheet {   // a PDF of markers at a true size
  std::string path;
  std::string dictionary;   // "": the first searched
  std::string ids;          // as typed: "0-11", "3,7,9" or "0-3,8"
  double size_mm = 50;
};
// A button of the dialog on screen, pressed: Save, Discard, Cancel (the unsaved-edits question), Write, Browse
// (the marker sheet dialog), Check, Export (File > Export...).
enum class DialogButton { save, discard, cancel, write, browse, check, export_bundle };
struct PressButton {
  DialogButton button;
};
enum class TextField { none, script, source_path, preset_path };
struct Focus {   // the text field takes the keyboard at its next draw
  TextField field;
};
struct TypeText {   // one character a frame, as a keyboard would ('\n' is Enter)
  std::string text;
};
struct Quit {};   // asks first when the Script editor has unsaved edits

// [SECTION] The Calibrate workspace
struct SetCalibrationBoard {
  BoardSpec board;
};
struct SetCalibrationCapture {
  bool on = true;
};
struct SetUndistort {
  bool on = false;
};
struct SetMarkerSize {   // the printed marker's side: poses in its unit; 0: in marker sides
  double size = 0;
};
struct DropCalibrationView {   // a kept view dropped, and the views solved again
  std::string name;            // as the Calibration views panel names it...
  int number = 0;              // ...or, when name is "", the number-th kept, from 1
};
struct ResetCalibration {};
struct SaveCalibrationAs {};   // the file browser asks where, then SaveCalibration
struct SaveCalibration {       // with the paper's two files when View::calibration_paper_files
  std::string path;
};
struct WaitForCalibration {   // a script's: until this many views are kept and solved (120 s at most)
  int views = 0;
};

// [SECTION] The Lab workspace
struct UsePaperPlan {};
struct ReadLabPlan {   // a plan file (YAML) into Settings::lab.plan
  std::string path;
};
struct SetLabFrames {
  int per_cell = 1;
};
struct SetLabAxis {
  const lab::PlanAxis* axis = nullptr;
  std::vector<double> values;
};
struct SetLabDetectors {
  std::vector<std::string> detectors;
};
struct StartLab {};   // Settings::lab's plan, run in the background
struct StopLab {};    // after the frame in hand; the finished cells stay
struct WaitForLab {   // a script's: until the run has finished `cells` (-1: until it ends; 600 s at most)
  int cells = -1;
};
struct OpenLabCell {   // a cell of the run, in the live view
  int cell = 0;
  int frame = 0;
};
struct WhyLabMarker {};   // Why not detected? on the lab frame's marker
enum class SpanEnd { start, end, whole };
struct MarkClipSpan {   // the video frame shown starts or ends the marker's span
  SpanEnd end;
};
struct ClipRow {   // the clip's row as typed in the Lab panel
  int id = 0;
  double size_mm = 0, distance_m = 0, lux = 0;
  std::string dir;   // the folder whose videos.csv gets the row ("": the clip's own)
};
struct SaveClip {   // Settings::lab.clip for the video playing, into videos.csv
  std::optional<ClipRow> typed;
};
struct RecordClip {   // Record: a clip from the source with Settings::lab.clip's conditions, listed in videos.csv
  std::optional<ClipRow> typed;   // dir: the folder of clips/ and videos.csv ("": as the panel says)
};
struct StopClip {};   // Stop: the clip ends, and its row goes into videos.csv
struct PrintClipMarker {};   // the clip's marker at its size typed, a PDF in Record's folder
struct SaveLabReport {   // tables, plots and report.pdf
  std::string dir;
};

// [SECTION] Export and play
struct OpenExportDialog {   // File > Export...
  std::string out;          // "": into the user's bundles folder
};
struct CheckExport {};      // the dialog's Check: the self-test, off the UI thread
struct WriteExport {        // the dialog's Export: checked again, then written
  // Given: the dialog set up first for this path ("": the default one), as File > Export... does, unseen.
  std::optional<std::string> out;
};
struct SetExportTitle {
  std::string title;
};
struct SetExportSize {
  double mm = 50;
};
struct SetExportCalibration {
  bool on = true;
};
struct SetExportForce {
  bool on = false;
};
struct SetExportWeb {
  bool on = false;
};
struct SetExportConvert {   // the dialog's 'convert what phones cannot play'
  bool on = false;
};
struct ServeBundle {   // the dialog's Serve: the bundle written, on 127.0.0.1 (on), or no more (off)
  bool on = true;
};
struct WaitForExport {   // a script's: until the check, export or server start running ends
  double seconds = 120;
};
struct PlayBundle {   // verified off the UI thread, then `arwb play` started on it
  std::string path;
};
struct SetPlayArgs {   // more arguments for the players started
  std::vector<std::string> args;
};
struct WaitForPlayers {   // a script's: until every player started has ended
  double seconds = 120;
};
struct WaitForSource {   // a script's: until the worker has taken the source last opened
  double seconds = 30;
};

using Request = std::variant<
    SetPanelOpen, SwitchWorkspace, SaveWorkspace, MovePanel, SetSplitter, TogglePresentation, SetFullscreen, ShowHelp,
    StartTour,
    ShowStage, SelectCandidate, SetRegion, ShowMedia, SetLabels, SetPoseDrawing, ClickLiveView,
    OpenSource, StepFrames, Seek, SetSpeed, NextFrame, Freeze, Snapshot, Drop, OpenRecent, OpenUrl,
    LoadPreset, SavePreset, ListPresets, LoadScene, ListExamples, SaveScript, WatchFile, Browse, ListDir, OpenFile,
    ToggleFavourite,
    SetParam, AddDictionary, ComputeDictionaryStats, EnablePeers, Undo, Redo, Sweep,
    OpenSheetDialog, WriteMarkerSheet, PressButton, Focus, TypeText, Quit,
    SetCalibrationBoard, SetCalibrationCapture, SetUndistort, SetMarkerSize, DropCalibrationView, ResetCalibration,
    SaveCalibrationAs, SaveCalibration, WaitForCalibration,
    UsePaperPlan, ReadLabPlan, SetLabFrames, SetLabAxis, SetLabDetectors, StartLab, StopLab, WaitForLab, OpenLabCell,
    WhyLabMarker, MarkClipSpan, SaveClip, RecordClip, StopClip, PrintClipMarker,
    SaveLabReport,
    OpenExportDialog, CheckExport, WriteExport, SetExportTitle, SetExportSize, SetExportCalibration, SetExportForce,
    SetExportWeb, SetExportConvert, ServeBundle, WaitForExport, PlayBundle, SetPlayArgs, WaitForPlayers, WaitForSource>;

// std::visit over one lambda per struct: Overloaded{[&](const A&) {...}, [&](const B&) {...}}.
template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
// Written out for clang 14, which does not deduce an aggregate's template arguments (C++20's P1816).
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

}  // namespace arwb::ui
