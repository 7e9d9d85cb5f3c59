// The --actions parser (ui/actions.hpp), without a window: every verb `arwb --help` lists becomes the typed request
// a menu, a key or a panel would make, with its argument in named fields; a bad argument is refused with a message
// naming the verb and the argument; a bad step or an unknown verb fails the whole script, naming it.
#include "detect/params.hpp"
#include "lab/plan.hpp"
#include "ui/actions.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace arwb::ui {
namespace {

// The request `verb=arg` makes, which must be a T.
template <class T>
T request_of(const std::string& verb, const std::string& arg = "") {
  const Result<Request> r = action_request(verb, arg);
  EXPECT_TRUE(r.ok()) << verb << "=" << arg << ": " << r.error();
  if (!r.ok() || !std::holds_alternative<T>(*r)) {
    ADD_FAILURE() << verb << "=" << arg << " made another request (index " << (r.ok() ? r->index() : 0) << ")";
    return T{};
  }
  return std::get<T>(*r);
}

std::string refusal(const std::string& verb, const std::string& arg) {
  const Result<Request> r = action_request(verb, arg);
  EXPECT_FALSE(r.ok()) << verb << "=" << arg << " was taken";
  return r.error();
}

TEST(Actions, EveryVerbTheHelpListsMakesARequest) {
  // One argument each verb takes: every verb in the table parses into some request.
  const std::vector<std::pair<std::string, std::string>> samples = {
      {"open", "timings"}, {"close", "all"}, {"source", "synthetic"}, {"freeze", ""}, {"unfreeze", ""}, {"next", ""}, {"speed", "8"},
      {"snapshot", ""}, {"stage", "otsu"}, {"select", "marker"}, {"region", "1,2,3,4"}, {"sweep", ""},
      {"tour", "2"}, {"presentation", ""}, {"fullscreen", "on"}, {"preset", "fast"}, {"peers", ""}, {"scene", "a.lua"},
      {"click", "1,2"}, {"media", "off"}, {"labels", "ids"}, {"add_dictionary", "ARUCO_ORIGINAL"},
      {"drop", "a.png"}, {"focus", "script"}, {"type", "x"}, {"undo", ""}, {"redo", ""},
      {"set", "threshold_window_px=31"}, {"quit", ""}, {"answer", "save"}, {"browse", "scene"}, {"sheet", ""},
      {"help", "about"}, {"save_preset", "mine"}, {"workspace", "Teach"}, {"save_workspace", "Mine"},
      {"move", "log>live_view"}, {"splitter", "0,0.3"}, {"calib_board", "charuco"}, {"calib_capture", "off"},
      {"calib_drop", "2"}, {"calib_reset", ""}, {"calib_save", "c.yml"}, {"calib_wait", "6"},
      {"undistort", "on"}, {"pose", "all"}, {"marker_size", "50"}, {"lab_plan", "paper"}, {"lab_frames", "4"},
      {"lab_axis", "lux:850"}, {"lab_detectors", "arwb"}, {"lab_run", ""}, {"lab_stop", ""}, {"lab_wait", ""},
      {"lab_cell", "2,0"}, {"lab_why", ""}, {"lab_save", "out"}, {"lab_span", "start"},
      {"lab_clip", "5,65,1,850"}, {"lab_record", "5,65,1,850"}, {"lab_print", ""},
      {"export_dialog", ""}, {"export", "b.arwb"}, {"export_title", "T"},
      {"export_size", "65"}, {"export_calibration", "off"}, {"export_force", "on"}, {"export_web", "on"}, {"export_convert", "on"}, {"serve", "on"}, {"export_wait", ""}, {"source_wait", ""},
      {"play", "b.arwb"}, {"play_args", "--frames 5"}, {"play_wait", "3"}};
  ASSERT_EQ(samples.size(), action_verbs().size()) << "a verb without a sample here";
  for (const auto& [verb, arg] : samples) {
    EXPECT_NE(std::find(action_verbs().begin(), action_verbs().end(), verb), action_verbs().end()) << verb;
    const Result<Request> r = action_request(verb, arg);
    EXPECT_TRUE(r.ok()) << verb << "=" << arg << ": " << r.error();
  }
}

TEST(Actions, ArgumentsLandInNamedFields) {
  EXPECT_EQ(request_of<SetPanelOpen>("open", "timings").panel, Panel::timings);
  EXPECT_TRUE(request_of<SetPanelOpen>("open", "timings").open);
  EXPECT_DOUBLE_EQ(request_of<SetSpeed>("speed", "0.5").speed, 0.5);
  EXPECT_FALSE(request_of<SetPanelOpen>("close", "all").panel.has_value());
  EXPECT_FALSE(request_of<SetPanelOpen>("close", "all").open);
  EXPECT_EQ(request_of<OpenSource>("source", "camera:0").spec, "camera:0");
  EXPECT_FALSE(request_of<OpenSource>("source", "camera:0").asked);
  EXPECT_TRUE(request_of<NextFrame>("next").wait) << "a script's next waits until the frame is shown";
  EXPECT_EQ(request_of<ShowStage>("stage", "otsu").stage, Stage::otsu);
  EXPECT_FALSE(request_of<ShowStage>("stage", "input").stage.has_value());
  EXPECT_FALSE(request_of<SelectCandidate>("select", "marker").index.has_value());
  EXPECT_EQ(request_of<SelectCandidate>("select", "7").index, 7);
  EXPECT_EQ(request_of<SetRegion>("region", "290,178,52,42").region, cv::Rect2f(290, 178, 52, 42));
  EXPECT_EQ(request_of<StartTour>("tour", "4").step, "4");
  EXPECT_EQ(request_of<StartTour>("tour", "otsu").step, "otsu");
  EXPECT_EQ(request_of<StartTour>("tour").step, "");
  EXPECT_EQ(request_of<SetFullscreen>("fullscreen", "off").on, false);
  EXPECT_FALSE(request_of<ShowMedia>("media", "off").on);
  const SetLabels labels = request_of<SetLabels>("labels", "ids,truth");
  EXPECT_TRUE(labels.ids && labels.truth);
  EXPECT_FALSE(labels.dictionary || labels.rejected || labels.peers);
  const SetPoseDrawing pose = request_of<SetPoseDrawing>("pose", "cube,axes");
  EXPECT_TRUE(pose.cube && pose.axes && !pose.alternative);
  EXPECT_EQ(request_of<ClickLiveView>("click", "281,340").at, cv::Point2d(281, 340));
  EXPECT_EQ(request_of<Focus>("focus", "preset_path").field, TextField::preset_path);
  EXPECT_EQ(request_of<TypeText>("type", "a\\nb").text, "a\nb") << "\\n is Enter";
  const SetParam set = request_of<SetParam>("set", "threshold_window_px=31");
  ASSERT_NE(set.param, nullptr);
  EXPECT_EQ(std::string(set.param->name), "threshold_window_px");
  EXPECT_EQ(set.value, 31);
  EXPECT_EQ(request_of<PressButton>("answer", "export").button, DialogButton::export_bundle);
  EXPECT_EQ(request_of<Browse>("browse", "preset").kind, FileKind::preset);
  EXPECT_EQ(request_of<ShowHelp>("help", "first").page, HelpPage::first_steps);
  const MovePanel move = request_of<MovePanel>("move", "timings>candidates");
  EXPECT_EQ(move.panel, Panel::timings);
  EXPECT_EQ(move.beside, Panel::candidates);
  EXPECT_EQ(request_of<SetSplitter>("splitter", "1,0.25").index, 1);
  EXPECT_FLOAT_EQ(request_of<SetSplitter>("splitter", "1,0.25").ratio, 0.25f);
  const BoardSpec board = request_of<SetCalibrationBoard>("calib_board", "charuco,5,7,35,26").board;
  EXPECT_EQ(board.kind, BoardKind::charuco);
  EXPECT_EQ(board.cols, 5);
  EXPECT_EQ(board.rows, 7);
  EXPECT_EQ(board.marker_mm, 26);
  EXPECT_EQ(request_of<DropCalibrationView>("calib_drop", "2").number, 2);
  EXPECT_TRUE(request_of<DropCalibrationView>("calib_drop", "2").name.empty());
  EXPECT_EQ(request_of<WaitForCalibration>("calib_wait", "7").views, 7);
  EXPECT_EQ(request_of<SetMarkerSize>("marker_size", "50").size, 50);
  EXPECT_TRUE(std::holds_alternative<UsePaperPlan>(*action_request("lab_plan", "paper")));
  EXPECT_EQ(request_of<ReadLabPlan>("lab_plan", "p.yml").path, "p.yml");
  const SetLabAxis axis = request_of<SetLabAxis>("lab_axis", "sizes_mm:65,26");
  ASSERT_NE(axis.axis, nullptr);
  EXPECT_EQ(std::string(axis.axis->key), "sizes_mm");
  EXPECT_EQ(axis.values, (std::vector<double>{65, 26}));
  EXPECT_EQ(request_of<SetLabDetectors>("lab_detectors", "arwb,,opencv").detectors,
            (std::vector<std::string>{"arwb", "opencv"}));
  EXPECT_EQ(request_of<WaitForLab>("lab_wait").cells, -1) << "no count: until the run ends";
  EXPECT_EQ(request_of<OpenLabCell>("lab_cell", "2,5").cell, 2);
  EXPECT_EQ(request_of<OpenLabCell>("lab_cell", "2,5").frame, 5);
  EXPECT_EQ(request_of<MarkClipSpan>("lab_span", "whole").end, SpanEnd::whole);
  const SaveClip clip = request_of<SaveClip>("lab_clip", "5,65,1.5,850,/tmp/clips");
  ASSERT_TRUE(clip.typed.has_value());
  EXPECT_EQ(clip.typed->id, 5);
  EXPECT_EQ(clip.typed->distance_m, 1.5);
  EXPECT_EQ(clip.typed->dir, "/tmp/clips");
  const RecordClip record = request_of<RecordClip>("lab_record", "7,39,0.5,500");
  ASSERT_TRUE(record.typed.has_value());
  EXPECT_EQ(record.typed->id, 7);
  EXPECT_EQ(record.typed->size_mm, 39);
  EXPECT_EQ(record.typed->dir, "") << "no folder: the panel's";
  EXPECT_TRUE(std::holds_alternative<StopClip>(*action_request("lab_record", "stop")));
  EXPECT_EQ(request_of<WriteExport>("export", "b.arwb").out, std::optional<std::string>("b.arwb"));
  EXPECT_EQ(request_of<WaitForExport>("export_wait").seconds, 120);
  EXPECT_EQ(request_of<WaitForPlayers>("play_wait", "9999").seconds, 600) << "at most 600 s";
  EXPECT_EQ(request_of<SetPlayArgs>("play_args", "--frames  5").args, (std::vector<std::string>{"--frames", "5"}));
}

TEST(Actions, ABadArgumentIsRefusedNamingTheVerbAndTheArgument) {
  EXPECT_EQ(refusal("open", "nowhere"), "--actions: no panel 'nowhere'");
  EXPECT_EQ(refusal("stage", "blur"), "--actions: no stage 'blur'");
  EXPECT_EQ(refusal("speed", "20"), "--actions speed: 0.1 to 8 times the source's pace, not '20'");
  EXPECT_EQ(refusal("region", "1,2,0,4"), "--actions: region wants X,Y,W,H, not '1,2,0,4'");
  EXPECT_EQ(refusal("move", "log"), "--actions: move wants PANEL>PANEL_IN_THE_TARGET_REGION, not 'log'");
  EXPECT_EQ(refusal("splitter", "0,2"), "--actions: splitter wants I,RATIO (RATIO in 0.05..0.95), not '0,2'");
  EXPECT_EQ(refusal("labels", "ids,colour"),
            "--actions labels=ids,colour: no kind 'colour' (ids, dict, rejected, truth, peers, all, none)");
  EXPECT_EQ(refusal("click", "here"), "--actions click=here: expected X,Y in image pixels");
  EXPECT_EQ(refusal("set", "no_such_param=3"), "--actions set=no_such_param=3: expected PARAM=VALUE");
  EXPECT_NE(refusal("set", "threshold_window_px=-5").find("threshold_window_px"), std::string::npos);
  EXPECT_EQ(refusal("calib_capture", "maybe"), "--actions calib_capture: on or off, not 'maybe'");
  EXPECT_EQ(refusal("calib_board", "circles"), "--actions calib_board: chessboard or charuco, not 'circles'");
  EXPECT_EQ(refusal("marker_size", "big"), "--actions marker_size: a size from 0 (marker sides) to 1000000, not 'big'");
  EXPECT_EQ(refusal("lab_frames", "0"), "--actions lab_frames: 1 to 10000 frames per cell, not '0'");
  EXPECT_EQ(refusal("lab_span", "middle"), "--actions lab_span: start, end or whole, not 'middle'");
  EXPECT_EQ(refusal("lab_record", "go"), "--actions lab_record: ID,SIZE_MM,DISTANCE_M,LUX[,DIR], not 'go' (or stop)");
  EXPECT_EQ(refusal("export_size", "0.5"), "--actions export_size: 1 to 1000 mm, not '0.5'");
  EXPECT_EQ(refusal("focus", "title"), "--actions focus: script, source_path or preset_path, not 'title'");
  EXPECT_EQ(refusal("answer", "maybe"), "--actions answer: save, discard, cancel, write, browse, check or export, not 'maybe'");
  EXPECT_NE(refusal("add_dictionary", "NO_SUCH_DICT").find("--actions add_dictionary: "), std::string::npos);
  EXPECT_EQ(refusal("explode", ""), "--actions: unknown verb 'explode'");
}

TEST(Actions, AScriptIsSortedByFrameAndAnUnknownVerbFailsItWhole) {
  const Result<std::vector<ScriptStep>> script = parse_script({"10:snapshot;2:open=log", "5:stage=nowhere"});
  ASSERT_TRUE(script.ok()) << script.error();
  ASSERT_EQ(script->size(), 3u);
  EXPECT_EQ((*script)[0].frame, 2);
  EXPECT_TRUE(std::holds_alternative<SetPanelOpen>(*(*script)[0].request));
  EXPECT_EQ((*script)[1].frame, 5);
  EXPECT_EQ((*script)[1].request.error(), "--actions: no stage 'nowhere'") << "said when frame 5 comes";
  EXPECT_TRUE(std::holds_alternative<Snapshot>(*(*script)[2].request));

  EXPECT_EQ(parse_script({"1:open=log;5:explode"}).error(), "--actions '5:explode': unknown verb 'explode'");
  EXPECT_EQ(parse_script({"x:open=log"}).error(), "--actions 'x:open=log': expected FRAME:VERB[=ARG]");
}

}  // namespace
}  // namespace arwb::ui
