// [SECTION] Index
//   Arguments   the shapes arguments take: on|off, lists, numbers
//   Verbs       one parser a verb, in one table
//   Script      the steps of --actions, split, sorted and parsed
#include "ui/actions.hpp"

#include "detect/dictionary.hpp"
#include "detect/params.hpp"
#include "lab/plan.hpp"
#include "workbench/actions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <sstream>

namespace arwb::ui {

namespace {

using Arg = const std::string&;
using Parse = Result<Request> (*)(Arg verb, Arg arg);

// [SECTION] Arguments
Result<bool> on_off(Arg verb, Arg arg) {
  if (arg != "on" && arg != "off") return fail("--actions " + verb + ": on or off, not '" + arg + "'");
  return arg == "on";
}

// A verb whose argument is on or off, asking for the request T{on}.
template <class T>
Result<Request> switch_to(Arg verb, Arg arg) {
  const Result<bool> on = on_off(verb, arg);
  return on ? Result<Request>(T{*on}) : fail(on.error());
}

// A comma list of kinds, each one of `names`, or all, or none: which are on.
Result<std::vector<bool>> kinds(Arg verb, Arg arg, const std::vector<std::string>& names) {
  std::vector<bool> on(names.size(), false);
  for (size_t at = 0; at <= arg.size();) {
    const size_t comma = std::min(arg.find(',', at), arg.size());
    const std::string kind = arg.substr(at, comma - at);
    at = comma + 1;
    const auto it = std::find(names.begin(), names.end(), kind);
    if (kind == "all") {
      on.assign(names.size(), true);
    } else if (it != names.end()) {
      on[static_cast<size_t>(it - names.begin())] = true;
    } else if (kind != "none" && !kind.empty()) {
      std::string known;
      for (const std::string& n : names) known += n + ", ";
      return fail("--actions " + verb + "=" + arg + ": no kind '" + kind + "' (" + known + "all, none)");
    }
  }
  return on;
}

// export_wait[=S], play_wait[=S]: 120 s unless given, at most 600.
double seconds(Arg arg) { return arg.empty() ? 120 : std::clamp(std::atof(arg.c_str()), 0.0, 600.0); }

// "a, b or c" for a message.
std::string one_of(const std::vector<std::string>& names) {
  std::string s;
  for (size_t i = 0; i < names.size(); ++i) s += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return s;
}

// The index of `arg` in `names`, or a message naming the verb, the names and the argument.
Result<size_t> choice(Arg verb, Arg arg, const std::vector<std::string>& names) {
  const auto it = std::find(names.begin(), names.end(), arg);
  if (it == names.end()) return fail("--actions " + verb + ": " + one_of(names) + ", not '" + arg + "'");
  return static_cast<size_t>(it - names.begin());
}

// [SECTION] Verbs
Result<Request> panel_open(Arg verb, Arg arg) {
  Panel p;
  if (arg == "all") return Request(SetPanelOpen{std::nullopt, verb == "open"});
  if (!panel_from_key(arg, &p)) return fail("--actions: no panel '" + arg + "'");
  return Request(SetPanelOpen{p, verb == "open"});
}

Result<Request> move(Arg, Arg arg) {
  // move=PANEL>OTHER: PANEL into the region showing OTHER.
  const size_t gt = arg.find('>');
  Panel p, q;
  if (gt == std::string::npos || !panel_from_key(arg.substr(0, gt), &p) || !panel_from_key(arg.substr(gt + 1), &q))
    return fail("--actions: move wants PANEL>PANEL_IN_THE_TARGET_REGION, not '" + arg + "'");
  return Request(MovePanel{p, q});
}

Result<Request> splitter(Arg, Arg arg) {
  // splitter=I,RATIO: the I-th split of the current workspace (depth first) at RATIO.
  int i = -1;
  float r = 0;
  if (std::sscanf(arg.c_str(), "%d,%f", &i, &r) != 2 || i < 0 || !(r >= 0.05f && r <= 0.95f))
    return fail("--actions: splitter wants I,RATIO (RATIO in 0.05..0.95), not '" + arg + "'");
  return Request(SetSplitter{i, r});
}

Result<Request> stage(Arg, Arg arg) {
  Stage s;
  if (arg == "input") return Request(ShowStage{std::nullopt});
  if (!stage_from_name(arg, &s)) return fail("--actions: no stage '" + arg + "'");
  return Request(ShowStage{s});
}

Result<Request> region(Arg, Arg arg) {
  float x, y, w, h;
  if (std::sscanf(arg.c_str(), "%f,%f,%f,%f", &x, &y, &w, &h) != 4 || !(w > 0 && h > 0))
    return fail("--actions: region wants X,Y,W,H, not '" + arg + "'");
  return Request(SetRegion{{x, y, w, h}});
}

Result<Request> labels(Arg verb, Arg arg) {
  // labels=ids,dict,rejected,truth,peers: those drawn, the others not; all; none.
  const Result<std::vector<bool>> on = kinds(verb, arg, {"ids", "dict", "rejected", "truth", "peers"});
  if (!on) return fail(on.error());
  const std::vector<bool>& k = *on;
  return Request(SetLabels{k[0], k[1], k[2], k[3], k[4]});
}

Result<Request> pose(Arg verb, Arg arg) {
  const Result<std::vector<bool>> on = kinds(verb, arg, {"axes", "cube", "alternative"});
  if (!on) return fail(on.error());
  return Request(SetPoseDrawing{(*on)[0], (*on)[1], (*on)[2]});
}

Result<Request> click(Arg, Arg arg) {
  double x = 0, y = 0;
  if (std::sscanf(arg.c_str(), "%lf,%lf", &x, &y) != 2)
    return fail("--actions click=" + arg + ": expected X,Y in image pixels");
  return Request(ClickLiveView{{x, y}});
}

Result<Request> add_dictionary(Arg, Arg arg) {
  std::string err;
  const std::optional<Dictionary> d = dictionary_by_name(arg, &err);
  if (!d) return fail("--actions add_dictionary: " + err);
  return Request(AddDictionary{d->name()});
}

Result<Request> focus(Arg verb, Arg arg) {
  const Result<size_t> i = choice(verb, arg, {"script", "source_path", "preset_path"});
  if (!i) return fail(i.error());
  return Request(Focus{static_cast<TextField>(*i + 1)});
}

Result<Request> type(Arg, Arg arg) {
  // "\n" is Enter; everything else is typed as it is.
  std::string text;
  for (size_t i = 0; i < arg.size(); ++i) {
    const bool enter = arg[i] == '\\' && i + 1 < arg.size() && arg[i + 1] == 'n';
    text += enter ? '\n' : arg[i];
    i += enter;
  }
  return Request(TypeText{text});
}

Result<Request> set(Arg, Arg arg) {
  // set=NAME=VALUE: what letting go of a slider does, one completed edit.
  const size_t eq = arg.find('=');
  const ParamInfo* info = find_param(arg.substr(0, eq));
  if (!info || eq == std::string::npos) return fail("--actions set=" + arg + ": expected PARAM=VALUE");
  const double value = std::atof(arg.c_str() + eq + 1);
  DetectorParams check;
  if (std::string err; !set_param(check, *info, value, &err)) return fail("--actions: " + err);
  return Request(SetParam{info, value});
}

Result<Request> answer(Arg verb, Arg arg) {
  const Result<size_t> i = choice(verb, arg, {"save", "discard", "cancel", "write", "browse", "check", "export"});
  if (!i) return fail(i.error());
  return Request(PressButton{static_cast<DialogButton>(*i)});
}

Result<Request> browse(Arg verb, Arg arg) {
  std::vector<std::string> names;
  for (int k = 0; k < kFileKindCount; ++k) names.emplace_back(file_kind_name(static_cast<FileKind>(k)));
  const Result<size_t> i = choice(verb, arg, names);
  if (!i) return fail(i.error());
  return Request(Browse{static_cast<FileKind>(*i)});
}

Result<Request> help(Arg verb, Arg arg) {
  const Result<size_t> i = choice(verb, arg, {"shortcuts", "first", "about"});
  if (!i) return fail(i.error());
  return Request(ShowHelp{static_cast<HelpPage>(*i)});
}

Result<Request> calib_board(Arg, Arg arg) {
  // calib_board=chessboard|charuco[,COLS,ROWS[,SQUARE_MM[,MARKER_MM]]]: the board the Calibrate workspace looks for.
  const std::string kind = arg.substr(0, arg.find(','));
  if (kind != "chessboard" && kind != "charuco")
    return fail("--actions calib_board: chessboard or charuco, not '" + arg + "'");
  BoardSpec b = default_board(kind == "charuco" ? BoardKind::charuco : BoardKind::chessboard);
  if (arg.size() > kind.size())
    std::sscanf(arg.c_str() + kind.size(), ",%d,%d,%lf,%lf", &b.cols, &b.rows, &b.square_mm, &b.marker_mm);
  if (const std::string why = b.problem(); !why.empty()) return fail("--actions calib_board=" + arg + ": " + why);
  return Request(SetCalibrationBoard{b});
}

Result<Request> marker_size(Arg, Arg arg) {
  // marker_size=L: the printed marker's side (poses in its unit); 0: in marker sides.
  char* end = nullptr;
  const double v = std::strtod(arg.c_str(), &end);
  if (arg.empty() || *end != '\0' || !std::isfinite(v) || v < 0 || v > 1e6)
    return fail("--actions marker_size: a size from 0 (marker sides) to 1000000, not '" + arg + "'");
  return Request(SetMarkerSize{v});
}

Result<Request> speed(Arg, Arg arg) {
  const double v = std::atof(arg.c_str());
  if (!(v >= 0.1 && v <= 8)) return fail("--actions speed: 0.1 to 8 times the source's pace, not '" + arg + "'");
  return Request(SetSpeed{v});
}

Result<Request> lab_frames(Arg, Arg arg) {
  const int n = std::atoi(arg.c_str());
  if (n < 1 || n > 10000) return fail("--actions lab_frames: 1 to 10000 frames per cell, not '" + arg + "'");
  return Request(SetLabFrames{n});
}

Result<Request> lab_axis(Arg, Arg arg) {
  // lab_axis=sizes_mm:65,39 (or distances_m:, lux:, or an added axis, tilts_deg: ...): what typing in the panel's
  // field does, or reading a plan file that gives it.
  const size_t colon = arg.find(':');
  const std::string key = arg.substr(0, colon);
  for (const lab::PlanAxis& axis : lab::plan_axes()) {
    if (key != axis.key || colon == std::string::npos) continue;
    Result<std::vector<double>> v = lab::parse_axis(axis, arg.substr(colon + 1));
    if (!v) return fail("--actions lab_axis: " + v.error());
    return Request(SetLabAxis{&axis, *v});
  }
  std::string keys;
  for (const lab::PlanAxis& axis : lab::plan_axes()) keys += (keys.empty() ? "" : ", ") + std::string(axis.key) + ":";
  return fail("--actions lab_axis: one of " + keys + " and values, not '" + arg + "'");
}

Result<Request> lab_detectors(Arg, Arg arg) {
  std::vector<std::string> list;
  std::stringstream in(arg);
  for (std::string d; std::getline(in, d, ',');)
    if (!d.empty()) list.push_back(d);
  return Request(SetLabDetectors{list});
}

Result<Request> lab_cell(Arg, Arg arg) {
  // lab_cell=I[,K]: cell I of the run (from 0, the table's order), at frame K; what clicking it does.
  int cell = -1, k = 0;
  if (std::sscanf(arg.c_str(), "%d,%d", &cell, &k) < 1) return fail("--actions lab_cell: CELL[,FRAME], not '" + arg + "'");
  return Request(OpenLabCell{cell, k});
}

Result<Request> lab_span(Arg, Arg arg) {
  // lab_span=start|end|whole: the Lab panel's span buttons on the video frame shown.
  if (arg != "start" && arg != "end" && arg != "whole")
    return fail("--actions lab_span: start, end or whole, not '" + arg + "'");
  return Request(MarkClipSpan{arg == "start" ? SpanEnd::start : arg == "end" ? SpanEnd::end : SpanEnd::whole});
}

// ID,SIZE_MM,DISTANCE_M,LUX[,DIR]: a clip's marker and conditions as typed in the Lab panel.
Result<ClipRow> clip_row(const char* action, Arg arg) {
  ClipRow row;
  char dir[1024] = "";
  if (std::sscanf(arg.c_str(), "%d,%lf,%lf,%lf,%1023[^\n]", &row.id, &row.size_mm, &row.distance_m, &row.lux, dir) < 4)
    return fail(std::string("--actions ") + action + ": ID,SIZE_MM,DISTANCE_M,LUX[,DIR], not '" + arg + "'");
  row.dir = dir;
  return row;
}

Result<Request> lab_clip(Arg, Arg arg) {
  // lab_clip=ID,SIZE_MM,DISTANCE_M,LUX[,DIR]: the clip's row as typed in the panel, then Save to videos.csv.
  Result<ClipRow> row = clip_row("lab_clip", arg);
  if (!row) return fail(row.error());
  return Request(SaveClip{*row});
}

Result<Request> lab_record(Arg, Arg arg) {
  // lab_record=ID,SIZE_MM,DISTANCE_M,LUX[,DIR]: the conditions as typed in the panel, then Record; lab_record=stop.
  if (arg == "stop") return Request(StopClip{});
  Result<ClipRow> row = clip_row("lab_record", arg);
  if (!row) return fail(row.error() + " (or stop)");
  return Request(RecordClip{*row});
}

Result<Request> export_size(Arg, Arg arg) {
  const double mm = std::atof(arg.c_str());
  if (!(mm >= 1 && mm <= 1000)) return fail("--actions export_size: 1 to 1000 mm, not '" + arg + "'");
  return Request(SetExportSize{mm});
}

Result<Request> play_args(Arg, Arg arg) {
  // play_args=ARGS: more arguments for the players File > Play bundle starts, split at spaces ("--frames 30").
  std::vector<std::string> args;
  std::istringstream in(arg);
  for (std::string w; in >> w;) args.push_back(w);
  return Request(SetPlayArgs{args});
}

struct Verb {
  const char* name;
  Parse parse;
};

// Each verb, what `arwb --help` says it does, and the request it makes.
const Verb kVerbs[] = {
    {"open", panel_open},
    {"close", panel_open},
    {"source", [](Arg, Arg a) -> Result<Request> { return Request(OpenSource{a}); }},
    {"freeze", [](Arg, Arg) -> Result<Request> { return Request(Freeze{true}); }},
    {"unfreeze", [](Arg, Arg) -> Result<Request> { return Request(Freeze{false}); }},
    {"next", [](Arg, Arg) -> Result<Request> { return Request(NextFrame{true}); }},
    {"speed", speed},
    {"snapshot", [](Arg, Arg) -> Result<Request> { return Request(Snapshot{}); }},
    {"stage", stage},
    {"select", [](Arg, Arg a) -> Result<Request> {   // select=N, or marker: the frame's first marker's candidate
       return Request(SelectCandidate{a == "marker" ? std::nullopt : std::optional<int>(std::atoi(a.c_str()))});
     }},
    {"region", region},
    {"sweep", [](Arg, Arg) -> Result<Request> { return Request(Sweep{}); }},
    {"tour", [](Arg, Arg a) -> Result<Request> {
       return Request(StartTour{a});   // a name or a number, checked against the tour when it opens
     }},
    {"presentation", [](Arg, Arg) -> Result<Request> { return Request(TogglePresentation{}); }},
    {"fullscreen", switch_to<SetFullscreen>},
    {"preset", [](Arg, Arg a) -> Result<Request> { return Request(LoadPreset{a}); }},
    {"peers", [](Arg, Arg) -> Result<Request> { return Request(EnablePeers{}); }},
    {"scene", [](Arg, Arg a) -> Result<Request> { return Request(LoadScene{a}); }},
    {"click", click},
    {"media", [](Arg, Arg a) -> Result<Request> { return Request(ShowMedia{a != "off"}); }},
    {"labels", labels},
    {"add_dictionary", add_dictionary},
    {"drop", [](Arg, Arg a) -> Result<Request> { return Request(Drop{a}); }},
    {"focus", focus},
    {"type", type},
    {"undo", [](Arg, Arg) -> Result<Request> { return Request(Undo{}); }},
    {"redo", [](Arg, Arg) -> Result<Request> { return Request(Redo{}); }},
    {"set", set},
    {"quit", [](Arg, Arg) -> Result<Request> { return Request(Quit{}); }},
    {"answer", answer},
    {"browse", browse},
    {"sheet", [](Arg, Arg) -> Result<Request> { return Request(OpenSheetDialog{}); }},
    {"help", help},
    {"save_preset", [](Arg, Arg a) -> Result<Request> { return Request(SavePreset{a}); }},
    {"workspace", [](Arg, Arg a) -> Result<Request> { return Request(SwitchWorkspace{a}); }},
    {"save_workspace", [](Arg, Arg a) -> Result<Request> { return Request(SaveWorkspace{a}); }},
    {"move", move},
    {"splitter", splitter},
    {"calib_board", calib_board},
    {"calib_capture", switch_to<SetCalibrationCapture>},
    {"calib_drop", [](Arg, Arg a) -> Result<Request> { return Request(DropCalibrationView{"", std::atoi(a.c_str())}); }},
    {"calib_reset", [](Arg, Arg) -> Result<Request> { return Request(ResetCalibration{}); }},
    {"calib_save", [](Arg, Arg a) -> Result<Request> { return Request(SaveCalibration{a}); }},
    {"calib_wait", [](Arg, Arg a) -> Result<Request> { return Request(WaitForCalibration{std::atoi(a.c_str())}); }},
    {"undistort", switch_to<SetUndistort>},
    {"pose", pose},
    {"marker_size", marker_size},
    {"lab_plan", [](Arg, Arg a) -> Result<Request> {   // paper, or a plan file
       return a == "paper" ? Request(UsePaperPlan{}) : ReadLabPlan{a};
     }},
    {"lab_frames", lab_frames},
    {"lab_axis", lab_axis},
    {"lab_detectors", lab_detectors},
    {"lab_run", [](Arg, Arg) -> Result<Request> { return Request(StartLab{}); }},
    {"lab_stop", [](Arg, Arg) -> Result<Request> { return Request(StopLab{}); }},
    {"lab_wait", [](Arg, Arg a) -> Result<Request> { return Request(WaitForLab{a.empty() ? -1 : std::atoi(a.c_str())}); }},
    {"lab_cell", lab_cell},
    {"lab_why", [](Arg, Arg) -> Result<Request> { return Request(WhyLabMarker{}); }},
    {"lab_save", [](Arg, Arg a) -> Result<Request> { return Request(SaveLabReport{a}); }},
    {"lab_span", lab_span},
    {"lab_clip", lab_clip},
    {"lab_record", lab_record},
    {"lab_print", [](Arg, Arg) -> Result<Request> { return Request(PrintClipMarker{}); }},
    {"export_dialog", [](Arg, Arg a) -> Result<Request> { return Request(OpenExportDialog{a}); }},
    {"export", [](Arg, Arg a) -> Result<Request> { return Request(WriteExport{a}); }},
    {"export_title", [](Arg, Arg a) -> Result<Request> { return Request(SetExportTitle{a}); }},
    {"export_size", export_size},
    {"export_calibration", switch_to<SetExportCalibration>},
    {"export_force", switch_to<SetExportForce>},
    {"export_web", switch_to<SetExportWeb>},
    {"export_convert", switch_to<SetExportConvert>},
    {"serve", switch_to<ServeBundle>},
    {"export_wait", [](Arg, Arg a) -> Result<Request> { return Request(WaitForExport{seconds(a)}); }},
    {"play", [](Arg, Arg a) -> Result<Request> { return Request(PlayBundle{a}); }},
    {"play_args", play_args},
    {"play_wait", [](Arg, Arg a) -> Result<Request> { return Request(WaitForPlayers{seconds(a)}); }},
    {"source_wait", [](Arg, Arg a) -> Result<Request> {
       return Request(WaitForSource{a.empty() ? 30.0 : seconds(a)});
     }},
};

}  // namespace

const std::vector<std::string>& action_verbs() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const Verb& verb : kVerbs) v.emplace_back(verb.name);
    return v;
  }();
  return names;
}

Result<Request> action_request(const std::string& verb, const std::string& arg) {
  const auto it = std::find_if(std::begin(kVerbs), std::end(kVerbs), [&](const Verb& v) { return verb == v.name; });
  if (it == std::end(kVerbs)) return fail("--actions: unknown verb '" + verb + "'");
  return it->parse(verb, arg);
}

// [SECTION] Script
Result<std::vector<ScriptStep>> parse_script(const std::vector<std::string>& specs) {
  std::vector<Action> actions;
  std::string err;
  if (!parse_actions(specs, &actions, &err, action_verbs())) return fail(err);
  std::vector<ScriptStep> steps;
  for (const Action& a : actions) steps.push_back({a.frame, action_request(a.verb, a.arg)});
  return steps;
}

}  // namespace arwb::ui
